"""The coverage map as a user sees it, in headless Chromium (:mod:`tests.report.browser`): the
report's coverage section (folded) and ``coverage.html``, the page ``crosscheck coverage``
writes for a fuzz campaign (open): the grid is drawn, choosing the engine recolours its cells
in the colours Python decided, empty cells are hatched and a space's fold opens to its grid."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd
import pytest
from playwright.sync_api import Locator, Page

from crosscheck.cli import main
from crosscheck.core.model import Category, Kind, Status
from crosscheck.core.options import RunOptions
from crosscheck.report.coverage import label_ranks, rank_of
from crosscheck.report.coverage_page import CODES, EMPTY, legend
from crosscheck.studies.fuzz.campaign import fuzz
from tests.fakes import AlwaysRight, OffByOne
from tests.report.advise_form import errors
from tests.report.browser import needs_chromium, opened

pytestmark = pytest.mark.browser

COVERAGE_CELLS = """fold => Array.from(fold.querySelectorAll('table.coverage-grid tbody td')).map(
    td => [td.dataset.row, td.dataset.column, td.dataset.code, getComputedStyle(td).backgroundImage,
           getComputedStyle(td).backgroundColor, td.title])"""
"""Every drawn cell of a coverage fold's grid: its levels, code, background, title."""


def rgb(colour: str) -> str:
    """A ``#rrggbb`` colour as the browser computes it."""
    r, g, b = (int(colour[i:i + 2], 16) for i in (1, 3, 5))
    return f"rgb({r}, {g}, {b})"


def drawn_per_engine(page: Page, fold: Locator, engines: list[str]) -> dict[str, list[Any]]:
    """Each engine chosen in turn: the cells of ``fold``'s grid."""
    drawn = {}
    for engine in engines:
        page.select_option("#coverage-engine", label=engine)
        drawn[engine] = fold.evaluate(COVERAGE_CELLS)
    return drawn


def assert_hatched(cells: list[Any]) -> None:
    empty = [c for c in cells if c[2] == EMPTY]
    assert empty and all("repeating-linear-gradient" in c[3] for c in empty)


def test_the_reports_coverage_section_draws_each_engines_worst_label_and_the_empty_cells(
        fakes_dir: Path) -> None:
    """The coverage section is one fold (the page opens short); inside, the first space's
    fold draws its first grid (direction x gap) for the chosen engine: the cell of the run's
    cases (along +x, gap 1) takes each engine's worst label over their rows, so choosing the
    other engine recolours it; every cell no case asks is hatched; choosing another pair
    draws that grid."""
    results = pd.read_csv(fakes_dir / "results.csv", keep_default_na=False)
    judged = results[~results["tags"].str.contains("bad-input")]
    worst = {str(e): CODES[int(label_ranks(rows["status"], rows["category"]).min())]
             for e, rows in judged.groupby("engine", sort=False)}
    assert len(set(worst.values())) == 2  # the engines differ there
    messages: list[str] = []
    with opened(fakes_dir / "report.html", messages) as page:
        page.wait_for_selector("#coverage[data-ready]", state="attached")
        closed = page.locator("table.coverage-grid").first.is_visible()
        page.locator("#coverage > summary").click()  # the section is one fold, closed
        fold = page.locator("#coverage details.coverage-space[open]").first
        drawn = drawn_per_engine(page, fold, list(worst))
        heads = fold.locator("table.coverage-grid thead th").all_text_contents()
        fold.locator("select.coverage-pair").select_option(label="direction x size ratio")
        other = fold.locator("table.coverage-grid thead th").all_text_contents()
    assert errors(messages) == []
    assert not closed
    assert heads[0].startswith("direction") and "+1" in heads and "deep" in heads
    assert other[0].startswith("direction") and "1e6" in other and "deep" not in other
    colours = {}
    for engine, cells in drawn.items():
        held = [c for c in cells if c[2] != EMPTY]
        assert [(r, k) for r, k, *_ in held] == [("+x", "+1")], engine
        colours[engine] = held[0][4]
        assert held[0][2] == worst[engine] and "4 cases" in held[0][5]
        assert len(cells) - 1 == len([c for c in cells if c[2] == EMPTY])
        assert_hatched(cells)
    assert len(set(colours.values())) == 2, colours


