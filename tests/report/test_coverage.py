"""The coverage map: cases placed in the cells of the configuration space, each engine's worst
label (status, and a disagree's category) and largest error in bounds per cell, the empty
cells, a campaign's unlisted cases, the report's coverage section (its packed grids, its place
in the page) and the coverage page of its own."""

from __future__ import annotations

import base64
import gzip
import json
import math
from typing import Any

import numpy as np
import pandas as pd
import pytest

from crosscheck.cases.cover import coverage, expand_cover
from crosscheck.cases.space import classify
from crosscheck.core.model import Category, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, CoverBlock
from crosscheck.report import coverage_page
from crosscheck.report.coverage import (
    LABELS,
    ROW_COLUMNS,
    CoverageMap,
    campaign_map,
    covered,
    empty_cells,
    label_ranks,
    rank_of,
    run_map,
    space_cells,
)
from crosscheck.report.render import render
from crosscheck.results.run import read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests.conftest import aabb, embedded, sphere
from tests.fakes import AlwaysRight, OffByOne

UNIT = [1.0, 1.0, 1.0]


def along_y(gap: float = 1.0, **extra: Any) -> AnyCase:
    """Two unit boxes, B apart from A along +y by ``gap`` times the touching displacement."""
    return aabb([0.0, 0.0, 0.0], UNIT, [0.0, 2.0 * (1.0 + gap), 0.0], UNIT, **extra)


def row(case: AnyCase, engine: str, quantity: str, status: Status, error: float = 0.0,
        tolerance: float = 1e-15, category: str = "") -> dict[str, Any]:
    if status is Status.DISAGREE and not category:
        category = "error"
    return {"case_id": case.id, "engine": engine, "kind": case.kind, "quantity": quantity,
            "status": str(status), "category": category, "error": error,
            "tolerance": tolerance}


def agreeing(cases: list[AnyCase], engine: str) -> list[dict[str, Any]]:
    return [row(c, engine, q, Status.AGREE) for c in cases for q in ("hit", "distance", "normal")]


def rows_of(records: list[dict[str, Any]]) -> pd.DataFrame:
    return pd.DataFrame(records, columns=list(ROW_COLUMNS))


def cell(found: CoverageMap, engine: str, **levels: str) -> pd.Series:
    """The one row of ``engine`` in the 2-way cell of ``levels`` (kind aabb, 3-D)."""
    (first, a), (second, b) = levels.items()
    t = found.table
    match = t[(t["kind"] == "aabb") & (t["dim"] == 3) & (t["dimension_1"] == first)
              & (t["level_1"] == a) & (t["dimension_2"] == second) & (t["level_2"] == b)
              & (t["dimension_3"] == "") & (t["engine"] == engine)]
    assert len(match) == 1, match
    return match.iloc[0]


def test_two_boxes_apart_along_y_at_gap_1_are_one_case_in_that_cell() -> None:
    case = along_y(id="y1")
    assert classify(case)["direction"] == "+y" and classify(case)["gap"] == "+1"
    found = run_map({case.id: case}, rows_of(agreeing([case], "e")), ["e"])
    assert cell(found, "e", direction="+y", gap="+1")["cases"] == 1
    assert cell(found, "e", direction="+x", gap="+1")["cases"] == 0
    assert cell(found, "e", direction="+y", gap="+10")["cases"] == 0
    held = found.table[(found.table["cases"] > 0) & (found.table["dimension_3"] == "")]
    placed = len(classify(case))  # at offset 0 it has no offset axis
    assert placed == len(space_cells(case.kind_enum, 3).space.names) - 1
    assert len(held) == placed * (placed - 1) // 2  # one cell of every pair it is placed on
    assert found.cases == {(case.kind_enum, 3): 1}


