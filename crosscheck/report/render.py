"""Report rendering: a stored run -> CSV files and one self-contained HTML page.

Reporting reads only the run directory (through :func:`crosscheck.results.run.read_run`,
or the :class:`~crosscheck.results.run.Run` the process that ran it already holds);
it never runs an engine, so ``crosscheck report DIR`` can re-render any stored
run.  The page is the list of :data:`crosscheck.report.sections.SECTIONS`,
each rendered from the run in its order.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from markupsafe import Markup

from crosscheck.report import claims
from crosscheck.report.parquet import write_parquet
from crosscheck.report.sections import SECTIONS, RunView
from crosscheck.report.style import packed_plotly_js, templates
from crosscheck.report.summary_tables import markdown_summary
from crosscheck.results import stored
from crosscheck.results.run import Run, read_run
from crosscheck.results.store import write_csv

__all__ = ["markdown_summary", "render", "render_html"]


Progress = Callable[[int], None]
"""Told each step of the render done (a file written, a section built): :data:`STEPS` in all."""

FILES = 8
"""The files :func:`render` writes, a step each: the results as Parquet and as CSV, five CSV
tables (summary, disagreements, asymmetries, metamorphic, claims) and report.html."""
STEPS = FILES + len(SECTIONS)
"""The steps of :func:`render` a progress bar counts."""


def render_html(view: RunView, progress: Progress | None = None) -> str:
    """The self-contained HTML report (inline CSS and JS, plotly.js once, gzip-compressed and
    base64-encoded, unpacked by the page itself; no network fetches); ``progress`` is told
    as each section is built."""
    built = []
    for section in sorted(SECTIONS, key=lambda s: s.order):
        built.append((section, section.build(view)))
        if progress:
            progress(1)
    shown = [(section, context) for section, context in built if context is not None]
    html = [{"id": section.anchor, "name": section.name,
             "html": Markup(templates().get_template(section.template).render(**context))}
            for section, context in shown]
    plots = any(section.plots(context) for section, context in shown)
    return templates().get_template("report.html.j2").render(
        info=view.info, total=len(view.frame), sections=html, missing=view.missing,
        plotly_js=packed_plotly_js() if plots else None)


def render(run: Run | Path, progress: Progress | None = None) -> dict[str, Path]:
    """Write results (CSV and typed Parquet), summary, disagreements, asymmetries,
    metamorphic and claims CSV files and report.html into the run's folder (a folder: read first).
    ``results.csv`` and ``results.parquet`` are written only when missing or stale: when the
    run's table was read from its up-to-date Parquet file
    (:attr:`~crosscheck.results.run.Run.from_stored`), neither is rewritten unless
    ``results.csv`` is older than the files the table is built from.  ``progress`` is told
    each of the :data:`STEPS` as it is done."""
    tick = progress or (lambda n: None)
    view = RunView(run if isinstance(run, Run) else read_run(run))
    directory = view.stored.directory
    paths = {"results": directory / "results.csv", "parquet": directory / stored.FILE}
    if not view.stored.from_stored:  # else the table was read from the up-to-date parquet
        write_parquet(view.stored.results, view.stored.decoded, directory)
    tick(1)
    if not (view.stored.from_stored and stored.up_to_date(directory, paths["results"])):
        write_csv(view.stored.results, directory)
    tick(1)
    for name, table in (("summary", view.summary), ("disagreements", view.disagreements),
                        ("asymmetries", view.asymmetries),
                        ("metamorphic", view.metamorphic),
                        ("claims", claims.frame(view.claim_checks))):
        paths[name] = directory / f"{name}.csv"
        table.to_csv(paths[name], index=False)
        tick(1)
    paths["report"] = directory / "report.html"
    paths["report"].write_text(render_html(view, tick), encoding="utf-8")
    tick(1)
    return paths
