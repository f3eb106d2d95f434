"""``scene_facts.jsonl``: what each scene case's exact run showed, stored by the run so that
the report does not run the exact reference again (and recomputed for a run without it)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.cases.load import load_paths
from crosscheck.core.model import Observation
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.report import dynamics
from crosscheck.report.render import render
from crosscheck.results.run import decoded, read_cases, read_results, read_run
from crosscheck.results.scene_facts import FILE, SceneFacts, facts_of, read_facts
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from crosscheck.run.runner import run_pending
from crosscheck.truth import scenes
from tests import fakes
from tests.conftest import ROOT, sphere

SUITE = {"scenes.toml": "scene-2d-cradle-5-iterations.dt=0.00416667,iterations=4",
         "gravity.toml": "drop-2d-e0.5.dt=0.0166667"}
"""Two short scenes of the suite: a cradle in open space, a ball bouncing on a ground."""


def with_values(frame: pd.DataFrame) -> pd.DataFrame:
    """A results frame with its values decoded, as the report reads a run."""
    return frame.join(decoded(frame))


def on_a_step() -> SceneCase:
    """Two discs closing at 2 m/s across a 3 m gap: their one impact, at t = 1.5 s, falls on
    the 15th step of dt = 0.1 (flagged on the dynamics chart)."""
    case = CASE_ADAPTER.validate_python({
        "id": "on-a-step", "description": "d", "kind": "sphere_scene", "dim": 2,
        "duration": 3.0, "dt": 0.1, "origin": "on-a-step", "bodies": [
            {"center": [-2.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [1.0, 0.0]},
            {"center": [2.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [-1.0, 0.0]}]})
    assert isinstance(case, SceneCase)
    return case


def scene_cases() -> list[SceneCase]:
    found = []
    for name, case_id in SUITE.items():
        (case,) = [c for c in load_paths([ROOT / "cases" / name]).cases if c.id == case_id]
        assert isinstance(case, SceneCase)
        found.append(case)
    return [*found, on_a_step()]


def as_the_report_computed(case: SceneCase) -> SceneFacts:
    """The facts from the case's exact run, as the report computed its flags before it read
    them from the run (``scenes.aligned(case, scenes.truth(case).impacts or ())``)."""
    impacts = scenes.truth(case).impacts
    assert impacts is not None
    return SceneFacts(case.id, len(impacts), tuple(scenes.aligned(case, impacts)))


@pytest.fixture(scope="module")
def scene_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The three scenes on the always-right fake, in process, as ``--quick`` runs them."""
    folder = tmp_path_factory.mktemp("facts") / "run"
    cases = scene_cases()
    options = RunOptions(quick=True, isolate=False)
    engines = [fakes.AlwaysRight()]
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    return folder


def test_a_run_stores_the_facts_the_report_computed_from_the_exact_run(scene_run: Path) -> None:
    cases = scene_cases()
    assert read_facts(scene_run) == {c.id: as_the_report_computed(c) for c in cases}
    assert read_facts(scene_run)["on-a-step"].aligned == (1.5,)  # the check can see a flag
    assert len((scene_run / FILE).read_text().splitlines()) == len(cases)  # once per case


def test_the_report_reads_the_stored_facts_instead_of_running_the_reference(
        scene_run: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    frame, cases = with_values(read_results(scene_run)), read_cases(scene_run)
    expected = {c.id: as_the_report_computed(c).aligned for c in scene_cases()}

    def no_reference(case: SceneCase) -> Observation:
        raise AssertionError(f"the report ran the exact reference on {case.id}")

    monkeypatch.setattr(scenes, "truth", no_reference)  # what scene_facts.recomputed calls
    points = dynamics.scene_points(frame, cases, read_facts(scene_run))
    assert dict(zip(points["case_id"], points["aligned"], strict=True)) == expected


def test_a_run_without_the_file_shows_the_same_flags_and_the_same_page(
        scene_run: Path, tmp_path: Path) -> None:
    old = tmp_path / "run"  # the same path: the page names its run folder
    shutil.copytree(scene_run, old)
    frame, cases = with_values(read_results(old)), read_cases(old)
    stored = dynamics.scene_points(frame, cases, read_facts(old))
    with_facts = render(old)["report"].read_bytes()
    (old / FILE).unlink()
    recomputed = dynamics.scene_points(frame, cases, read_facts(old))
    assert read_facts(old) == {}
    assert list(recomputed["aligned"]) == list(stored["aligned"])
    assert (1.5,) in list(stored["aligned"])
    assert render(old)["report"].read_bytes() == with_facts


def test_a_resumed_run_keeps_the_facts_and_drops_a_half_written_line(scene_run: Path,
                                                                     tmp_path: Path) -> None:
    folder = tmp_path / "run"
    shutil.copytree(scene_run, folder)
    last = scene_cases()[-1].id  # killed before its rows and its facts were complete
    rows = (folder / "results.jsonl").read_text().splitlines()
    (folder / "results.jsonl").write_text(
        "".join(r + "\n" for r in rows if json.loads(r)["case_id"] != last))
    kept = [line for line in (folder / FILE).read_text().splitlines()
            if json.loads(line)["case_id"] != last]
    (folder / FILE).write_text("".join(line + "\n" for line in kept) + '{"case_id": "on-a-st')
    store = ResultsStore(folder, resume=True)
    try:
        assert last not in {case_id for case_id, _ in store.done}
        run_pending(list(read_run(folder).cases.values()), [fakes.AlwaysRight()], store,
                    RunOptions(quick=True, isolate=False))
    finally:
        store.close()
    lines = (folder / FILE).read_text().splitlines()
    assert lines[:len(kept)] == kept  # the finished cases' facts, as written
    assert [json.loads(line)["case_id"] for line in lines[len(kept):]] == [last]
    assert read_facts(folder) == read_facts(scene_run)


def test_only_a_scene_whose_exact_run_was_computed_has_facts() -> None:
    case = on_a_step()
    assert facts_of(case, Observation()) is None  # --quick skipped it: no truth computed
    assert facts_of(sphere(0.0, 1.0), Observation(distance=1.0)) is None
    failed = Observation.undefined(("positions", "velocities"), "no reference: too many events")
    assert facts_of(case, failed) == SceneFacts(case.id, None, ())
    line = SceneFacts(case.id, None, ()).to_json()
    assert SceneFacts.from_json(line) == SceneFacts(case.id, None, ())
