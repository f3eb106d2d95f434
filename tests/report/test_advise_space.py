"""``advise`` speaks every kind's dimensions: scene and time-of-impact limits, one tolerance per
unit, options that apply to no asked kind refused, behaviours never excused, and what an
answer rests on (its cases, and what a ``--quick`` run did not ask).

The runs are made by fake engines whose answers are known: the exact truth, except where a
fake says otherwise, so every grade below follows from the cases' inputs.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any, ClassVar

import pytest

from crosscheck.cases.cover import coverage
from crosscheck.cli import main
from crosscheck.core.conventions import Conventions
from crosscheck.core.model import Observation
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from crosscheck.report.advise.recommend import Advice, EngineAdvice, Envelope, EnvelopeError, advise
from crosscheck.results.run import Run, read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from crosscheck.testing import fakes
from crosscheck.truth import oracle
from tests.conftest import sphere

TILT = 1e-6
"""How far (rad) :class:`Tilted` turns every normal."""


class Tilted(fakes.AlwaysRight):
    """Right, except every normal turned by :data:`TILT` in the xy plane."""

    name: ClassVar[str] = "fake-tilted"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        if not isinstance(truth.normal, tuple):
            return truth
        x, y, *rest = truth.normal
        c, s = math.cos(TILT), math.sin(TILT)
        return dataclasses.replace(truth, normal=(x * c - y * s, x * s + y * c, *rest))


class Damped(fakes.AlwaysRight):
    """Declares a damping (as pybullet-default does) and loses energy: its energy drift is
    :data:`LOST` per second below the exact one."""

    name: ClassVar[str] = "fake-damped"
    conventions: ClassVar[Conventions] = Conventions(damping=1.0)

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        if not isinstance(truth.energy_drift, float):
            return truth
        return dataclasses.replace(truth, energy_drift=truth.energy_drift - LOST)


class Soft(Damped):
    """Declares a soft contact (as mujoco-default does) and loses the same energy."""

    name: ClassVar[str] = "fake-soft"
    conventions: ClassVar[Conventions] = Conventions(restitution_model="soft")


LOST = 0.3
"""The energy :class:`Damped` and :class:`Soft` lose, as a share of the energy per second."""


def head_on(case_id: str, dt: float, speed: float, duration: float = 3.0) -> AnyCase:
    """Two r 0.05 discs closing head-on at ``speed`` each."""
    return CASE_ADAPTER.validate_python({
        "id": case_id, "description": "d", "kind": "sphere_scene", "dim": 2,
        "duration": duration, "dt": dt, "restitution": 1.0, "bodies": [
            {"center": [-1.0123, 0], "radius": 0.05, "mass": 1, "velocity": [speed, 0]},
            {"center": [1.0123, 0], "radius": 0.05, "mass": 1, "velocity": [-speed, 0]}]})


def toi(case_id: str, duration: float) -> AnyCase:
    return CASE_ADAPTER.validate_python({
        "id": case_id, "description": "d", "kind": "sphere_toi", "dim": 3,
        "duration": duration,
        "a": {"center": [0, 0, 0], "radius": 0.5, "velocity": [3, 4, 0]},
        "b": {"center": [4, 0, 0], "radius": 0.5, "velocity": [0, 0, 0]}})


SCENES = [head_on("slow", 1 / 240, 1.0), head_on("shot", 1 / 60, 150.0),
          head_on("long", 1 / 240, 1.0, duration=10.0)]
"""Step travels 0.04, 25 (a shooter's r 0.05 ball at 300 m/s against a resting one, dt 1/60)
and 0.04 again over 2,400 steps: more than a ``--quick`` run asks."""
PAIRS = [sphere(0.0, 2.0, id="apart"), sphere(0.0, 1.0, id="touch"),
         sphere(0.0, 2.0, dim=2, id="apart-2d")]


def stored(folder: Path, cases: list[AnyCase], engines: list[Any], quick: bool) -> Run:
    options = RunOptions(quick=quick, isolate=False, timing_cases=0)
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    return read_run(folder)


@pytest.fixture(scope="module")
def scenes(tmp_path_factory: pytest.TempPathFactory) -> Run:
    return stored(tmp_path_factory.mktemp("scenes") / "run", SCENES,
                  [fakes.AlwaysRight(), Damped(), Soft()], quick=True)


@pytest.fixture(scope="module")
def pairs(tmp_path_factory: pytest.TempPathFactory) -> Run:
    return stored(tmp_path_factory.mktemp("pairs") / "run", PAIRS,
                  [fakes.AlwaysRight(), Tilted(), fakes.TouchingIsContact()], quick=True)


def grade(advice: Advice, engine: str) -> EngineAdvice:
    return next(e for e in advice.ranking + advice.baselines if e.engine == engine)


@pytest.mark.parametrize(("options", "named", "why"), [
    (["--kind", "aabb", "--mass-ratio", "10"], "--mass-ratio", "sphere_response and"),
    (["--duration", "60"], "--duration", "(aabb, sphere, sphere_response) have none"),
    (["--kind", "sphere", "--step-travel", "25"], "--step-travel", "sphere_scene"),
    (["--kind", "sphere", "--dt", "1/60"], "--dt", "sphere_scene"),
    (["--kind", "sphere_scene", "--interval", "1"], "--interval", "sphere_toi"),
    (["--kind", "aabb", "--speed", "300"], "--speed", "sphere_response"),
    (["--kind", "sphere_response", "--touching-contact"], "--touching-contact", "aabb"),
    (["--kind", "sphere_response", "--tolerance", "1e-3"], "--tolerance",
     "--velocity-tolerance"),
    (["--kind", "sphere", "--quantities", "hit,distance", "--angle-tolerance", "1e-3"],
     "--angle-tolerance", "no asked quantity"),
    (["--kind", "sphere", "--velocity-tolerance", "1"], "--velocity-tolerance", "in m/s"),
    (["--kind", "sphere", "--time-tolerance", "1"], "--time-tolerance", "in s"),
    (["--kind", "sphere_toi", "--fraction-tolerance", "1"], "--fraction-tolerance", "toi: s"),
    (["--kind", "sphere_response", "--rtol", "1e-6"], "--rtol", "in m"),
    (["--kind", "sphere", "--quantities", "settle"], "--quantities", "no quantity"),
])
def test_an_option_no_asked_kind_has_is_refused_before_the_run_is_read(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], options: list[str], named: str,
        why: str) -> None:
    assert main(["advise", str(tmp_path / "no-such-run"), *options]) == 2
    error = capsys.readouterr().err
    assert named in error and why in error and "RUN_DIR" not in error


def test_each_option_applies_where_a_kind_has_it() -> None:
    Envelope(kinds=("sphere_scene",), dt=(0.0, 1 / 60), step_travel=25.0, speed=300.0,
             mass_ratio=10.0, duration=60.0, fraction_tolerance=1e-3, tolerance=1e-3).check()
    Envelope(kinds=("sphere_toi",), interval=(0.0, 1.0), speed=10.0, time_tolerance=1e-9,
             angle_tolerance=1e-6).check()
    Envelope(kinds=("sphere", "sphere_scene"), duration=10.0, tolerance=1e-3,
             angle_tolerance=1e-3).check()  # a limit of one kind, in a profile of two
    with pytest.raises(EnvelopeError, match="--dt: LO must be <= HI"):
        Envelope(kinds=("sphere_scene",), dt=(0.1, 0.01)).check()


def test_scene_and_time_of_impact_limits_place_cases_by_their_own_inputs() -> None:
    slow, shot, _ = SCENES
    assert Envelope(dt=(0.0, 1 / 240)).holds(slow) and not Envelope(dt=(0.0, 1 / 240)).holds(shot)
    assert Envelope(dt=(1 / 60, 1 / 60)).holds(shot)  # 1/60 as the case file writes it
    assert Envelope(step_travel=25.0).holds(shot) and not Envelope(step_travel=24.0).holds(shot)
    assert Envelope(speed=150.0).holds(shot) and not Envelope(speed=149.0).holds(shot)
    moving = toi("t", 2.0)  # A at |(3, 4, 0)| = 5: a body's speed, not a component
    assert Envelope(speed=5.0).holds(moving) and not Envelope(speed=4.9).holds(moving)
    assert Envelope(interval=(0.0, 2.0)).holds(moving)
    assert not Envelope(interval=(0.0, 1.0)).holds(moving)
    for other in (sphere(0.0, 2.0), toi("t", 2.0)):  # limits of another kind leave it alone
        assert Envelope(dt=(0.0, 1e-9), step_travel=0.0, duration=1e9).holds(other)
    assert Envelope(interval=(0.0, 1e-9)).holds(slow)


def test_a_tolerance_judges_only_the_quantities_of_its_unit(pairs: Run) -> None:
    metres = advise(pairs, Envelope(kinds=("sphere",), tolerance=1e-3))
    tilted = grade(metres, "fake-tilted")  # no angle tolerance: normals must agree
    assert not tilted.passes and tilted.worst is not None
    assert tilted.worst.quantity == "normal" and tilted.worst.allowed == 0.0
    both = advise(pairs, Envelope(kinds=("sphere",), tolerance=1e-3, angle_tolerance=10 * TILT))
    assert grade(both, "fake-tilted").passes
    tight = advise(pairs, Envelope(kinds=("sphere",), tolerance=1.0, angle_tolerance=TILT / 10))
    assert not grade(tight, "fake-tilted").passes  # a metre of room is no radian of it
    lengths = advise(pairs, Envelope(kinds=("sphere",), quantities=("hit", "distance"),
                                     tolerance=1e-3))
    assert grade(lengths, "fake-tilted").passes


def test_a_declared_behaviour_never_excuses_the_energy_it_loses(scenes: Run) -> None:
    """A 60-s-style energy profile: the damped and the soft engine lose energy by their
    declared behaviours; their rows are conventions in the report, failures here."""
    need = Envelope(kinds=("sphere_scene",), quantities=("energy_drift",),
                    fraction_tolerance=1e-3)
    advice = advise(scenes, need)
    assert [e.engine for e in advice.passing] == ["fake-right"]
    for name in ("fake-damped", "fake-soft"):
        lost = grade(advice, name)
        assert lost.tier == "fails" and lost.conventions == ()
        assert [(m.quantity, m.category, m.nature) for m in lost.failure_modes] == [
            ("energy_drift", "convention", "behaviour")]
        assert lost.failure_modes[0].largest == pytest.approx(LOST)
    roomy = advise(scenes, dataclasses.replace(need, fraction_tolerance=LOST * 1.01))
    assert {e.engine for e in roomy.passing} == {"fake-right", "fake-damped", "fake-soft"}


def test_a_declared_definition_still_excuses_its_row(pairs: Run) -> None:
    touch = grade(advise(pairs, Envelope(kinds=("sphere",))), "fake-touch")
    assert touch.passes
    assert [(m.quantity, m.example, m.nature) for m in touch.conventions] == [
        ("hit", "touch", "definition")]


def test_a_quick_run_says_which_cases_it_did_not_ask(
        scenes: Run, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    quick = advise(scenes, Envelope(kinds=("sphere_scene",)))
    assert quick.quick and quick.not_asked == 1 and quick.cases == 2
    assert grade(quick, "fake-right").passes  # the long scene is not held against anyone
    assert advise(scenes, Envelope(kinds=("sphere_scene",), dt=(1 / 60, 1))).not_asked == 0
    assert main(["advise", str(scenes.directory), "--kind", "sphere_scene"]) == 0
    printed = " ".join(capsys.readouterr().out.split())
    assert "a --quick run: 1 cases of this profile not asked (scenes over 1000 steps)" in printed
    full = stored(tmp_path / "full", SCENES, [fakes.AlwaysRight()], quick=False)
    asked = advise(full, Envelope(kinds=("sphere_scene",)))
    assert not asked.quick and asked.not_asked == 0 and asked.cases == 3


def test_the_answer_says_how_many_cases_it_rests_on(
        scenes: Run, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(scenes.directory), "--kind", "sphere_scene", "--step-travel",
                 "1", "--fraction-tolerance", "1e-3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["cases"] == 1  # only the slow scene travels under 1 per step
    assert data["rests_on"] == {"fake-right": 1, "fake-damped": 1, "fake-soft": 1}
    assert data["envelope"]["step_travel"] == 1.0 and data["not_asked"] == 1
    assert main(["advise", str(scenes.directory), "--kind", "sphere_scene", "--step-travel",
                 "1", "--fraction-tolerance", "1e-3"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("the answer rests on 1 cases (sphere_scene; 2-D)")
    header = next(line for line in lines if line.startswith("#"))
    assert header.split()[:5] == ["#", "engine", "tier", "cases", "within"]
    right = next(line for line in lines if " fake-right " in line)
    assert right.split()[2:4] == ["pass", "1"]
    accuracy = next(line for line in lines if line.startswith("accuracy: "))
    assert accuracy.startswith("accuracy: shares of their scale 0.001, lengths: agree only")


def test_the_answer_says_which_cells_of_the_space_it_rests_on(pairs: Run) -> None:
    asked = advise(pairs, Envelope())
    inside = [pairs.cases[i] for i in pairs.results["case_id"].unique()
              if not pairs.cases[i].bad_input]
    expected = {f"{c.kind.value} {c.dim}-D": (c.covered, c.cells)
                for c in coverage(inside, 2) if c.cases}
    assert asked.cells == expected and expected  # what crosscheck validate counts
    assert all(0 < covered < cells for covered, cells in asked.cells.values())
    flat = advise(pairs, Envelope(dims=(2,)))
    assert set(flat.cells) == {"sphere 2-D"} and flat.cells["sphere 2-D"][0] > 0
