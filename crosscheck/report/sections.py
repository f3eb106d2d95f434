"""The report's sections: a list of objects, each with a name, an order, a builder and a template.

In the manner of asv's publishers, :func:`crosscheck.report.render.render_html`
walks :data:`SECTIONS` in order: ``build`` makes a section's template context
from the stored run (``None``: the section has nothing to show and is left
out), the section's template renders it, and the page stacks the results.
Adding a section is one builder, one template and one entry in the list.

>>> [s.name for s in sorted(SECTIONS, key=lambda s: s.order)][:3]
['verdict', 'case errors', 'engines x case groups']
"""

from __future__ import annotations

import functools
import re
import shlex
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import pandas as pd
from markupsafe import Markup

from crosscheck.core.schema import AnyCase
from crosscheck.report import (
    aside,
    claims,
    coverage_page,
    dynamics,
    energy_chart,
    metamorphic,
    profiles,
    results_table,
    speed,
    speed_error,
    stability,
    symmetry,
    text,
    verdict,
    versions,
)
from crosscheck.report.advise import page as advise_page
from crosscheck.report.coverage import CoverageMap, run_map
from crosscheck.report.stability import charts as stability_charts
from crosscheck.report.summary_tables import STATUSES, disagreements, group_matrix, summary
from crosscheck.report.symmetry import asymmetries
from crosscheck.results.run import Run
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.scene_facts import read_facts
from crosscheck.results.series import read_series
from crosscheck.results.timings import read_timings

Context = dict[str, Any]


