"""The stability study: thresholds along sweeps, relative errors, charts, template and command
(the matrix cells and the folded charts as the page shows them: test_stability_page.py)."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

import adapters
from crosscheck.cases.expand import expand
from crosscheck.cases.load import load_paths
from crosscheck.cli import stability as stability_command
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER
from crosscheck.report import stability
from crosscheck.report.stability import charts as stability_charts
from crosscheck.report.style import templates
from crosscheck.results.run import read_cases, read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from crosscheck.truth import scene_rules
from tests.conftest import ROOT

EVIL = "<script>alert('pwned')</script>"


def rows(sweep: str, param: str, walk: list[tuple[float, str]], engine: str = "e",
         quantity: str = "distance", kind: str = "sphere") -> list[dict[str, Any]]:
    """Result rows of one sweep for one engine: (value, status) pairs, in any order."""
    return [{"case_id": f"{sweep}.{param}={value:.6g}", "kind": kind, "dim": 3, "engine": engine,
             "quantity": quantity, "value": "0.0", "status": status, "error": 1e-6,
             "tolerance": 1e-9, "category": "tolerance" if status == "disagree" else "",
             "origin": sweep, "coords": json.dumps({param: value}), "twin_of": ""}
            for value, status in walk]


def table_of(*parts: list[dict[str, Any]]) -> pd.DataFrame:
    frame = pd.DataFrame([row for part in parts for row in part])
    return stability.thresholds(stability.sweep_points(frame, {}))


def only(table: pd.DataFrame, **where: Any) -> dict[str, Any]:
    mask = pd.Series(True, index=table.index)
    for column, value in where.items():
        mask &= table[column] == value
    found: list[dict[str, Any]] = table[mask].to_dict("records")  # type: ignore[assignment]
    assert len(found) == 1, found
    return found[0]


GAPS = [1e-1, 1e-3, 1e-5, 1e-7]


def test_gap_walks_from_the_largest_value_down() -> None:
    walk = list(zip(GAPS, ["agree", "agree", "disagree", "disagree"], strict=True))
    row = only(table_of(rows("g", "gap", walk[::-1])))  # input order does not matter
    assert row["threshold"] == 1e-5 and row["state"] == "breaks" and not row["recovers"]
    assert row["verdict"] == "breaks at 1e-05 (disagree, tolerance)"
    assert row["axis"] == "gap or overlap relative to size" and row["easiest"] == 0.1


def test_offset_walks_from_the_smallest_value_up() -> None:
    walk = [(1.0, "agree"), (1e3, "agree"), (1e6, "error"), (1e9, "disagree")]
    row = only(table_of(rows("o", "offset", walk)))
    assert row["threshold"] == 1e6 and row["status"] == "error"
    assert row["verdict"] == "breaks at 1e+06 (error)" and row["axis"] == "distance from origin"


def test_scale_is_walked_from_one_towards_tiny_and_towards_huge() -> None:
    walk = [(1e-6, "disagree"), (1e-3, "crash"), (1.0, "agree"), (1e3, "agree"),
            (1e6, "timeout")]
    table = table_of(rows("s", "scale", walk))
    tiny, huge = only(table, direction="tiny"), only(table, direction="huge")
    assert (tiny["threshold"], tiny["status"], tiny["easiest"]) == (1e-3, "crash", 1.0)
    assert (huge["threshold"], huge["status"], huge["easiest"]) == (1e6, "timeout", 1.0)
    assert tiny["points"] == huge["points"] == 3  # 1 belongs to both walks


def test_never_breaking_is_none_in_range_up_to_the_hardest_value() -> None:
    row = only(table_of(rows("g", "gap", [(g, "agree") for g in GAPS])))
    assert math.isnan(row["threshold"]) and row["state"] == "none" and not row["recovers"]
    assert row["verdict"] == "none in range (checked to 1e-07)" and row["reached"] == 1.0


def test_breaking_at_the_easiest_value_says_so() -> None:
    row = only(table_of(rows("g", "gap", [(g, "disagree") for g in GAPS])))
    assert row["threshold"] == 0.1 and row["state"] == "already" and row["reached"] == 0.0
    assert row["verdict"].startswith("already at the easiest value 0.1 (disagree")


def test_recovers_when_an_agree_follows_the_first_break() -> None:
    walk = [(1.0, "agree"), (10.0, "disagree"), (100.0, "disagree"), (1e3, "agree")]
    row = only(table_of(rows("o", "offset", walk)))
    assert row["threshold"] == 10.0 and row["recovers"] and row["recovered_at"] == 1e3
    assert row["verdict"].endswith("; agrees again at 1e+03")
    steady = only(table_of(rows("o", "offset", walk[:3])))
    assert not steady["recovers"] and math.isnan(steady["recovered_at"])


def test_skip_and_undefined_neither_break_nor_agree() -> None:
    walk = list(zip(GAPS, ["skip", "undefined", "agree", "disagree"], strict=True))
    row = only(table_of(rows("g", "gap", walk)))
    assert row["threshold"] == 1e-7 and row["state"] == "breaks" and row["points"] == 2
    assert row["reached"] == 0.5
    skipped = only(table_of(rows("g", "gap", [(g, "skip") for g in GAPS])))
    assert skipped["state"] == "unjudged" and math.isnan(skipped["threshold"])
    assert skipped["verdict"].startswith("no verdict")


def test_each_engine_and_quantity_has_its_own_threshold() -> None:
    table = table_of(rows("g", "gap", [(0.1, "agree"), (1e-3, "disagree")], engine="a"),
                     rows("g", "gap", [(0.1, "agree"), (1e-3, "agree")], engine="b"),
                     rows("g", "gap", [(0.1, "disagree")], engine="a", quantity="normal"))
    assert only(table, engine="a", quantity="distance")["threshold"] == 1e-3
    assert only(table, engine="b", quantity="distance")["state"] == "none"
    assert only(table, engine="a", quantity="normal")["state"] == "already"
    assert table["headline"].tolist() == [True, True, False]


def test_only_single_parameter_sweep_points_are_read() -> None:
    point = rows("x", "gap", [(0.1, "agree")])[0]
    others = [  # what the loader sets on a plain case, a twin, a scene step, a 2-parameter point
        {"case_id": "plain", "origin": "", "coords": ""},
        {"case_id": "x.gap=0.1.swapped", "twin_of": "x.gap=0.1"},
        {"case_id": "x.dt=0.01", "coords": json.dumps({"dt": 0.01})},
        {"case_id": "x.gap=0.1,offset=2", "coords": json.dumps({"gap": 0.1, "offset": 2.0})}]
    frame = pd.DataFrame([point, *({**point, **other} for other in others)])
    assert stability.sweep_points(frame, {})["case_id"].tolist() == ["x.gap=0.1"]
    assert stability.sweep_points(frame.iloc[:0], {}).empty


def twin_sweep() -> dict[str, Any]:
    """The cases of a 3-D gap sweep ``g`` with its 2-D twin ``g.2d``, by id."""
    case = {"id": "g", "description": "d", "kind": "sphere", "dim": 3, "twin_2d": "xy",
            "a": {"center": [0.0, 0.0, 0.0], "radius": 0.5},
            "b": {"center": [1.0, 0.0, 0.0], "radius": 0.5}, "sweep": {"gap": GAPS}}
    return {c.id: c for c in expand(CASE_ADAPTER.validate_python(case))}


def dim_rows(cases: dict[str, Any], dim: int, engine: str, statuses: list[str],
             quantity: str = "distance") -> list[dict[str, Any]]:
    """Result rows of the points of ``cases`` in ``dim``, with these statuses in sweep order."""
    points = [c for c in cases.values() if c.dim == dim]
    return [{"case_id": c.id, "kind": "sphere", "dim": dim, "engine": engine,
             "quantity": quantity, "value": "0.0", "status": status, "error": 1e-6,
             "tolerance": 1e-9, "category": "tolerance" if status == "disagree" else "",
             "origin": c.origin, "coords": json.dumps(c.coords), "twin_of": ""}
            for c, status in zip(points, statuses, strict=True)]


def test_an_engine_without_distances_is_shown_by_its_hit_walk() -> None:
    table = table_of(rows("g", "gap", [(g, "skip") for g in GAPS]),
                     rows("g", "gap", [(0.1, "agree"), (1e-7, "disagree")], quantity="hit"))
    shown = only(table, headline=True)
    assert (shown["quantity"], shown["threshold"]) == ("hit", 1e-7)
    assert shown["verdict"] == "hit: breaks at 1e-07 (disagree, tolerance) (distance: no verdict)"
    judged = table_of(rows("g", "gap", [(0.1, "agree")]),
                      rows("g", "gap", [(0.1, "disagree")], quantity="hit"))
    assert only(judged, headline=True)["quantity"] == "distance"  # no fallback when judged


def test_relative_error_divides_by_the_case_scale() -> None:
    body = {"center": [1000.0, 0.0, 0.0], "radius": 0.5}
    moving = {"center": [0.0, 0.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [4.0, 0, 0]}
    cases = {str(case["id"]): CASE_ADAPTER.validate_python(case) for case in (
        {"id": "s.offset=1000", "description": "d", "kind": "sphere", "dim": 3,
         "a": body, "b": body, "source": "x"},
        {"id": "r.mass_ratio=10", "description": "d", "dim": 3, "kind": "sphere_response",
         "a": moving, "b": moving | {"velocity": [-2.0, 0, 0]}, "source": "x"})}
    frame = pd.DataFrame(rows("s", "offset", [(1000, "agree")]) + rows(
        "r", "mass_ratio", [(10, "agree")], quantity="v2", kind="sphere_response"))
    points = stability.sweep_points(frame.assign(error=[2e-9, 2e-9]), cases)
    assert points["rel_error"].tolist() == pytest.approx([2e-12, 5e-10])
    assert points["rel_tolerance"].tolist() == pytest.approx([1e-12, 2.5e-10])


# --- a real run of the sweeps ------------------------------------------------------------------


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("stability") / "run"
    cases = load_paths([ROOT / "cases" / "sweeps.toml"]).cases
    engines = [adapters.get("reference"), adapters.get("reference-f32")]
    options = RunOptions(quick=True, jobs=2)
    launch(ResultsStore(directory), cases, engines, options,
           new_info(directory, "test", options, engines, cases))
    return directory


@pytest.fixture(scope="module")
def points(run_dir: Path) -> pd.DataFrame:
    return stability.sweep_points(read_results(run_dir), read_cases(run_dir))


@pytest.mark.parametrize("sweep", ["sweep-sphere-3d-offset", "sweep-aabb-3d-offset"])
def test_float32_breaks_at_a_smaller_offset_than_float64(points: pd.DataFrame,
                                                         sweep: str) -> None:
    """24 significant bits lose a 1e-3 gap far sooner than 53 as the coordinates grow."""
    table = stability.thresholds(points)
    f32 = only(table, sweep=sweep, engine="reference-f32", quantity="distance")
    f64 = only(table, sweep=sweep, engine="reference", quantity="distance")
    assert f32["threshold"] < math.inf  # breaks somewhere in range
    assert math.isnan(f64["threshold"]) or f32["threshold"] < f64["threshold"]


def test_points_cover_every_sweep_with_finite_relative_errors(points: pd.DataFrame) -> None:
    # every axis of cases/sweeps.toml; step_travel is swept by the scenes of cases/fast.toml
    assert set(points["param"]) == set(stability.AXES) - {"step_travel"}
    scored = points[points["status"].isin(["agree", "disagree"])]
    assert scored["rel_error"].notna().all() and (scored["rel_error"] >= 0).all()


def test_charts_are_plotly_divs_without_the_library(points: pd.DataFrame) -> None:
    charts = stability_charts.charts(points)
    titles = [c["title"] for c in charts]
    assert "distance from origin \u2014 sphere" in titles
    assert "mass ratio \u2014 sphere_response" in titles
    for chart in charts:
        assert "plotly-graph-div" in chart["html"] and 'class="plotly-figure"' in chart["html"]
        assert len(chart["html"]) < 200_000  # plotly.js itself is not inlined


def test_chart_text_is_escaped() -> None:
    frame = pd.DataFrame(rows("g", "gap", [(0.1, "agree"), (1e-3, "disagree")], engine=EVIL))
    (chart, *_) = stability_charts.charts(stability.sweep_points(frame, {}))
    assert EVIL not in chart["html"]


# --- template and command line -----------------------------------------------------------------


def section(points: pd.DataFrame) -> dict[str, Any]:
    """The stability section's context, as the report builds it."""
    table = stability.thresholds(points)
    return {"matrix": stability.matrix(table), "folds": stability_charts.folds(points, table)}


