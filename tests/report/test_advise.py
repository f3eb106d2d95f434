"""``crosscheck advise``: a graded, ranked answer for a scene profile from a stored run.

The run is made by fake engines whose failures are known (tests/fakes.py and the fakes
here), so every grade below follows from the cases' inputs and the oracle.
"""

from __future__ import annotations

import dataclasses
import json
import math
import shlex
import shutil
from pathlib import Path
from typing import Any, ClassVar

import pytest

from crosscheck.cli import main
from crosscheck.core.model import Observation
from crosscheck.core.options import RunOptions
from crosscheck.report.advise.judge import judge
from crosscheck.report.advise.recommend import Advice, EngineAdvice, Envelope, EnvelopeError, advise
from crosscheck.report.advise.table import worst_text
from crosscheck.results.run import Run, read_run
from crosscheck.results.store import ResultsStore, repro_name
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


class WrongNearTouch(fakes.AlwaysRight):
    """Right, except the hit verdict flipped on pairs whose exact gap is within 1e-3."""

    name: ClassVar[str] = "fake-near"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        if isinstance(truth.distance, float) and 0.0 < abs(truth.distance) < 1e-3:
            return dataclasses.replace(truth, hit=not truth.hit)
        return truth


class Textbook(fakes.AlwaysRight):
    """Exact, under the name of the textbook baseline: shown apart, never a contender."""

    name: ClassVar[str] = "reference"


NEAR_GAP = 1.000001 - 1.0
CASES = [
    sphere(0.0, 2.0, id="s3-apart"),
    sphere(0.0, 2.0, dim=2, id="s2-apart"),
    sphere(0.0, 4.0, ra=2.0, rb=2.0, id="s3-touch"),
    sphere(0.0, 1.000001, id="s3-near"),
    aabb([0.0, 0.0, 0.0], [10.0, 10.0, 10.0], [30.0, 0.0, 0.0], [10.0, 10.0, 10.0],
         id="b3-big"),
    aabb([1000.0, 0.0], [0.5, 0.5], [1002.0, 0.0], [0.5, 0.5], id="b2-far"),
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], id="r3"),
    sphere(0.0, 2.0, ra=-0.5, id="s3-bad", tags=["bad-input"]),
]
ENGINES = [fakes.AlwaysRight(), fakes.OffByOne(), fakes.HitOnly(), fakes.Raises(),
           fakes.TouchingIsContact(), WrongFar(), WrongNearTouch(), Textbook()]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("advise") / "run"
    options = RunOptions(quick=True, isolate=False)
    launch(ResultsStore(folder), CASES, ENGINES, options,
           new_info(folder, "test", options, ENGINES, CASES))
    return folder


@pytest.fixture(scope="module")
def stored(run_dir: Path) -> Run:
    return read_run(run_dir)


def names(engines: list[EngineAdvice]) -> list[str]:
    return [e.engine for e in engines]


def grade(advice: Advice, engine: str) -> EngineAdvice:
    everyone = (advice.ranking + advice.unsupported + advice.excluded + advice.baselines)
    return next(e for e in everyone if e.engine == engine)


def test_the_exact_engines_pass_and_the_baseline_is_shown_apart(stored: Run) -> None:
    advice = advise(stored, Envelope())
    assert advice.cases == 7 and advice.kinds == ("aabb", "sphere", "sphere_response")
    assert "fake-right" in names(advice.passing)
    assert "reference" not in names(advice.ranking)
    assert names(advice.baselines) == ["reference"] and advice.baselines[0].passes
    off = grade(advice, "fake-off")
    # every pair case fails its distance by 1.0; the response raises (OffByOne has no v1)
    assert off.tier == "fails" and off.answered == 7 and off.within == 0
    assert off.worst is not None and off.worst.status == "error"
    distance = next(m for m in off.failure_modes if m.quantity == "distance")
    assert (distance.cases, distance.largest, distance.allowed) == (6, 1.0, 0.0)


