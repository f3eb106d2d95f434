"""The whole suite's report as a reader sees it, at 1,400 and 1,024 px: no table hides columns
without a cue, no stability cell is coloured without a verdict, the page, as it opens
(every fold closed), is at most :data:`PAGE_HEIGHT` tall, and its advise form ranks as
``crosscheck advise`` does.  Every test of the whole suite's run (marked ``suite``) lives in
this one module, so that a parallel run (pytest -n, whole files per worker) makes the run
once."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Page

from tests.report.advise_form import REAL_PROFILES, form_and_cli
from tests.report.browser import needs_chromium, opened

pytestmark = pytest.mark.browser

PAGE_HEIGHT = 16_000
"""Pixels: the full run's page at 1,400 px, folds closed (it was 51,526 px before the folds)."""
WIDTHS = (1400, 1024)

CLIPPED = """() => {
  const bad = [], cut = [];
  const view = document.documentElement.clientWidth;
  for (const table of document.querySelectorAll("table")) {
    if (!table.checkVisibility()) continue;
    let box = table.parentElement;
    while (box !== document.body && !["auto", "scroll", "hidden"].includes(
        getComputedStyle(box).overflowX)) box = box.parentElement;
    const scrolls = box !== document.body;
    const right = scrolls ? box.getBoundingClientRect().right : view;
    const head = table.querySelector("thead tr:last-child") || table.querySelector("tr");
    let hidden = 0;
    for (const cell of head ? head.cells : []) {
      if (cell.getBoundingClientRect().right > right + 1) hidden += cell.colSpan;
    }
    if (!hidden) continue;
    const name = table.id || table.className || "a table";
    const frame = table.closest(".wide-frame");
    const cue = frame && frame.querySelector(":scope > .cue");
    const text = cue && getComputedStyle(cue).display !== "none" ? cue.innerText : "";
    cut.push([name, hidden]);
    const says = new RegExp("\\\\b" + hidden + " more columns? \\u2192");
    if (!scrolls || !says.test(text)) bad.push([name, hidden, text]);
  }
  return [bad, cut];
}"""
"""Per visible table whose header cells reach past the right edge of what is seen (its
scrolling box, else the viewport): it must scroll inside a box whose cue says how many
columns are cut off. Returns [the tables that do not, every cut table]."""


def clipped_without_cue(page: Page) -> tuple[list[Any], list[Any]]:
    bad, cut = page.evaluate(CLIPPED)
    return bad, cut


def open_every_fold(page: Page) -> None:
    page.evaluate("document.querySelectorAll('details').forEach(d => { d.open = true; })")
    page.wait_for_timeout(300)  # the toggle events update the cues


@pytest.mark.parametrize("width", WIDTHS)
def test_a_wide_table_without_a_cue_is_caught(tmp_path: Path, width: int) -> None:
    """The check can fail: a bare table wider than the page, and a scrolled one whose cue
    counts wrong, are both reported; a report-styled one is not."""
    needs_chromium()
    cells = "".join(f"<th>column {i}</th>" for i in range(40))
    page_file = tmp_path / "wide.html"
    page_file.write_text(
        f"<html><body><table id='bare'><thead><tr>{cells}</tr></thead></table>"
        f"<div class='wide-frame'><div class='cue'>2 more columns \u2192</div>"
        f"<div style='overflow-x: auto'><table id='miscounted'><thead><tr>{cells}</tr>"
        f"</thead></table></div></div></body></html>")
    with opened(page_file, width=width) as page:
        bad, _ = clipped_without_cue(page)
    assert [name for name, _, _ in bad] == ["bare", "miscounted"]


@pytest.mark.suite
@pytest.mark.engine
@pytest.mark.parametrize("width", WIDTHS)
def test_no_table_of_the_full_report_hides_columns_without_a_cue(
        suite_run: Path, width: int) -> None:
    messages: list[str] = []
    with opened(suite_run / "report.html", messages, width=width) as page:
        page.wait_for_load_state("load")
        # the results table is built after the load event, from its compressed data
        page.wait_for_selector("#results-table[data-ready]", state="attached")
        closed, cut_closed = clipped_without_cue(page)
        open_every_fold(page)
        opened_up, cut_open = clipped_without_cue(page)
    assert closed == [] and opened_up == []
    assert cut_closed or cut_open or width == 1400, "at 1,024 px some table must scroll"
    assert [m for m in messages if m.startswith(("error", "pageerror"))] == []


