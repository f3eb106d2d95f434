"""``crosscheck advise``: which engines pass every stored case inside a scene's envelope.

The run is made by fake engines whose failures are known (tests/fakes.py and
``WrongFar`` here), so every verdict below follows from the cases' inputs.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any, ClassVar

import pytest

from crosscheck.cli import main
from crosscheck.core.model import Observation
from crosscheck.core.options import RunOptions
from crosscheck.report.advise import Advice, EngineAdvice, Envelope, EnvelopeError, advise
from crosscheck.results.store import ResultsStore, StoredRun, read_run
from crosscheck.run.launch import launch, new_info
from crosscheck.truth import oracle
from tests import fakes
from tests.conftest import aabb, response, sphere


class WrongFar(fakes.AlwaysRight):
    """Right, except a distance 1.0 too large when a centre coordinate exceeds 100."""

    name: ClassVar[str] = "fake-far"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        if max(abs(c) for c in (*prepared.a.center, *prepared.b.center)) <= 100.0:
            return truth
        assert isinstance(truth.distance, float)
        return dataclasses.replace(truth, distance=truth.distance + 1.0)


CASES = [
    sphere(0.0, 2.0, id="s3-apart"),
    sphere(0.0, 2.0, dim=2, id="s2-apart"),
    sphere(0.0, 4.0, ra=2.0, rb=2.0, id="s3-touch"),
    aabb([0.0, 0.0, 0.0], [10.0, 10.0, 10.0], [30.0, 0.0, 0.0], [10.0, 10.0, 10.0],
         id="b3-big"),
    aabb([1000.0, 0.0], [0.5, 0.5], [1002.0, 0.0], [0.5, 0.5], id="b2-far"),
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], id="r3"),
    sphere(0.0, 2.0, ra=-0.5, id="s3-bad", tags=["bad-input"]),
]
ENGINES = [fakes.AlwaysRight(), fakes.OffByOne(), fakes.HitOnly(), fakes.Raises(),
           fakes.TouchingIsContact(), WrongFar()]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("advise") / "run"
    options = RunOptions(quick=True, isolate=False)
    launch(ResultsStore(folder), CASES, ENGINES, options,
           new_info(folder, "test", options, ENGINES, CASES))
    return folder


@pytest.fixture(scope="module")
def stored(run_dir: Path) -> StoredRun:
    return read_run(run_dir)


def names(engines: list[EngineAdvice]) -> list[str]:
    return [e.engine for e in engines]


def verdict(advice: Advice, engine: str) -> EngineAdvice:
    return next(e for e in advice.passing + advice.failing if e.engine == engine)


def test_only_the_always_right_engine_passes_everything(stored: StoredRun) -> None:
    advice = advise(stored, Envelope())
    assert names(advice.passing) == ["fake-right"]
    assert advice.cases == 6 and advice.kinds == ("aabb", "sphere", "sphere_response")
    off = verdict(advice, "fake-off")
    # every pair case but the response fails its distance; the response raises (no distance)
    assert off.failing_cases == 6
    assert (off.culprits[0].case_id, off.culprits[0].status) == ("r3", "error")
    assert [(c.quantity, c.status, c.error) for c in off.culprits[1:]] == [
        ("distance", "disagree", 1.0)] * 2
    raises = verdict(advice, "fake-raises")
    assert raises.failing_cases == 6 and {c.status for c in raises.culprits} == {"error"}


def test_the_failing_cases_named_are_the_ones_the_data_says(stored: StoredRun) -> None:
    advice = advise(stored, Envelope())
    assert [(c.case_id, c.quantity, c.status, c.category) for c in
            verdict(advice, "fake-touch").culprits] == [
        ("s3-touch", "hit", "disagree", "convention")]
    assert [(c.case_id, c.quantity) for c in verdict(advice, "fake-far").culprits] == [
        ("b2-far", "distance")]
    assert verdict(advice, "fake-hit-only").unsupported == ("sphere_response",)
    assert verdict(advice, "fake-hit-only").failing_cases == 0


def test_tolerance_lets_small_errors_pass_but_never_a_wrong_hit(stored: StoredRun) -> None:
    detection = ("aabb", "sphere")
    tight = advise(stored, Envelope(kinds=detection, tolerance=0.5))
    assert "fake-off" in names(tight.failing)
    loose = advise(stored, Envelope(kinds=detection, tolerance=2.0))
    assert {"fake-off", "fake-far", "fake-hit-only"} <= set(names(loose.passing))
    assert names(advise(stored, Envelope(kinds=detection, tolerance=1e9)).failing) == [
        "fake-touch", "fake-raises"]


def test_envelope_filters_change_the_verdict_as_the_data_says(stored: StoredRun) -> None:
    pairs = ("aabb", "sphere")
    assert "fake-far" in names(advise(stored, Envelope(kinds=pairs)).failing)
    assert "fake-far" in names(advise(stored, Envelope(kinds=pairs, dims=(3,))).passing)
    assert "fake-far" in names(advise(stored, Envelope(kinds=pairs, offset=100.0)).passing)
    assert "fake-far" in names(advise(stored, Envelope(kinds=pairs, offset=1002.0)).failing)
    assert "fake-touch" in names(advise(stored, Envelope(kinds=pairs, scale=(0.0, 1.0))).passing)
    assert "fake-touch" in names(advise(stored, Envelope(kinds=pairs, scale=(1.0, 20.0))).failing)
    assert advise(stored, Envelope(kinds=pairs, scale=(1.0, 20.0))).cases == 2
    assert "fake-hit-only" in names(advise(stored, Envelope(kinds=("sphere",))).passing)


def test_bad_input_is_outside_unless_included(stored: StoredRun) -> None:
    assert advise(stored, Envelope(kinds=("sphere",))).cases == 3
    assert advise(stored, Envelope(kinds=("sphere",), include_bad_input=True)).cases == 4


def test_responses_are_filtered_by_speed_and_mass_ratio(stored: StoredRun) -> None:
    assert advise(stored, Envelope(kinds=("sphere_response",), speed=1.0)).cases == 1
    assert advise(stored, Envelope(kinds=("sphere_response",), speed=0.5)).cases == 0
    assert advise(stored, Envelope(kinds=("sphere_response",), mass_ratio=1.0)).cases == 1


def test_the_cheapest_passing_engine_comes_first(stored: StoredRun) -> None:
    results = stored.results.copy()
    speeds = {"fake-right": 3e-6, "fake-far": 1e-6, "fake-hit-only": 2e-6}
    results["query_s"] = results["engine"].map(speeds)
    # one slow case does not move a median: fake-far stays the cheapest
    results.loc[(results["engine"] == "fake-far") & (results["case_id"] == "s3-apart"),
                "query_s"] = 1.0
    timed = dataclasses.replace(stored, results=results)
    advice = advise(timed, Envelope(kinds=("aabb", "sphere"), tolerance=2.0))
    assert names(advice.passing) == ["fake-far", "fake-hit-only", "fake-right", "fake-off"]
    assert advice.passing[-1].median_query_s is None
    assert advice.passing[0].median_query_s == 1e-6


def test_impossible_envelopes_name_the_option(stored: StoredRun) -> None:
    with pytest.raises(EnvelopeError, match="--scale"):
        advise(stored, Envelope(scale=(5.0, 1.0)))
    with pytest.raises(EnvelopeError, match="--kind"):
        advise(stored, Envelope(kinds=("sphere_scene",)))


def test_cli_prints_the_table(run_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(run_dir), "--kind", "sphere", "--tolerance", "2"]) == 0
    text = capsys.readouterr().out
    for engine in ("fake-right", "fake-off", "fake-touch", "fake-raises", "s3-touch"):
        assert engine in text
    assert "3 cases inside the envelope" in text


def test_cli_json_parses(run_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(run_dir), "--dim", "3", "--offset", "100", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [e["engine"] for e in data["passing"]] == ["fake-right", "fake-far"]
    assert data["envelope"]["offset"] == 100.0 and data["dims"] == [3]
    assert data["failing"][0]["culprits"][0]["case_id"]


@pytest.mark.parametrize(("options", "named"), [
    (["--scale", "5:1"], "--scale"), (["--scale", "1"], "--scale"),
    (["--offset", "far"], "--offset"), (["--speed", "-1"], "--speed"),
    (["--mass-ratio", "0.5"], "--mass-ratio"), (["--tolerance", "nan"], "--tolerance"),
    (["--dim", "4"], "--dim"), (["--kind", "boxes"], "--kind"),
    (["--kind", "sphere_scene"], "--kind"),
])
def test_cli_bad_options_exit_2_naming_the_option(
        run_dir: Path, capsys: pytest.CaptureFixture[str], options: list[str],
        named: str) -> None:
    assert main(["advise", str(run_dir), *options]) == 2
    assert named in capsys.readouterr().err


def test_cli_refuses_a_folder_that_is_not_a_run(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(tmp_path / "missing")]) == 2
    assert "RUN_DIR" in capsys.readouterr().err
    assert main(["advise", str(tmp_path)]) == 2
    assert "RUN_DIR" in capsys.readouterr().err