def test_the_worst_status_is_the_most_severe_and_names_its_case() -> None:
    cases = [along_y(id="fine"), along_y(id="wrong"), along_y(id="dies"), along_y(id="other")]
    records = agreeing(cases[:1], "e") + agreeing(cases, "calm")
    records += [row(cases[1], "e", "distance", Status.DISAGREE, 1e-3),
                row(cases[1], "e", "hit", Status.AGREE), row(cases[1], "e", "normal", Status.SKIP)]
    records += [row(cases[2], "e", q, Status.CRASH, math.nan, math.nan)
                for q in ("hit", "distance", "normal")]
    records += [row(cases[3], "e", "normal", Status.UNDEFINED, math.nan, math.nan)]
    found = run_map({c.id: c for c in cases}, rows_of(records), ["e", "calm"])
    worst = cell(found, "e", direction="+y", gap="+1")
    assert worst["cases"] == 4
    assert (worst["worst_status"], worst["worst_case"]) == ("crash", "dies")
    without = run_map({c.id: c for c in cases[:2]}, rows_of(records), ["e"])
    assert cell(without, "e", direction="+y", gap="+1")["worst_status"] == "disagree"
    assert cell(without, "e", direction="+y", gap="+1")["worst_case"] == "wrong"
    assert cell(found, "calm", direction="+y", gap="+1")["worst_status"] == "agree"


def test_the_largest_error_is_in_units_of_each_rows_bound() -> None:
    a, b = along_y(id="a"), along_y(id="b")
    records = [row(a, "e", "distance", Status.DISAGREE, 3e-12, 1e-15),  # 3,000 bounds
               row(b, "e", "distance", Status.DISAGREE, 5e-9, 1e-10),  # 50 bounds
               row(b, "e", "normal", Status.AGREE, 0.0, 0.0),  # 0 over a bound of 0: 0
               row(a, "e", "hit", Status.DISAGREE, 1.0, 0.0),  # a verdict: its status says it
               row(b, "e", "hit", Status.AGREE, 0.0, 0.0)]
    found = run_map({"a": a, "b": b}, rows_of(records), ["e"])
    assert cell(found, "e", direction="+y", gap="+1")["max_error_bounds"] == pytest.approx(3000)
    zero = run_map({"b": b}, rows_of(records[2:3]), ["e"])
    assert cell(zero, "e", direction="+y", gap="+1")["max_error_bounds"] == 0.0
    unbounded = rows_of([row(b, "e", "distance", Status.DISAGREE, 1e-3, 0.0)])
    assert math.isinf(cell(run_map({"b": b}, unbounded, ["e"]), "e", direction="+y",
                           gap="+1")["max_error_bounds"])
    crashed = rows_of([row(b, "e", "distance", Status.CRASH, math.nan, math.nan)])
    assert math.isnan(cell(run_map({"b": b}, crashed, ["e"]), "e", direction="+y",
                           gap="+1")["max_error_bounds"])


def test_bad_input_cases_and_scenes_are_left_out() -> None:
    good = along_y(id="good")
    bad = along_y(id="bad", tags=["bad-input"])
    found = run_map({"good": good, "bad": bad}, rows_of(agreeing([good, bad], "e")), ["e"])
    assert cell(found, "e", direction="+y", gap="+1")["cases"] == 1
    assert run_map({"bad": bad}, rows_of(agreeing([bad], "e")), ["e"]).table.empty


def test_an_engine_without_rows_in_a_cell_has_no_status_there() -> None:
    case = along_y(id="y1")
    found = run_map({case.id: case}, rows_of(agreeing([case], "e")), ["e", "stopped"])
    stopped = cell(found, "stopped", direction="+y", gap="+1")
    assert stopped["cases"] == 1 and stopped["worst_status"] == "" and stopped["worst_case"] == ""


