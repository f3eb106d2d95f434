"""Energy against time in the dynamics section: one chart per scene family.

Reads the run's ``series.jsonl`` (:mod:`crosscheck.results.series`; the report never runs
an engine).  A *family* is one scene block (the cases' ``origin``) at one time step ``dt``:
its chart has one line per engine variant and the exact reference's (dashed, black), x the
simulated time in seconds, y the relative energy drift ``(E(t) - E(0)) / energy scale``
(the scale: the initial kinetic energy plus ``m |g| h`` of each body above the ground;
0 is no drift, negative is energy lost).  Only the family's own point is drawn: of an
offset or scale sweep, the point at offset 0 and scale 1; of a swept solver iteration
count, each engine's first series.

At most :data:`MAX_CHARTS` charts, so that the section stays readable: when there are more
families, each block keeps only its largest time step (where drift shows most), blocks
without an offset or scale sweep come first, and the rest are left out (the section says
how many; every series stays in ``series.jsonl``).

Every text that reaches plotly (engine names, block ids) is HTML-escaped first.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from crosscheck.core.schema import DEFAULT_DT, AnyCase, SceneCase
from crosscheck.report.style import COLOURS, SYMBOLS, plot_div, plotly_template
from crosscheck.results.series import EXACT, SeriesRecord

MAX_CHARTS = 12
"""Energy charts in the section at most."""
EXACT_LINE = {"color": "#222", "dash": "dash", "width": 2}
WORLD_SWEEP = {"offset": 0.0, "scale": 1.0}
"""Sweep coordinates of a moved or resized scene, at their origin point's value."""


@dataclass(frozen=True)
class Family:
    """One scene block at one time step, with its series (the exact one first)."""

    origin: str
    dt: float
    swept: bool
    """The block sweeps offset or scale (its origin point stands for it)."""
    series: tuple[SeriesRecord, ...]

    @property
    def key(self) -> str:
        """The family's name on the page: its block and time step."""
        return f"{self.origin} at dt {step_text(self.dt)}"


def step_text(dt: float) -> str:
    """A time step as the chart titles write it (``1/n s`` for a whole rate).

    >>> step_text(1 / 60), step_text(0.002)
    ('1/60 s', '0.002 s')
    """
    rate = round(1.0 / dt)
    if float(f"{dt:.3g}") != dt and abs(rate * dt - 1.0) < 1e-9:
        return f"1/{rate} s"
    return f"{dt:g} s"


def _dt(record: SeriesRecord, cases: Mapping[str, AnyCase]) -> float:
    case = cases.get(record.case_id)
    if "dt" in record.coords:
        return float(record.coords["dt"])
    return float(case.dt or DEFAULT_DT) if isinstance(case, SceneCase) else DEFAULT_DT


def _origin_point(record: SeriesRecord) -> bool:
    """Not a moved or resized point of a sweep (its offset 0 and scale 1 are)."""
    return all(record.coords.get(name, at) == at for name, at in WORLD_SWEEP.items())


def families(records: Sequence[SeriesRecord], cases: Mapping[str, AnyCase]) -> list[Family]:
    """Every family of the run's series, in the order first written, the exact series first
    and one series per engine (its first)."""
    grouped: dict[tuple[str, float], dict[str, SeriesRecord]] = {}
    swept: set[str] = set()
    for record in records:
        if any(name in record.coords for name in WORLD_SWEEP):
            swept.add(record.origin)
        if not _origin_point(record):
            continue
        lines = grouped.setdefault((record.origin, _dt(record, cases)), {})
        lines.setdefault(record.engine, record)
    out = []
    for (origin, dt), lines in grouped.items():
        ordered = sorted(lines.values(), key=lambda r: r.engine != EXACT)
        out.append(Family(origin, dt, origin in swept, tuple(ordered)))
    return out


