"""Scene scoring (:mod:`crosscheck.truth.scenes`): a scene's disagreement is ``timestep``
when the positions lag the truth by no more than the step allows, ``convention`` when the
energy lost is what the declared damping takes, and ``error`` beyond both.

The engine answers are the exact truth shifted by known amounts, never an engine's output.
"""

from __future__ import annotations

from dataclasses import replace

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Category, Observation
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.truth import scenes
from crosscheck.truth.score import judge


def _scene(dt: float) -> SceneCase:
    case = CASE_ADAPTER.validate_python({
        "id": "s", "description": "head on", "kind": "sphere_scene", "dim": 2, "duration": 1.0,
        "dt": dt, "bodies": [
            {"center": [0.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [1.0, 0.0]},
            {"center": [2.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [-1.0, 0.0]}]})
    assert isinstance(case, SceneCase)
    return case


def _shifted(truth: Observation, dx: float, dv: float) -> Observation:
    assert isinstance(truth.positions, tuple) and isinstance(truth.velocities, tuple)
    return replace(truth, positions=tuple((p[0] + dx, p[1]) for p in truth.positions),
                   velocities=tuple((v[0] + dv, v[1]) for v in truth.velocities), impacts=None)


def test_scenes_get_categories_from_the_step_and_declared_damping() -> None:
    case = _scene(0.01)
    truth = scenes.truth(case)
    assert truth.impacts is not None and len(truth.impacts) == 1
    travel = 1.0 * 0.01 / 0.5  # one step at the top speed 1, dt 0.01, in mean radii 0.5
    late = _shifted(truth, 0.5 * travel * 0.5, 0.0)  # positions off by half a step's travel
    verdict = judge(case, Conventions(), "positions", late.positions, truth, late)
    assert verdict.category == Category.TIMESTEP and "a step late" in verdict.reason
    assert f"v dt = {travel:.3g} mean radii" in verdict.reason
    far = _shifted(truth, 2.0 * travel * 0.5, 0.01)
    assert judge(case, Conventions(), "positions", far.positions, truth, far).category == "error"
    # an elastic head-on impact met a step late swaps the same velocities: no lag explains
    # velocities that differ, whether the positions are within a step's travel or not
    assert judge(case, Conventions(), "velocities", far.velocities, truth, far).category == "error"
    near = _shifted(truth, 0.0, 0.01)
    assert judge(case, Conventions(), "velocities", near.velocities, truth,
                 near).category == "error"
    drained = replace(truth, energy=0.9 * float(truth.energy or 0.0))
    damped = judge(case, Conventions(damping=0.04), "energy", drained.energy, truth, drained)
    assert damped.category == Category.CONVENTION and "damps" in damped.reason
    assert judge(case, Conventions(), "energy", drained.energy, truth, drained).category == "error"


def test_a_scene_within_the_declared_precision_is_tolerance_beyond_it_error() -> None:
    case = _scene(0.01)
    truth = scenes.truth(case)
    f32 = Conventions(rtol=2.0**-21)
    bound = scenes.PRECISION_FACTOR * f32.rtol
    assert truth.energy is not None
    within = replace(truth, energy=float(truth.energy) * (1.0 + 0.5 * bound))
    verdict = judge(case, f32, "energy", within.energy, truth, within)
    assert verdict.category == Category.TOLERANCE and "declared precision" in verdict.reason
    # the same error on an engine that declares no precision, or twice the bound: error
    assert judge(case, Conventions(), "energy", within.energy, truth, within).category == "error"
    beyond = replace(truth, energy=float(truth.energy) * (1.0 + 2.0 * bound))
    assert judge(case, f32, "energy", beyond.energy, truth, beyond).category == "error"
    # positions have their own precision: rtol of the scene's coordinates, in mean radii
    held = scenes.held(case, f32)
    inside = _shifted(truth, 0.5 * held, 0.0)
    assert judge(case, f32, "positions", inside.positions, truth,
                 inside).category == "tolerance"
    moved = _shifted(truth, 2.0 * held, 0.0)
    assert judge(case, f32, "positions", moved.positions, truth, moved).category != "tolerance"