@pytest.mark.suite
@pytest.mark.engine
def test_the_full_report_opens_at_most_16000_px_tall(suite_run: Path) -> None:
    with opened(suite_run / "report.html") as page:
        page.wait_for_load_state("load")
        # measured once the page has settled: the results table built and the charts drawn
        # (they draw lazily, near the viewport or when idle, so a page measured at "load" on a
        # busy machine is caught halfway, some charts at their final height and some not)
        page.wait_for_selector("#results-table[data-ready]")
        page.evaluate("crosscheck.drawAllCharts()")
        height = page.evaluate("document.documentElement.scrollHeight")
        folds = page.locator("details").count()
    assert height <= PAGE_HEIGHT, f"the page is {height} px tall at 1,400 px"
    assert folds > 10  # the height is bought by folding, and the folds are there


@pytest.mark.suite
@pytest.mark.engine
def test_the_results_table_of_scene_rows_scrolls_with_a_cue_at_1024_px(suite_run: Path) -> None:
    """Scene rows bring their own columns into the results table (DataTables): wider than its
    box at 1,024 px, it scrolls there with the same cue as every other table."""
    with opened(suite_run / "report.html", width=1024) as page:
        page.wait_for_selector("#results-table[data-ready]")
        page.locator("#results-breaking").uncheck()
        page.locator("#results-table thead input").nth(2).fill("sphere_scene")  # kind
        page.wait_for_timeout(500)
        bad, cut = clipped_without_cue(page)
    assert bad == []
    assert "results-table" in [name.split()[0] for name, _ in cut]


NO_COLOUR = "rgb(228, 228, 228)"
"""The grey of a stability cell without a verdict (the legend's swatch)."""


@pytest.mark.suite
@pytest.mark.engine
def test_no_stability_cell_of_the_full_report_is_coloured_without_a_verdict(
        suite_run: Path) -> None:
    with opened(suite_run / "report.html") as page:
        page.wait_for_load_state("load")
        cells = page.evaluate("""[...document.querySelectorAll('#stability-matrix td.cell')]
            .map(c => [c.innerText, getComputedStyle(c).backgroundColor, c.title])""")
    grey = [(colour, title) for text, colour, title in cells if "no verdict" in text]
    coloured = [(text, colour, title) for text, colour, title in cells
                if "no verdict" not in text]
    assert grey and coloured  # the full run has both kinds of cell
    assert {colour for colour, _ in grey} == {NO_COLOUR}
    for text, colour, title in coloured:
        verdict = title.split("): ", 1)[1]  # "<engine> on <sweep> (<dim>; <way>): <verdict>"
        assert colour != NO_COLOUR and not verdict.startswith("no verdict"), title
        if "(distance: no verdict)" in title:  # a verdict of hit alone says so in the cell
            assert text.endswith("hit (no distance)"), (text, title)
    assert not [t for _, _, t in coloured if "pymunk on sweep-sphere-3d-offset " in t]  # 3-D


@pytest.mark.suite
@pytest.mark.engine
def test_the_advise_form_on_a_full_run_of_the_suite_ranks_as_the_cli_does(
        suite_run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the form writes the command of the profiles of the docs; the page answers the standard
    # profiles (the docs' four among them) as advise --json does, on the whole suite's run:
    # the same engines, tiers, shares and times
    found, expected, console = form_and_cli(suite_run, REAL_PROFILES, capsys)
    assert console == []
    assert found == expected
    for rows in found[len(REAL_PROFILES) + 1:len(REAL_PROFILES) + 5]:  # the docs' four
        assert rows and rows[0][1] == "pass"  # each has engines that pass its whole envelope