def chosen(found: Sequence[Family], most: int = MAX_CHARTS) -> list[Family]:
    """The families drawn (see the module docstring), in their order.

    >>> pairs = (("a", .1), ("a", .2), ("m", .1), ("b", .1))
    >>> f = [Family(o, dt, o == "m", ()) for o, dt in pairs]
    >>> [x.key for x in chosen(f, 4)]
    ['a at dt 0.1 s', 'a at dt 0.2 s', 'm at dt 0.1 s', 'b at dt 0.1 s']
    >>> [x.key for x in chosen(f, 2)]
    ['a at dt 0.2 s', 'b at dt 0.1 s']
    """
    if len(found) <= most:
        return list(found)
    coarsest: dict[str, Family] = {}
    for family in found:
        if family.origin not in coarsest or family.dt > coarsest[family.origin].dt:
            coarsest[family.origin] = family
    kept = sorted(coarsest.values(), key=lambda f: f.swept)[:most]
    return [f for f in found if f in kept]


def _style(engine: str, styles: Mapping[str, int]) -> dict[str, Any]:
    index = styles.get(engine, len(styles))
    return {"color": COLOURS[index % len(COLOURS)], "symbol": SYMBOLS[index % len(SYMBOLS)]}


def _trace(record: SeriesRecord, styles: Mapping[str, int]) -> dict[str, Any]:
    exact = record.engine == EXACT
    name = "exact reference" if exact else html.escape(record.engine)
    style = _style(record.engine, styles)
    line = EXACT_LINE if exact else {"color": style["color"], "width": 1.5}
    return {
        "type": "scatter", "mode": "lines", "name": name, "x": list(record.times),
        "y": [e if math.isfinite(e) else None for e in record.energy], "line": line,
        "hovertemplate": f"<b>{name}</b><br>t = %{{x:.4g}} s<br>energy drift %{{y:.3g}} "
                         f"of the energy scale<extra>{html.escape(record.case_id)}</extra>"}


def figure(family: Family, styles: Mapping[str, int]) -> dict[str, Any]:
    """The chart of one family (a plain plotly figure; the exact line drawn last, on top)."""
    engines = [r for r in family.series if r.engine != EXACT]
    exact = [r for r in family.series if r.engine == EXACT]
    layout = {
        "template": plotly_template(), "height": 380, "hoverlabel": {"align": "left"},
        "title": {"text": html.escape(family.key) + (" (the sweep's origin point)"
                                                     if family.swept else "")},
        "margin": {"t": 50, "b": 40, "l": 40, "r": 20},
        "xaxis": {"title": {"text": "simulated time (s)"}},
        "yaxis": {"title": {"text": "energy drift (E(t) \u2212 E(0)) / energy scale"}},
        "legend": {"title": {"text": "engine"}}}
    return {"data": [_trace(r, styles) for r in [*engines, *exact]], "layout": layout}


def final_drift(family: Family) -> list[tuple[str, float]]:
    """Each series' last drift: (engine, drift), the exact reference first."""
    return [(r.engine, r.energy[-1] if r.energy else math.nan) for r in family.series]


def summary(family: Family) -> str:
    """A family's line in words: each engine's drift at the end.

    >>> s = SeriesRecord("c", "e", "b", {}, (0.0, 2.0), (0.0, -0.0123))
    >>> summary(Family("b", 0.5, False, (s,)))
    'at the end (2 s): e -0.0123'
    """
    end = max((r.times[-1] for r in family.series if r.times), default=math.nan)
    words = ", ".join(f"{'exact' if e == EXACT else e} {d:.3g}" for e, d in final_drift(family))
    return f"at the end ({end:g} s): {words}"


def section(records: Sequence[SeriesRecord], cases: Mapping[str, AnyCase],
            order: Sequence[str]) -> dict[str, Any]:
    """What the dynamics template needs: per drawn family its name, summary line and chart
    (``charts``), and how many families were left out (``omitted``)."""
    found = families(records, cases)
    drawn = chosen(found)
    names = dict.fromkeys([*order, *(r.engine for f in drawn for r in f.series
                                     if r.engine != EXACT)])
    styles = {name: i for i, name in enumerate(names)}
    charts = [{"family": f.key, "summary": summary(f),
               "html": plot_div(figure(f, styles), f"energy-{k}")}
              for k, f in enumerate(drawn)]
    return {"charts": charts, "omitted": len(found) - len(drawn)}
