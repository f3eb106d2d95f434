"""The stability section as the page shows it: a column per sweep walk and dimension, grey
"no verdict" cells, the quantity each cell summarises, and the charts folded per family."""

from __future__ import annotations

import re
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import pandas as pd
import pytest
from markupsafe import Markup

from crosscheck.core.kinds import spec
from crosscheck.report import stability
from crosscheck.report.stability import charts as stability_charts
from crosscheck.report.style import packed_plotly_js, templates
from tests.report.browser import needs_chromium, opened
from tests.report.test_report import info_of
from tests.report.test_stability import GAPS, dim_rows, render, rows, section, table_of, twin_sweep


class Matrix(HTMLParser):
    """The threshold matrix of a page: the last header row's cells and, per engine, its cells
    (each: attributes, the bold text and the small lines)."""

    def __init__(self, html: str) -> None:
        super().__init__()
        self.headers: list[dict[str, str | None]] = []
        self.cells: dict[str, list[dict[str, Any]]] = {}
        self.wrapper: dict[str, str | None] = {}
        self._row: list[dict[str, Any]] = []
        self._open: list[str] = []
        self._in = False
        self.feed(html)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        found = dict(attrs)
        if tag == "table" and found.get("id") == "stability-matrix":
            self._in = True
        if not self._in:
            if tag == "div" and not self.cells:  # the box around the table
                self.wrapper = found
            return
        self._open.append(tag)
        if tag == "tr":
            self._row = []
        elif tag in ("td", "th"):
            self._row.append({"attrs": found, "tag": tag, "b": "", "small": [], "text": ""})
        elif tag == "small" and self._row:
            self._row[-1]["small"].append("")

    def handle_endtag(self, tag: str) -> None:
        if not self._in:
            return
        if tag == "table":
            self._in = False
        elif tag == "tr" and self._row and self._row[0]["tag"] == "td":
            self.cells[self._row[0]["text"]] = self._row[1:]
        elif tag == "tr" and self._row:
            self.headers = [cell["attrs"] | {"text": cell["text"]} for cell in self._row]
        if self._open:
            self._open.pop()

    def handle_data(self, data: str) -> None:
        if not (self._in and self._row and self._open
                and self._open[-1] in ("td", "th", "b", "small")):
            return
        cell = self._row[-1]
        cell["text"] += data
        if self._open[-1] == "b":
            cell["b"] += data
        elif self._open[-1] == "small":
            cell["small"][-1] += data

    def cell(self, engine: str, title_starts: str) -> dict[str, Any]:
        """The engine's cell under the header whose title starts so."""
        (at,) = [i for i, h in enumerate(self.headers)
                 if str(h.get("title", "")).startswith(title_starts)]
        found: dict[str, Any] = self.cells[engine][at]
        return found


def coloured(cell: dict[str, Any]) -> bool:
    return "hsl(" in str(cell["attrs"].get("style", ""))


def twin_run() -> pd.DataFrame:
    """A 3-D gap sweep and its 2-D twin: ``flat`` skips every 3-D point and holds in 2-D,
    ``both`` holds in 3-D and breaks in 2-D, ``solid`` runs only the 3-D sweep."""
    cases = twin_sweep()
    agree, late = ["agree"] * 4, ["agree", "agree", "disagree", "disagree"]
    frame = pd.DataFrame(dim_rows(cases, 3, "both", agree) + dim_rows(cases, 2, "both", late)
                         + dim_rows(cases, 3, "flat", ["skip"] * 4)
                         + dim_rows(cases, 2, "flat", agree) + dim_rows(cases, 3, "solid", agree))
    return stability.sweep_points(frame, cases)


def test_a_2d_twin_has_columns_of_its_own_beside_its_3d_sweep() -> None:
    table = stability.thresholds(twin_run())
    shown = table[table["headline"]]
    assert set(shown["column"]) == {"g (smaller)", "g.2d (smaller)"}
    for column, dim in (("g (smaller)", 3), ("g.2d (smaller)", 2)):
        assert set(shown.loc[shown["column"] == column, "dim"]) == {dim}
    assert set(shown["family"]) == {"g"}
    both = shown[shown["engine"] == "both"].set_index("dim")
    assert both.loc[3, "state"] == "none" and both.loc[2, "threshold"] == GAPS[2]
    headers = [c["label"] for c in stability.matrix(table)["columns"]]
    assert headers == ["3-D", "2-D"]  # the 3-D sweep first, its twin beside it


def test_a_2d_engine_skipping_every_3d_point_has_no_verdict_in_the_3d_column() -> None:
    """Even though its 2-D twin holds: the 3-D column shows 3-D rows only."""
    page = Matrix(render(section(twin_run())))
    cell = page.cell("flat", "g (3-D")
    assert not coloured(cell) and "grey" in str(cell["attrs"]["class"])
    assert cell["small"] == ["no verdict"]
    assert "no verdict" in str(cell["attrs"]["title"])


def test_the_2d_twins_verdict_is_in_the_2d_column() -> None:
    page = Matrix(render(section(twin_run())))
    flat, both = page.cell("flat", "g.2d (2-D"), page.cell("both", "g.2d (2-D")
    assert coloured(flat) and flat["b"] == "none"
    assert "none in range" in str(flat["attrs"]["title"])
    assert both["b"] == f"{GAPS[2]:.3g}" and "breaks at" in str(both["attrs"]["title"])
    assert page.cell("both", "g (3-D")["b"] == "none"  # its 3-D walk holds


def test_an_engine_without_rows_in_a_column_has_no_verdict() -> None:
    page = Matrix(render(section(twin_run())))
    cell = page.cell("solid", "g.2d (2-D")
    assert not coloured(cell) and cell["small"] == ["no verdict"]
    assert "not run" in str(cell["attrs"]["title"])