@pytest.fixture(scope="module")
def campaign_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small fuzz campaign of boxes on the two fakes, mapped by ``crosscheck coverage``."""
    needs_chromium()
    folder = tmp_path_factory.mktemp("coverage-campaign") / "campaign"
    fuzz(Kind.AABB, 40, 5, folder, [AlwaysRight(), OffByOne()],
         RunOptions(quick=True, jobs=1), per_group=1, command="test")
    assert main(["coverage", str(folder)]) == 0
    return folder


def expected_codes(campaign: Path, engine: str) -> dict[tuple[str, str], str]:
    """Per held cell of the aabb 3-D direction x gap grid: the code of ``engine``'s worst
    label in coverage.csv."""
    table = pd.read_csv(campaign / "coverage.csv", keep_default_na=False,
                        dtype={"level_1": str, "level_2": str})
    rows = table[(table["kind"] == "aabb") & (table["dim"] == 3) & (table["cases"] > 0)
                 & (table["dimension_1"] == "direction") & (table["dimension_2"] == "gap")
                 & (table["dimension_3"] == "") & (table["engine"] == engine)]
    return {(str(a), str(b)): CODES[rank_of(Status(s), Category(c) if c else None)]
            for a, b, s, c in zip(rows["level_1"], rows["level_2"], rows["worst_status"],
                                  rows["worst_category"], strict=True)}


def test_a_campaigns_coverage_page_draws_the_grids_python_decided(campaign_dir: Path) -> None:
    """coverage.html opens on the section, open: the first space's grid (aabb 3-D, direction
    x gap) is drawn for the chosen engine, each held cell with the code of coverage.csv and
    the legend's colour; choosing the other engine recolours the cells; empty cells are
    hatched; the next space's fold, closed, opens to its own grid."""
    engines = ["fake-right", "fake-off"]
    colour = {entry["code"]: entry["colour"] for entry in legend()}
    messages: list[str] = []
    with opened(campaign_dir / "coverage.html", messages) as page:
        page.wait_for_selector("#coverage[data-ready]", state="attached")
        title = page.locator("h1").inner_text()
        fold = page.locator("#coverage details.coverage-space").first
        shown = fold.locator("table.coverage-grid").is_visible()
        drawn = drawn_per_engine(page, fold, engines)
        second = page.locator("#coverage details.coverage-space").nth(1)
        hidden = second.locator("table.coverage-grid").is_visible()
        second.locator("summary").click()
        opens = second.locator("table.coverage-grid").is_visible()
        cells = second.locator("table.coverage-grid tbody td[data-code]").count()
        requests = page.evaluate("performance.getEntriesByType('resource').map(e => e.name)")
    assert errors(messages) == [] and [r for r in requests if r.startswith("http")] == []
    assert title == f"Collision Crosscheck: coverage of fuzz campaign {campaign_dir.name}"
    assert shown and not hidden and opens and cells > 0
    for engine, grid in drawn.items():
        held = {(r, k): (code, background) for r, k, code, _, background, _ in grid
                if code != EMPTY}
        assert {cell: code for cell, (code, _) in held.items()} == expected_codes(
            campaign_dir, engine)
        assert all(background == rgb(colour[code]) for code, background in held.values())
        assert_hatched(grid)
    assert {code for _, _, code, *_ in drawn["fake-right"]} == {EMPTY, CODES[rank_of(
        Status.AGREE)]}
    assert [c[4] for c in drawn["fake-right"]] != [c[4] for c in drawn["fake-off"]]