def test_the_empty_cells_are_every_cell_without_a_case() -> None:
    cases = [along_y(id="y1"), aabb([0.0, 0.0, 0.0], UNIT, [2.2, 0.0, 0.0], UNIT, id="x01")]
    found = run_map({c.id: c for c in cases}, rows_of(agreeing(cases, "e")), ["e"])
    empty = empty_cells(found.table)
    every = space_cells(cases[0].kind_enum, 3).cells
    assert len(empty) == len(every) - int((found.table["cases"] > 0).sum())
    listed = set(zip(empty["dimension_1"], empty["level_1"], empty["dimension_2"],
                     empty["level_2"], empty["dimension_3"], strict=True))
    assert ("direction", "+x", "gap", "+1", "") in listed
    assert ("direction", "+y", "gap", "+1", "") not in listed
    assert ("direction", "+x", "gap", "+1e-1", "") not in listed  # x01: 2.2 = 2 x (1 + 0.1)


@pytest.mark.parametrize(("kind", "dims", "levels"), [
    ("sphere", ("direction", "gap", "size_ratio"), {"gap": ("0", "+1", "+1e3")}),
    ("sphere_response", ("direction", "size_ratio", "mass_ratio"), {"mass_ratio": ("1", "1e6")}),
])
def test_the_cells_covered_are_those_crosscheck_validate_counts(
        kind: str, dims: tuple[str, ...], levels: dict[str, tuple[str, ...]]) -> None:
    block = CoverBlock(id="cv", description="d", kind=kind, dim=3, dimensions=dims,
                       levels=levels, strength=3)
    cases = expand_cover(block).cases
    found = run_map({c.id: c for c in cases}, rows_of(agreeing(cases, "e")), ["e"])
    (space,) = covered(found.table)
    two, three = coverage(cases, 2), coverage(cases, 3)
    in_3d = [(c2, c3) for c2, c3 in zip(two, three, strict=True)
             if c2.kind.value == kind and c2.dim == 3]
    (counted2, counted3), = in_3d
    assert (space["covered_2"], space["cells_2"]) == (counted2.covered, counted2.cells)
    assert (space["covered_3"], space["cells_3"]) == (counted3.covered, counted3.cells)
    assert counted3.covered > 0


def test_a_campaigns_cases_without_a_finding_agree() -> None:
    cases = [along_y(id="quiet"), along_y(id="found"), along_y(10.0, id="far")]
    findings = rows_of([row(cases[1], "off", "distance", Status.DISAGREE, 2e-13, 1e-15)])
    found = campaign_map(iter(cases), findings, ["off", "right"])
    noisy = cell(found, "off", direction="+y", gap="+1")
    assert (noisy["cases"], noisy["worst_status"], noisy["worst_case"]) == (2, "disagree", "found")
    assert noisy["max_error_bounds"] == pytest.approx(200)
    quiet = cell(found, "right", direction="+y", gap="+1")
    assert (quiet["worst_status"], quiet["worst_case"]) == ("agree", "")
    assert math.isnan(quiet["max_error_bounds"])  # agreeing rows are not stored
    far = cell(found, "off", direction="+y", gap="+10")
    assert (far["cases"], far["worst_status"]) == (1, "agree")


WORST_FIRST = ["error", "timestep", "convention", "tolerance"]
"""The categories of a disagree, the worst (unexplained) first: what the map must rank by."""


@pytest.mark.parametrize("worse, milder", [(a, b) for i, a in enumerate(WORST_FIRST)
                                           for b in WORST_FIRST[i + 1:]])
def test_among_disagreements_the_worse_category_wins_whatever_the_errors(
        worse: str, milder: str) -> None:
    """A cell's worst label is the worse category even when the milder one's error is larger
    (the tie-break of equal labels) and comes first in case order."""
    mild, bad = along_y(id="mild"), along_y(id="bad")
    records = [row(mild, "e", "distance", Status.DISAGREE, 1e-9, category=milder),
               row(bad, "e", "distance", Status.DISAGREE, 1e-14, category=worse)]
    found = run_map({"mild": mild, "bad": bad}, rows_of(records), ["e"])
    worst = cell(found, "e", direction="+y", gap="+1")
    assert (worst["worst_status"], worst["worst_category"], worst["worst_case"]) == (
        "disagree", worse, "bad")
    assert worst["max_error_bounds"] == pytest.approx(1e6)  # the largest error, any category