def render(stability_data: dict[str, Any] | None) -> str:
    page = templates().from_string(
        "<main>{% include '_stability.html.j2' %}</main>")
    return page.render(stability=stability_data)


def test_template_renders_the_matrix_and_the_charts(points: pd.DataFrame) -> None:
    html = render(section(points))
    assert 'id="stability-matrix"' in html and html.count('class="chart"') >= 8
    for header in ("engine", "distance from origin", "body scale", "mass ratio",
                   "approach speed", "gap or overlap relative to size", "sphere offset",
                   "sweep-sphere-3d-offset (3-D; larger is harder)", ">2-D<",
                   "huge: larger is harder", "tiny: smaller is harder"):
        assert f"{header}" in html, header
    assert ">reference-f32</td>" in html and "none</b>" in html
    assert '<script type="application/octet-stream" class="plotly-figure"' in html  # not escaped


def test_template_renders_nothing_without_sweep_rows() -> None:
    empty = stability.thresholds(pd.DataFrame(columns=stability.POINT_COLUMNS))
    assert render({"matrix": stability.matrix(empty), "folds": []}) == "<main></main>"
    assert render(None) == "<main></main>"


def test_template_escapes_text() -> None:
    frame = pd.DataFrame(rows("g", "gap", [(0.1, "agree"), (1e-3, "disagree")], engine=EVIL))
    html = render(section(stability.sweep_points(frame, {})))
    assert EVIL not in html and "&lt;script&gt;" in html