def test_a_wrong_verdict_within_the_accuracy_of_the_exact_gap_is_within(
        stored: Run) -> None:
    tight = grade(advise(stored, Envelope(tolerance=1e-9)), "fake-near")
    assert tight.tier == "fails" and tight.failing_cases == ("s3-near",)
    assert tight.worst is not None and tight.worst.quantity == "hit"
    assert tight.worst.measure == pytest.approx(NEAR_GAP) and tight.worst.allowed == 1e-9
    assert grade(advise(stored, Envelope(tolerance=1e-5)), "fake-near").passes
    # relative to the smallest body (0.5): 1e-5 x 0.5 still forgives a gap of 1e-6
    assert grade(advise(stored, Envelope(rtol=1e-5)), "fake-near").passes
    assert not grade(advise(stored, Envelope(rtol=1e-7)), "fake-near").passes


def test_a_declared_touching_rule_is_a_convention_unless_touching_must_count(
        stored: Run) -> None:
    touch = grade(advise(stored, Envelope(kinds=("sphere",))), "fake-touch")
    assert touch.passes
    assert [(m.quantity, m.example, m.cases, m.largest) for m in touch.conventions] == [
        ("hit", "s3-touch", 1, 0.0)]
    strict = grade(advise(stored, Envelope(kinds=("sphere",), touching_contact=True)),
                   "fake-touch")
    assert strict.tier == "fails" and strict.failing_cases == ("s3-touch",)


def test_definitions_are_judged_on_their_error_only_when_the_profile_says_so() -> None:
    row = ("disagree", "distance", "convention", 0.002, math.nan, 1e-9)
    assert judge(Envelope(), *row, nature="definition") == "convention"
    assert judge(Envelope(strict_conventions=True), *row, nature="definition") == "wrong"
    assert judge(Envelope(strict_conventions=True), *row[:-1], 0.01,
                 nature="definition") == "within"


def test_a_behaviour_is_always_judged_on_its_error() -> None:
    row = ("disagree", "energy_drift", "convention", 0.9, math.nan)
    assert judge(Envelope(), *row, 1e-3, nature="behaviour") == "wrong"
    assert judge(Envelope(), *row, 1.0, nature="behaviour") == "within"
    assert judge(Envelope(), *row, 1e-3) == "wrong"  # resting on nothing named: not excused


def test_an_engine_that_skips_part_of_the_envelope_never_outranks_by_skipping(
        stored: Run) -> None:
    advice = advise(stored, Envelope())
    hit_only = grade(advice, "fake-hit-only")
    assert hit_only.tier == "partial" and hit_only.unsupported == ("sphere_response",)
    assert hit_only.answered == 6 and hit_only.coverage == pytest.approx(6 / 7)
    assert [(p.kind, p.answered, p.cases) for p in hit_only.parts if p.kind != "aabb"] == [
        ("sphere", 1, 1), ("sphere", 3, 3), ("sphere_response", 0, 1)]
    ranking = names(advice.ranking)
    assert ranking.index("fake-right") < ranking.index("fake-hit-only")
    assert ranking.index("fake-hit-only") < ranking.index("fake-far")
    # failing engines by the cases of the whole envelope they get within
    within = [e.within for e in advice.failing]
    assert within == sorted(within, reverse=True) and advice.failing[-1].engine == "fake-raises"


def test_an_engine_that_answers_nothing_is_listed_not_ranked(stored: Run) -> None:
    advice = advise(stored, Envelope(kinds=("sphere_response",)))
    assert names(advice.unsupported) == ["fake-hit-only", "fake-touch"]
    assert "fake-hit-only" not in names(advice.ranking)


def test_when_nothing_passes_the_closest_and_its_deciding_cases_are_named(
        stored: Run) -> None:
    results = stored.results[stored.results["engine"] != "fake-right"]
    without = stored.with_results(results)
    advice = advise(without, Envelope(touching_contact=True))
    assert advice.passing == [] and advice.ranking
    assert advice.closest == "fake-hit-only"
    assert advice.deciding == ("sphere_response 3-D: 1 of 1 cases skipped",)
    far = advise(without, Envelope(kinds=("aabb",), touching_contact=True))
    assert far.passing and far.closest is None