def test_a_failed_status_is_worse_than_any_disagreement_and_agree_has_no_category() -> None:
    a, b = along_y(id="a"), along_y(id="b")
    records = [row(a, "e", "distance", Status.DISAGREE, 1.0, category="error"),
               row(b, "e", "distance", Status.ERROR, math.nan, math.nan)]
    records += agreeing([a, b], "calm")
    found = run_map({"a": a, "b": b}, rows_of(records), ["e", "calm"])
    worst = cell(found, "e", direction="+y", gap="+1")
    assert (worst["worst_status"], worst["worst_category"], worst["worst_case"]) == (
        "error", "", "b")
    calm = cell(found, "calm", direction="+y", gap="+1")
    assert (calm["worst_status"], calm["worst_category"]) == ("agree", "")


def test_a_disagreement_without_a_known_category_counts_as_unexplained() -> None:
    a, b = along_y(id="a"), along_y(id="b")
    records = [row(a, "e", "distance", Status.DISAGREE, 1e-9, category="tolerance"),
               {**row(b, "e", "distance", Status.DISAGREE, 1e-14), "category": math.nan}]
    found = run_map({"a": a, "b": b}, rows_of(records), ["e"])
    worst = cell(found, "e", direction="+y", gap="+1")
    assert (worst["worst_category"], worst["worst_case"]) == ("error", "b")


def test_the_categories_have_one_order_the_disagreements_table_shares() -> None:
    from crosscheck.report.summary_tables import disagreements
    assert sorted(WORST_FIRST, key=lambda c: Category(c).severity) == WORST_FIRST
    frame = pd.DataFrame({"status": ["disagree"] * 5 + ["crash"],
                          "category": ["tolerance", "", "convention", "error", "timestep", ""],
                          "error": [9.0, 9.0, 9.0, 1.0, 9.0, math.nan]})
    assert list(disagreements(frame)["category"]) == ["", *WORST_FIRST, ""]


def grid(context: dict[str, Any], space: int, label: str) -> dict[str, Any]:
    """The packed data of one grid of the section's ``space``-th space."""
    data = json.loads(gzip.decompress(base64.b64decode(context["coverage"]["packed"])))
    labels = context["coverage"]["spaces"][space]["grids"]
    return dict(data["spaces"][space]["grids"][labels.index(label)])


def code_at(g: dict[str, Any], engine: int, row_level: str, column_level: str,
            key: str = "status") -> str:
    i = g["row_levels"].index(row_level) * len(g["column_levels"]) + \
        g["column_levels"].index(column_level)
    return str(g[key][engine][i])


def code(status: Status, category: Category | None = None) -> str:
    """The page's code of a label."""
    return coverage_page.CODES[rank_of(status, category)]


def test_the_page_grid_packs_each_engines_worst_label_and_the_empty_cells() -> None:
    cases = [along_y(id="y1"), along_y(id="y2")]
    engines = ["right", "off", "soft"]
    records = agreeing(cases, "right") + agreeing(cases[:1], "off") + agreeing(cases, "soft")
    records += [row(cases[1], "off", "distance", Status.DISAGREE, 1e-12, 1e-15)]
    records += [row(cases[0], "soft", "normal", Status.DISAGREE, 1e-9, category="tolerance")]
    found = run_map({c.id: c for c in cases}, rows_of(records), engines)
    context = coverage_page.section(found, engines, "crosscheck coverage RUN")
    assert context is not None
    space = context["coverage"]["spaces"][0]
    assert space["grids"][0] == "direction x gap"  # the most informative pair first
    assert (space["kind"], space["dim"], space["cases"]) == ("aabb", 3, 2)
    g = grid(context, 0, "direction x gap")
    assert code_at(g, 0, "+y", "+1") == code(Status.AGREE)
    assert code_at(g, 1, "+y", "+1") == code(Status.DISAGREE, Category.ERROR)
    assert code_at(g, 2, "+y", "+1") == code(Status.DISAGREE, Category.TOLERANCE)
    assert len({code(Status.AGREE), code(Status.DISAGREE, Category.ERROR),
                code(Status.DISAGREE, Category.TOLERANCE)}) == 3
    n = int((found.table["cases"] > 0).sum()) // 3 - 1  # 2-way cells held (one 3-way)
    unexplained, explained = space["breaking"].split(";")
    assert f"right 0, off {n}, soft 0" in unexplained
    assert f"right 0, off 0, soft {n}" in explained
    assert code_at(g, 1, "+x", "+1") == coverage_page.EMPTY
    assert code_at(g, 1, "+y", "+1", "error") == coverage_page.error_codes(np.array([1e3]))[0]
    assert g["cases"][g["row_levels"].index("+y") * len(g["column_levels"])
                      + g["column_levels"].index("+1")] == 2
    axes = grid(context, 0, "offset x offset axis")
    assert code_at(axes, 0, "0", "x") == coverage_page.NO_CELL  # no axis at offset 0
    assert "direction x gap at size ratio 1" in space["grids"]