def parser() -> argparse.ArgumentParser:
    top = argparse.ArgumentParser()
    stability_command.register(top.add_subparsers())
    return top


def test_command_analyses_a_run_directory(run_dir: Path, tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    args = parser().parse_args(["stability", str(run_dir), "--out", str(tmp_path / "csv")])
    assert args.func(args) == 0
    table = pd.read_csv(tmp_path / "csv" / "stability.csv")
    assert set(table["engine"]) == {"reference", "reference-f32"}
    assert (tmp_path / "csv" / "stability_points.csv").stat().st_size > 0
    shown = capsys.readouterr().out
    assert "reference-f32" in shown and ("breaks at" in shown or "already at" in shown)
    args = parser().parse_args(["stability", str(run_dir)])
    assert args.func(args) == 0 and (run_dir / "stability.csv").exists()


def test_command_refuses_a_folder_without_results(tmp_path: Path) -> None:
    args = parser().parse_args(["stability", str(tmp_path)])
    assert args.func(args) == 2


def test_command_without_a_directory_runs_the_sweeps(tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    out = tmp_path / "run"
    args = parser().parse_args(["stability", "--engine", "reference", "--out", str(out)])
    assert args.func(args) == 0
    for name in ("results.jsonl", "run.json", "report.html", "stability.csv"):
        assert (out / name).exists(), name
    assert set(pd.read_csv(out / "stability.csv")["state"]) == {"none"}


def test_the_step_travel_threshold_is_the_first_missed_impact_at_any_phase() -> None:
    """A step-late impact disagrees but is caught; the walk breaks at the first pass-through."""
    def point(travel: float, phase: float, reason: str) -> dict[str, Any]:
        return {"case_id": f"f.dt=0.01.step_travel={travel},phase={phase}", "origin": "f",
                "coords": json.dumps({"dt": 0.01, "step_travel": travel, "phase": phase}),
                "twin_of": "", "kind": "sphere_scene", "dim": 2, "engine": "e",
                "quantity": "velocities", "status": "disagree", "category": "timestep",
                "reason": reason, "error": 1.0, "tolerance": 1e-9, "value": "[]"}
    late = "velocities off by 0.1, within the 0.4 that resolving each impact a step late allows"
    missed = f"velocities off by 2: {scene_rules.PASSED_THROUGH} at step travel 2"
    frame = pd.DataFrame([point(0.5, 0.5, late), point(1.0, 0.1, late),
                          point(1.0, 0.9, missed), point(2.0, 0.5, missed)])
    points = stability.sweep_points(frame, {})
    assert set(points["sweep"]) == {"f (dt=0.01)"}
    row = only(stability.thresholds(points), engine="e", quantity="velocities")
    assert row["threshold"] == 1.0 and row["category"] == "timestep"