def test_bad_input_is_judged_apart_as_robustness(stored: Run) -> None:
    advice = advise(stored, Envelope(kinds=("sphere",)))
    assert advice.cases == 4 and advice.bad_input_cases == 1
    assert grade(advice, "fake-raises").robustness == {"error": 1}
    assert "s3-bad" not in grade(advice, "fake-raises").failing_cases


def test_the_quantities_that_matter_and_the_envelope_filter_the_verdict(
        stored: Run) -> None:
    pairs = ("aabb", "sphere")
    assert not grade(advise(stored, Envelope(kinds=pairs)), "fake-off").passes
    assert grade(advise(stored, Envelope(kinds=pairs, quantities=("hit",))), "fake-off").passes
    assert grade(advise(stored, Envelope(kinds=pairs, offset=100.0)), "fake-far").passes
    assert not grade(advise(stored, Envelope(kinds=pairs, offset=1002.0)), "fake-far").passes
    assert grade(advise(stored, Envelope(kinds=pairs, dims=(3,))), "fake-far").passes
    assert advise(stored, Envelope(kinds=pairs, scale=(1.0, 20.0))).cases == 2
    assert grade(advise(stored, Envelope(kinds=pairs, tolerance=2.0)), "fake-off").passes


def test_responses_are_filtered_by_speed_and_mass_ratio(stored: Run) -> None:
    assert advise(stored, Envelope(kinds=("sphere_response",), speed=1.0)).cases == 1
    assert advise(stored, Envelope(kinds=("sphere_response",), speed=0.5)).cases == 0
    assert advise(stored, Envelope(kinds=("sphere_response",), mass_ratio=1.0)).cases == 1


def test_a_float32_engine_ranks_only_when_float32_is_acceptable(stored: Run) -> None:
    engines = tuple({**e, "settings": "float32 throughout"} if e["name"] == "fake-far" else e
                    for e in stored.info.engines)
    f32 = dataclasses.replace(stored, info=dataclasses.replace(stored.info, engines=engines))
    assert "fake-far" in names(advise(f32, Envelope()).ranking)
    refused = advise(f32, Envelope(float32=False))
    assert names(refused.excluded) == ["fake-far"] and "fake-far" not in names(refused.ranking)


def test_the_cheapest_passing_engine_comes_first_with_its_spread(stored: Run) -> None:
    results = stored.results.copy()
    speeds = {"fake-right": 3e-6, "fake-far": 1e-6, "fake-touch": 2e-6}
    results["query_s"] = results["engine"].map(speeds)
    # one slow case does not move a median: fake-far stays the cheapest
    slow = (results["engine"] == "fake-far") & (results["case_id"] == "s3-apart")
    results.loc[slow, "query_s"] = 1.0
    timed = stored.with_results(results)
    advice = advise(timed, Envelope(kinds=("sphere",)))
    assert names(advice.passing)[:3] == ["fake-far", "fake-touch", "fake-right"]
    assert advice.passing[0].median_query_s == 1e-6
    assert advice.passing[0].query_iqr_s == pytest.approx(0.25 * (1.0 - 1e-6))
    assert advice.passing[-1].median_query_s is None


def test_the_worst_answer_gives_its_repro_command_and_the_script_once_written(
        run_dir: Path, tmp_path: Path) -> None:
    """A run writes no script: the worst answer gives the command that prints it; once the
    folder holds the script (``crosscheck repro RUN --all``), its path too."""
    run = tmp_path / "run"
    shutil.copytree(run_dir, run)
    worst = grade(advise(read_run(run), Envelope()), "fake-off").worst
    assert worst is not None and worst.repro is None
    assert worst.repro_command == shlex.join(
        ["crosscheck", "repro", str(run), worst.case_id, "--engine", "fake-off"])
    script = run / "repro" / f"{repro_name(worst.case_id, 'fake-off')}.py"
    script.parent.mkdir()
    script.write_text("# a repro script\n", encoding="utf-8")
    again = grade(advise(read_run(run), Envelope()), "fake-off").worst
    assert again is not None and again.repro == str(script)
    assert again.repro_command == worst.repro_command