def test_every_cell_with_a_verdict_names_its_quantity() -> None:
    frame = pd.DataFrame(rows("g", "gap", [(0.1, "agree"), (1e-3, "disagree")], engine="a")
                         + rows("r", "mass_ratio", [(1.0, "agree")], engine="a", quantity="v2",
                                kind="sphere_response"))
    page = Matrix(render(section(stability.sweep_points(frame, {}))))
    gap, ratio = page.cells["a"]
    assert gap["small"][-1] == spec("sphere").headline and coloured(gap)
    assert ratio["small"][-1] == spec("sphere_response").headline


def test_a_fallback_to_hit_is_labelled() -> None:
    frame = pd.DataFrame(rows("g", "gap", [(g, "skip") for g in GAPS], engine="flat")
                         + rows("g", "gap", [(g, "agree") for g in GAPS], engine="flat",
                                quantity="hit"))
    page = Matrix(render(section(stability.sweep_points(frame, {}))))
    (cell,) = page.cells["flat"]
    assert cell["small"][-1] == "hit (no distance)" and coloured(cell)
    assert "hit: none in range" in str(cell["attrs"]["title"])
    assert "(distance: no verdict)" in str(cell["attrs"]["title"])


def test_the_matrix_scrolls_in_a_wide_box_with_the_engine_column_held() -> None:
    page = Matrix(render(section(twin_run())))
    assert page.wrapper.get("class") == "wide"
    html = render(section(twin_run()))
    engine_cell = re.search(r"<tr><td style=\"([^\"]*)\">flat</td>", html)
    assert engine_cell and "position: sticky; left: 0" in engine_cell.group(1)
    assert "background: white" in engine_cell.group(1)


# --- the folded charts --------------------------------------------------------------------------


def test_the_fold_headline_counts_engines_from_the_thresholds() -> None:
    early = [(0.1, "agree"), (1e-3, "agree"), (1e-5, "disagree")]
    table = table_of(rows("g", "gap", early, engine="late"),
                     rows("g", "gap", [(0.1, "agree"), (1e-3, "error")], engine="soon"),
                     rows("v", "overlap", early, engine="soon"),  # an engine counts once
                     rows("g", "gap", [(0.1, "agree")], engine="steady"),
                     rows("g", "gap", [(0.1, "skip")], engine="idle"))
    axis = stability.AXES["gap"]
    assert stability_charts.headline(table, axis, "sphere") == (
        f"{axis}, sphere: 2 of 3 engines break, first at gap 0.001 (soon)")
    table = table_of(rows("g", "gap", early, engine="late"),
                     rows("g", "gap", [(0.1, "crash")], engine="at once"))
    assert stability_charts.headline(table, axis, "sphere") == (
        f"{axis}, sphere: 2 of 2 engines break, 1 at the easiest value (at once)")
    table = table_of(rows("g", "gap", [(0.1, "agree")], engine="steady"),
                     rows("g", "gap", [(0.1, "disagree")], engine="steady", quantity="normal"))
    assert stability_charts.headline(table, axis, "sphere") == (
        f"{axis}, sphere: no engine breaks (1 with a verdict on distance); normal: 1 of 1 break")


def test_charts_are_folded_closed_one_fold_per_family_headed_by_its_headline() -> None:
    frame = pd.DataFrame(rows("g", "gap", [(0.1, "agree"), (1e-3, "disagree")], engine="a")
                         + rows("g", "gap", [(0.1, "agree"), (1e-3, "agree")], engine="a",
                                quantity="normal")
                         + rows("o", "offset", [(1.0, "agree"), (1e3, "agree")], engine="a"))
    points = stability.sweep_points(frame, {})
    table = stability.thresholds(points)
    html = render(section(points))
    folds = re.findall(r"<details class=\"fold\"( open)?><summary>([^<]*)</summary>(.*?)</details>",
                       html, re.S)
    expected = [stability_charts.headline(table, stability.AXES[p], "sphere")
                for p in ("gap", "offset")]
    assert [summary for _, summary, _ in folds] == expected
    assert not any(opened for opened, _, _ in folds)  # closed by default
    assert [body.count('class="chart"') for _, _, body in folds] == [2, 1]  # distance, normal
    assert html.count('class="chart"') == 3  # every chart is in a fold


@pytest.mark.browser
def test_a_chart_drawn_in_a_closed_fold_fits_its_box_once_opened(tmp_path: Path) -> None:
    """Charts are drawn when idle, folded or not: one drawn while its fold gave it no width
    (``display: none`` here, as a browser may lay out nothing in a closed <details>) is drawn
    again to its box's width when the fold opens, and drawing every chart throws nothing."""
    needs_chromium()
    hidden = "<style>details:not([open]) .chart { display: none }</style>"
    body = hidden + render(section(twin_run()))
    page_file = tmp_path / "report.html"
    page_file.write_text(templates().get_template("report.html.j2").render(
        info=info_of(), total=0, missing=0, plotly_js=packed_plotly_js(),
        sections=[{"id": "section-stability", "name": "stability", "html": Markup(body)}]))
    messages: list[str] = []
    with opened(page_file, messages) as page:
        page.wait_for_load_state("load")
        page.evaluate("crosscheck.drawAllCharts()")
        page.locator("#stability-charts details summary").first.click()
        page.wait_for_timeout(500)
        widths = page.evaluate("""[...document.querySelectorAll(
            '#stability-charts details[open] .plotly-graph-div')].map(div => [
            Math.round(div.getBoundingClientRect().width),
            Math.round(div.querySelector('svg.main-svg').getBoundingClientRect().width)])""")
    assert [m for m in messages if m.startswith(("error", "pageerror"))] == []
    assert widths and all(box == drawn and box > 700 for box, drawn in widths), widths
