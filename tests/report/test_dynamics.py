"""Scenes end to end: expansion, validation, engines against the event-driven truth, report."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pandas as pd
import pytest
from markupsafe import Markup

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, SceneCase
from crosscheck.report import dynamics, style
from crosscheck.results.run import decoded, read_cases, read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.casework import QUICK_SCENE_STEPS
from crosscheck.run.runner import run
from crosscheck.truth import scenes
from tests.conftest import ROOT

HEAD_ON = """
[[case]]
id = "head-on"
description = "Two equal discs approach head-on and exchange velocities"
kind = "sphere_scene"
dim = 2
duration = 3.0
bodies = [
  { center = [-2.0, 0.0], radius = 0.5, mass = 1.0, velocity = [1.0, 0.0] },
  { center = [2.0037, 0.0], radius = 0.5, mass = 1.0, velocity = [-1.0, 0.0] },
]
steps = { dt = [1e-3, 1e-2, 1e-1], iterations = [10] }
"""


def scene_file(tmp_path: Path, text: str = HEAD_ON) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


def run_scenes(tmp_path: Path, cases: list[AnyCase], engines: list[str],
               quick: bool = False) -> pd.DataFrame:
    store = ResultsStore(tmp_path / "run")
    run(cases, [adapters.get(e) for e in engines], store, RunOptions(quick=quick))
    store.close()
    frame = read_results(tmp_path / "run")
    return frame.join(decoded(frame))


def test_steps_expand_into_one_case_per_dt_and_iterations(tmp_path: Path) -> None:
    cases = load_paths([scene_file(tmp_path)]).cases
    assert [c.id for c in cases] == ["head-on.dt=0.001,iterations=10",
                                     "head-on.dt=0.01,iterations=10",
                                     "head-on.dt=0.1,iterations=10"]
    assert [c.step_count for c in cases if isinstance(c, SceneCase)] == [3000, 300, 30]
    assert all(isinstance(c, SceneCase) and c.iterations == 10 and "swapped" not in c.tags
               for c in cases)


def test_overlapping_bodies_are_rejected_naming_the_field(tmp_path: Path) -> None:
    text = HEAD_ON.replace("[2.0037, 0.0], radius", "[-1.5, 0.0], radius")
    result = load_paths([scene_file(tmp_path, text)])
    assert not result.cases
    assert {(e.field, e.reason) for e in result.errors} == {
        ("bodies[1].center", "overlaps bodies[0] at the start (touching is allowed)")}


def test_generated_bodies_are_deterministic() -> None:
    block: dict[str, Any] = {
        "id": "c", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": 1.0,
        "generator": {"name": "cluster", "n": 12, "seed": 3, "extent": 4.0, "radius": 0.3}}
    one, two = CASE_ADAPTER.validate_python(block), CASE_ADAPTER.validate_python(block)
    assert one == two and len(getattr(one, "bodies")) == 12  # noqa: B009


@pytest.mark.engine
def test_engines_converge_to_the_exact_reference_as_dt_shrinks(tmp_path: Path) -> None:
    cases = load_paths([scene_file(tmp_path)]).cases
    frame = run_scenes(tmp_path, cases, ["pymunk", "pybullet"])
    points = dynamics.scene_points(frame, read_cases(tmp_path / "run"))
    assert len(points) == 6 and (points["rtf"] > 0).all()
    for _, curve in points.groupby("engine"):
        errors = curve.sort_values("dt")["position_error"].tolist()
        # the impact (t = 1.50185, off every step grid here) is resolved up to a step
        # late: the lag is at most the closing speed x dt, in radii
        for error, dt in zip(errors, (1e-3, 1e-2, 1e-1), strict=True):
            assert error <= 2.0 * dt / 0.5
        assert errors[0] < errors[-1]
    # momentum is conserved by both engines' impulses (relative to sum m|v|)
    momentum = frame[frame["quantity"] == "momentum"]
    assert (momentum["error"] < 1e-9).all()


@pytest.mark.engine
def test_quick_skips_long_scenes_with_a_reason(tmp_path: Path) -> None:
    text = HEAD_ON.replace("dt = [1e-3, 1e-2, 1e-1]", "dt = [1e-4, 1e-1]")
    cases = load_paths([scene_file(tmp_path, text)]).cases
    frame = run_scenes(tmp_path, cases, ["pymunk"], quick=True)
    long = frame[frame["case_id"].str.contains("dt=0.0001")]
    assert set(long["status"]) == {"skip"}
    assert set(long["reason"]) == {
        f"--quick runs scenes of at most {QUICK_SCENE_STEPS} steps; this one takes 30000"}
    short = frame[frame["case_id"].str.contains("dt=0.1,")]
    assert "skip" not in set(short["status"])


@pytest.mark.engine
def test_report_has_the_dynamics_section(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["run", str(scene_file(tmp_path)), "--engine", "pymunk", "--quick",
                 "--out", str(out)]) == 0
    page = (out / "report.html").read_text()
    assert "Dynamics: accuracy against speed (2 scene runs)" in page  # --quick: 3000 steps skip
    assert 'id="dyn-head-on"' in page


def test_no_suite_scene_has_an_impact_on_a_swept_step_boundary() -> None:
    scenes_suite = [c for c in load_paths([ROOT / "cases" / "scenes.toml"]).cases
                    if isinstance(c, SceneCase)]
    assert len(scenes_suite) > 30
    on_step = {c.id: scenes.aligned(c, scenes.truth(c).impacts or ()) for c in scenes_suite}
    assert {case_id: times for case_id, times in on_step.items() if times} == {}


HEADLINE_RUNS = {  # engine: wall seconds per step, position error per dt
    "rough": (1e-6, {0.1: 0.3, 0.01: 0.02}),
    "exact-slow": (1e-4, {0.1: 0.2, 0.01: 1e-3}),
    "exact-fast": (1e-5, {0.1: 0.2, 0.01: 1e-3})}
"""One scene at two time steps (no impact on a step boundary): two engines tie on accuracy."""


@pytest.fixture(scope="module")
def headline_run(tmp_path_factory: pytest.TempPathFactory
                 ) -> tuple[pd.DataFrame, dict[str, AnyCase]]:
    """HEADLINE_RUNS on the head-on scene: the rows an engine would write, and the cases."""
    text = HEAD_ON.replace("dt = [1e-3, 1e-2, 1e-1], iterations = [10]", "dt = [0.1, 0.01]")
    cases = load_paths([scene_file(tmp_path_factory.mktemp("headline"), text)]).cases
    rows = [{"case_id": c.id, "kind": c.kind, "engine": engine, "quantity": q,
             "value": "1.0", "truth": "1.0", "status": "disagree", "query_iqr_s": 0.0,
             "error": errors[c.dt] if q == "positions" else 0.0,
             "query_s": per_step * c.step_count}
            for c in cases if isinstance(c, SceneCase) and c.dt
            for engine, (per_step, errors) in HEADLINE_RUNS.items()
            for q in ("positions", "velocities", "momentum", "energy")]
    frame = pd.DataFrame(rows)
    return frame.join(decoded(frame)), {c.id: c for c in cases}


def test_the_dynamics_headline_names_the_most_accurate_run_from_the_rows(
        headline_run: tuple[pd.DataFrame, dict[str, Any]]) -> None:
    frame, cases = headline_run
    (built,) = dynamics.section(frame, cases, list(HEADLINE_RUNS))["scenes"]
    positions = frame[frame["quantity"] == "positions"]
    best = positions.loc[positions.groupby("engine")["error"].idxmin()].set_index("engine")
    assert {e: r["case_id"] for e, r in built["best"].items()} == best["case_id"].to_dict()
    tied = best[best["error"] == best["error"].min()]
    assert built["tied"] == [e for e in HEADLINE_RUNS if e in tied.index]
    fastest = tied["query_s"].idxmin()  # same simulated time: the least wall time is fastest
    assert built["top"]["engine"] == fastest
    assert built["summary"].startswith(f"as accurate: {' and '.join(built['tied'])}, error ")
    dt = getattr(cases[str(best.loc[fastest, "case_id"])], "dt")  # noqa: B009
    assert f"the fastest of them, {fastest} at dt {dynamics.step(dt)}, " in built["summary"]


def test_the_dynamics_section_folds_each_scene_under_its_headline(
        headline_run: tuple[pd.DataFrame, dict[str, Any]]) -> None:
    section = dynamics.section(*headline_run, list(HEADLINE_RUNS))
    section["scenes"] = [{**s, "chart": Markup(s["chart"])} for s in section["scenes"]]
    page = style.templates().from_string("{% include '_dynamics.html.j2' %}").render(
        dynamics=section)
    (built,) = section["scenes"]
    folded = re.findall(r'<details class="dynamics-scene"[^>]*><summary>(.*?)</summary>', page)
    assert folded == [f'<span class="mono">head-on</span>: {built["summary"]}']  # closed: no "open"
    fold = page[page.index('<details class="dynamics-scene"'):]
    assert fold.count("<tr><td>") == len(headline_run[0]["case_id"].unique()) * len(HEADLINE_RUNS)
    assert 'id="dyn-head-on"' in fold  # the chart, folded with its runs
    headline = page[page.index('<table id="dynamics-best">'):page.index("</table>")]
    assert headline.count("<b>") == len(built["tied"])  # the tied most accurate cells