def test_impossible_envelopes_name_the_option(stored: Run) -> None:
    with pytest.raises(EnvelopeError, match="--scale"):
        advise(stored, Envelope(scale=(5.0, 1.0)))
    with pytest.raises(EnvelopeError, match="--kind"):
        advise(stored, Envelope(kinds=("sphere_scene",)))
    with pytest.raises(EnvelopeError, match="--rtol"):
        advise(stored, Envelope(rtol=-1.0))


def _row_and_worst(lines: list[str], engine: str) -> tuple[str, str]:
    """An engine's line of the printed ranking and the line below it (its worst answer)."""
    at = next(n for n, line in enumerate(lines) if f" {engine} " in line)
    return lines[at], lines[at + 1]


def test_cli_prints_one_line_per_engine_at_80_columns(
        run_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(run_dir), "--tolerance", "1e-9"]) == 0
    text = capsys.readouterr().out
    lines = text.splitlines()
    assert max(len(line) for line in lines) <= 80
    for engine in ENGINES:
        assert sum(f" {engine.name} " in line and "%" in line for line in lines) == 1
    near, worst = _row_and_worst(lines, "fake-near")
    assert "fail" in near and "worst: hit 1e-06>1e-09" in worst
    touch, worst = _row_and_worst(lines, "fake-touch")
    assert "part" in touch and "worst: skips sphere_response 3-D 1/1" in worst  # whole
    assert worst_text(grade(advise(read_run(run_dir), Envelope()), "fake-touch")) == (
        "skips sphere_response 3-D 1/1")
    assert main(["advise", str(run_dir), "--kind", "sphere"]) == 0
    touch, worst = _row_and_worst(capsys.readouterr().out.splitlines(), "fake-touch")
    assert "pass" in touch and "worst: conv hit n=1 ≤0" in worst  # its touching rule, at gap 0
    assert "7 cases" in text and "passing: fake-right" in text
    assert "bad input, judged apart (1 cases): no crash or timeout" in text


def test_cli_json_keeps_passing_and_adds_the_grades(
        run_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(run_dir), "--dim", "3", "--offset", "100", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    passing = [e["engine"] for e in data["passing"]]
    assert {"fake-right", "fake-far"} <= set(passing) and "reference" not in passing
    assert data["ranking"][:len(passing)] == passing
    assert data["envelope"]["offset"] == 100.0 and data["dims"] == [3]
    off = next(e for e in data["failing"] if e["engine"] == "fake-off")
    assert off["worst"]["case_id"] and off["failure_modes"][0]["cases"] >= 1
    assert off["worst"]["repro"] is None
    assert off["worst"]["repro_command"].startswith(f"crosscheck repro {run_dir} ")
    assert [e["engine"] for e in data["baselines"]] == ["reference"]


@pytest.mark.parametrize(("options", "named"), [
    (["--scale", "5:1"], "--scale"), (["--scale", "1"], "--scale"),
    (["--offset", "far"], "--offset"), (["--speed", "-1"], "--speed"),
    (["--mass-ratio", "0.5"], "--mass-ratio"), (["--tolerance", "nan"], "--tolerance"),
    (["--rtol", "-1"], "--rtol"), (["--quantities", "hit,speed"], "--quantities"),
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


def test_zero_size_bodies_are_in_the_envelope_only_when_the_profile_admits_them() -> None:
    point = sphere(0.0, 1.0, ra=0.0)
    plate = aabb([0.0, 0.0, 0.0], [0.0, 1.0, 1.0], [2.0, 0.0, 0.0], [1.0, 1.0, 1.0])
    for case in (point, plate):
        assert not Envelope().holds(case)  # no --scale: every body has a positive size
        assert Envelope(scale=(0.0, 1.0)).holds(case)  # --scale 0:1 admits them
        assert not Envelope(scale=(0.1, 1.0)).holds(case)
    assert Envelope().holds(sphere(0.0, 1.0))