def plain_strings(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with its text columns as Python objects: the sections walk rows in Python,
    and pandas' Arrow-backed ``str`` columns cost about a sixth of the page in iterating
    (the files are written from the stored frame, with its own dtypes)."""
    text = [c for c in frame.columns if isinstance(frame[c].dtype, pd.StringDtype)]
    return frame.astype(dict.fromkeys(text, object)) if text else frame


class RunView:
    """A stored run and what several sections (and the CSV files) derive from it, once each."""

    def __init__(self, stored: Run) -> None:
        self.stored = stored
        self.frame: pd.DataFrame = plain_strings(stored.results)
        self.info: RunInfo = stored.info
        self.cases: Mapping[str, AnyCase] = stored.cases

    @functools.cached_property
    def rows(self) -> pd.DataFrame:
        """:attr:`frame` with its values decoded once (:attr:`crosscheck.results.run.Run.decoded`),
        for the sections that compare values (symmetry, moved scenes, dynamics, horizons)."""
        return self.frame.join(self.stored.decoded)

    @functools.cached_property
    def plain(self) -> Run:
        """The stored run with :attr:`frame` (its text as Python objects) as its results, for
        the sections that read the run itself (the advise answers)."""
        return self.stored.with_results(self.frame, self.stored.decoded)

    @functools.cached_property
    def missing(self) -> int:
        """Case x engine pairs the run should hold but does not (a run stopped early)."""
        engines = self.info.engine_names
        done = set(zip(self.frame["case_id"], self.frame["engine"], strict=True))
        return sum((case_id, e) not in done for case_id in self.cases for e in engines)

    @functools.cached_property
    def order(self) -> list[str]:
        """The engines in run order: each keeps its colour and marker on every chart."""
        return [str(e) for e in dict.fromkeys(self.frame["engine"])]

    @functools.cached_property
    def timings(self) -> pd.DataFrame:
        """Every kept timing sample of the run (``timings.jsonl``; empty when none)."""
        return read_timings(self.stored.directory)

    @functools.cached_property
    def speed_charts(self) -> list[speed_error.SpeedChart]:
        return speed_error.speed_charts(self.frame, self.info, self.cases)

    @functools.cached_property
    def summary(self) -> pd.DataFrame:
        return summary(self.frame)

    @functools.cached_property
    def disagreements(self) -> pd.DataFrame:
        return disagreements(self.frame)

    @functools.cached_property
    def mirrored(self) -> pd.DataFrame:
        """Every swapped twin's answer against its original's (:func:`symmetry.compared`), for
        the symmetry section and ``asymmetries.csv``."""
        return symmetry.compared(self.rows)

    @functools.cached_property
    def asymmetries(self) -> pd.DataFrame:
        return asymmetries(self.rows, self.mirrored)

    @functools.cached_property
    def coverage(self) -> CoverageMap:
        """Each cell of the configuration space the run's cases reach, per engine: its cases,
        the worst status and the largest error in bounds (``coverage.csv``)."""
        return run_map(self.cases, self.frame, self.order)

    @functools.cached_property
    def claim_checks(self) -> list[claims.ClaimCheck]:
        """Each engine's recorded claims against the run (:func:`claims.evaluate`), for the
        claims section and ``claims.csv``; empty when the run records none."""
        return claims.evaluate(self.stored)

    @functools.cached_property
    def metamorphic(self) -> pd.DataFrame:
        """Each moved or resized scene point x engine against the engine's own origin run
        (``metamorphic.csv``; empty without such sweeps)."""
        return metamorphic.points(self.rows, self.cases)


def _no_plots(context: Context) -> bool:
    return False


@dataclass(frozen=True)
class Section:
    """One part of the page: ``build`` makes its context (or None), ``template`` renders it."""

    name: str
    order: int
    template: str
    build: Callable[[RunView], Context | None]
    plots: Callable[[Context], bool] = _no_plots
    """Whether the built section draws plotly charts (the page then inlines plotly.js once)."""

    @property
    def anchor(self) -> str:
        """The section's id in the page, for the table of contents.

        >>> Section("A/B symmetry", 80, "t", _no_plots).anchor
        'section-a-b-symmetry'
        """
        return "section-" + "-".join(re.findall(r"[a-z0-9]+", self.name.lower()))


def _verdict(view: RunView) -> Context | None:
    """The standard profiles on common ground, then per engine and kind: agreeing shares,
    speed ranks and failure modes, those of bad input and zero-size bodies set aside
    (None: an empty run)."""
    if view.frame.empty:
        return None
    repros, zero_sized = view.stored.repros, aside.zero_size(view.cases)
    return verdict.verdict(view.frame, repros, view.info.repeat_check, zero_sized) \
        | profiles.context(view.frame, repros, zero_sized) \
        | {"run_dir": str(view.stored.directory)}


def _errors(view: RunView) -> Context | None:
    return {"info": view.info} if view.info.case_errors else None


def _matrix(view: RunView) -> Context:
    return {"matrix": group_matrix(view.frame)}


def _coverage(view: RunView) -> Context | None:
    """Heat maps of the configuration space per kind and dimension pair, coloured by the chosen
    engine's worst status (None: no case of the run has a cell)."""
    command = shlex.join(["crosscheck", "coverage", str(view.stored.directory)])
    return coverage_page.section(view.coverage, view.order, command)


def _summary(view: RunView) -> Context:
    return {"summary": view.summary.to_dict("records"), "statuses": STATUSES,
            "threshold": speed.UNSTABLE_SPREAD,
            "counted": bool(view.summary.get("counted", pd.Series(dtype=int)).gt(0).any())}


def _speed(view: RunView) -> Context:
    """The speed charts; ``counted``: some kind's cost is counted instructions (the section
    then says how they were counted); ``off``: the section's one line when no kind has a
    timed engine to draw (a run without its timing phase), else ``""``."""
    return {"off": _untimed(view),
            "speed": [{"data": chart, "html": Markup(speed_error.figure_html(chart, view.order))
                       if chart.plotted else None} for chart in view.speed_charts],
            "seconds": text.seconds, "with_iqr": text.with_iqr,
            "threshold": speed.UNSTABLE_SPREAD,
            "counted": any(chart.by_counts for chart in view.speed_charts)}


def _untimed(view: RunView) -> str:
    """The speed section's one line when no chart has a timed engine ('' when one has)."""
    if any(chart.plotted for chart in view.speed_charts):
        return ""
    why = (speed.timing_context(view.info, view.frame, [], view.timings)["off"]
           if view.info.timing is None else "No engine has a query time in this run.")
    return (f"Nothing to draw. {why} The accuracy of every engine is in the verdict and the "
            "engine \u00d7 kind table above; a run with its timing phase (without --quick) "
            "draws each kind's cost against its error here.")


def _timing(view: RunView) -> Context:
    kinds = [chart.kind for chart in view.speed_charts]
    return {"timing": speed.timing_context(view.info, view.frame, kinds, view.timings)}


def _dynamics(view: RunView) -> Context | None:
    """Each scene x engine's most accurate run in view (its impacts on a step boundary from
    ``scene_facts.jsonl``, recomputed where the run stored none); every run and the chart
    folded per scene; energy against time per scene family, from ``series.jsonl`` when the
    run stored it; moved and resized scenes against the engine's own origin run (None without
    scene runs)."""
    built = dynamics.section(view.rows, view.cases, view.order,
                             read_facts(view.stored.directory))
    if not built["runs"]:
        return None
    built["scenes"] = [{**s, "chart": Markup(s["chart"])} for s in built["scenes"]]
    energy = energy_chart.section(read_series(view.stored.directory), view.cases, view.order)
    energy["charts"] = [{**c, "html": Markup(c["html"])} for c in energy["charts"]]
    built["energy"] = energy
    built["metamorphic"] = metamorphic.section(view.metamorphic, view.order)
    built["charts"] = [*built["charts"], *energy["charts"]]
    return {"dynamics": built}


def _stability(view: RunView) -> Context | None:
    """The threshold matrix and the charts folded per family (``None`` without sweeps);
    ``charts`` lists them all (the page inlines plotly.js when a section has charts)."""
    points = stability.sweep_points(view.frame, view.cases)
    table = stability.with_horizons(stability.thresholds(points), view.rows, view.cases)
    if table.empty:
        return None
    folds = stability_charts.folds(points, table)
    return {"stability": {"matrix": stability.matrix(table), "folds": folds,
                          "charts": [chart for fold in folds for chart in fold["charts"]]}}


def _disagreements(view: RunView) -> Context:
    """The results table: every case x engine once, packed, with the run folder (each breaking
    row's repro command is built from it in the page), each row's repro link (if written) and
    the case inputs the page's case details are built from."""
    return results_table.results_table(view.frame, view.cases, view.stored.repros,
                               str(view.stored.directory))


def _advise(view: RunView) -> Context:
    """The advise form, which writes the command of the profile it states, and the answers of
    the standard profiles (:func:`crosscheck.report.advise.page.section`)."""
    kinds = [str(k) for k in dict.fromkeys(view.frame["kind"])] if len(view.frame) else []
    quantities = ([str(q) for q in dict.fromkeys(view.frame["quantity"])]
                  if len(view.frame) else [])
    return {"run_id": view.info.run_id,
            **advise_page.section(view.plain, kinds, quantities)}


def _symmetry(view: RunView) -> Context:
    """The A/B symmetry counts per engine x quantity and each engine's asymmetric answers
    (``asymmetries.csv`` is written from ``view.asymmetries``, every row kept)."""
    return symmetry.section(view.rows, view.order, view.mirrored)


def _versions(view: RunView) -> Context | None:
    """What changed from an engine's earlier major version to its next, both in the run
    (None: no such pair)."""
    return versions.section(view.frame, view.info.engines, view.stored.directory)


VERDICT_STYLES = {"holds": "agree", "fails": "disagree", "untested": "undefined"}
"""The page's class of each claim verdict (its colour)."""


def _claims(view: RunView) -> Context | None:
    """Each recorded claim against the run, its cells written (None: the run records none)."""
    if not view.claim_checks:
        return None
    rows = [{**claims.cells(c), "style": VERDICT_STYLES[c.verdict]} for c in view.claim_checks]
    found = {v: sum(c.verdict == v for c in view.claim_checks) for v in VERDICT_STYLES}
    engines: dict[str, dict[str, int]] = {}
    for check in view.claim_checks:
        per = engines.setdefault(check.engine, dict.fromkeys(VERDICT_STYLES, 0))
        per[check.verdict] += 1
    return {"rows": rows, "counts": ", ".join(f"{n} {v}" for v, n in found.items() if n),
            "by_verdict": [{"verdict": v, "style": style, "engines": ", ".join(
                f"{e} {per[v]}" for e, per in engines.items() if per[v])}
                for v, style in VERDICT_STYLES.items() if found[v]]}


def _info(view: RunView) -> Context:
    return {"info": view.info}


def _cases(view: RunView) -> Context:
    """The case details: built on demand by the page from the results table's data."""
    return {"cases": int(view.frame["case_id"].nunique()) if len(view.frame) else 0}


def _has(key: str) -> Callable[[Context], bool]:
    def plots(context: Context) -> bool:
        return bool(context[key]["charts"])
    return plots


SECTIONS: list[Section] = [
    Section("verdict", 5, "_verdict.html.j2", _verdict),
    Section("case errors", 10, "_errors.html.j2", _errors),
    Section("engines x case groups", 20, "_matrix.html.j2", _matrix),
    Section("coverage", 25, "_coverage.html.j2", _coverage),
    Section("engine x kind", 30, "_summary.html.j2", _summary),
    Section("speed against error", 40, "_speed.html.j2", _speed,
            lambda c: any(chart["html"] for chart in c["speed"])),
    Section("timing", 45, "_timing.html.j2", _timing),
    Section("dynamics", 50, "_dynamics.html.j2", _dynamics, _has("dynamics")),
    Section("stability", 60, "_stability.html.j2", _stability, _has("stability")),
    Section("results", 70, "_disagreements.html.j2", _disagreements),
    Section("which engine for my scene", 75, "_advise.html.j2", _advise),
    Section("A/B symmetry", 80, "_symmetry.html.j2", _symmetry),
    Section("engine versions", 85, "_versions.html.j2", _versions),
    Section("published claims", 88, "_claims.html.j2", _claims),
    Section("engines and conventions", 90, "_engines.html.j2", _info),
    Section("case details", 100, "_cases.html.j2", _cases),
    Section("environment", 110, "_environment.html.j2", _info),
]
"""Every section of the report page, with its place in the page."""