def test_every_label_has_its_own_colour_and_the_legend_lists_them_most_severe_first() -> None:
    entries = coverage_page.legend()
    labels = [e["label"].split(" (")[0] for e in entries[:len(LABELS)]]
    assert labels == ["crash", "timeout", "error", *(f"disagree, {c}" for c in WORST_FIRST),
                      "undefined", "skip", "agree"]
    assert "within the engine's declared tolerance" in entries[6]["label"]
    assert len({e["colour"] for e in entries}) == len(entries)
    assert len({e["code"] for e in entries}) == len(entries)
    assert coverage_page.colours(Status.DISAGREE, Category.ERROR)[0] == "#e06666"  # red


def test_the_report_has_the_coverage_section_with_its_packed_grids(tmp_path: Any) -> None:
    folder = tmp_path / "run"
    cases = [sphere(0.0, 2.0 + i / 4, id=f"s{i}") for i in range(3)]
    cases += [sphere(math.nan, math.inf, ra=math.nan, id="s-nan", tags=["bad-input"])]
    options, engines = RunOptions(quick=True, isolate=False), [AlwaysRight(), OffByOne()]
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    html = render(folder)["report"].read_text(encoding="utf-8")
    assert "<h2>Coverage of the configuration space</h2>" in html
    assert f"crosscheck coverage {folder}" in html
    data = embedded(html, "coverage-data")
    assert data["engines"] == ["fake-right", "fake-off"]
    stored = read_run(folder)
    results = stored.results
    found = run_map(stored.cases, results, data["engines"])
    g = data["spaces"][0]["grids"][0]
    for e, engine in enumerate(data["engines"]):
        mine = results[(results["engine"] == engine) & (results["case_id"] != "s-nan")]
        worst = int(label_ranks(mine["status"], mine["category"]).min())
        assert code_at(g, e, "+x", "+1") == coverage_page.CODES[worst]
    assert int(found.table["cases"].max()) == 3  # the bad-input case is in no cell


def test_the_coverage_page_is_the_section_open_in_a_page_of_its_own() -> None:
    case = along_y(id="y1")
    found = campaign_map([case], rows_of([]), ["e"])
    html = coverage_page.page_html(found, ["e"], "crosscheck coverage CAMPAIGN", "coverage of X",
                                   "Fuzz campaign X: 1 case.", "campaign")
    assert '<details class="fold" id="coverage" open>' in html
    assert "<h1>Collision Crosscheck: coverage of X</h1>" in html
    assert "Each case of the campaign" in html and "cc.unpack = function" in html
    assert embedded(html, "coverage-data")["engines"] == ["e"]
    bad = along_y(id="bad", tags=["bad-input"])
    nothing = coverage_page.page_html(campaign_map([bad], rows_of([]), ["e"]), ["e"], "c", "t",
                                      "a", "campaign")
    assert "No case of this folder has a cell" in nothing and 'id="coverage"' not in nothing
