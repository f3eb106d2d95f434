"""Fast-body scenes: the step_travel and phase expansion, a missed impact named as such, and
a declared per-step speed cap measured against the exact run with capped speeds."""

from __future__ import annotations

import math

from crosscheck.cases.expand import expand
from crosscheck.core.contract import Conventions
from crosscheck.core.model import Category, Observation, Status
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.truth import oracle, scene_runs, scenes
from crosscheck.truth.score import judge


def block(**sweep: list[float]) -> SceneCase:
    case = CASE_ADAPTER.validate_python({
        "id": "f", "description": "d", "kind": "sphere_scene", "dim": 2,
        "steps": {"dt": [1 / 60, 1 / 240]}, "sweep": sweep, "bodies": [
            {"center": [-1.0123456789, 0.0], "radius": 0.05, "mass": 1.0, "velocity": [1, 0]},
            {"center": [1.0123456789, 0.0], "radius": 0.05, "mass": 1.0, "velocity": [-1, 0]}]})
    assert isinstance(case, SceneCase)
    return case


def points(**sweep: list[float]) -> list[SceneCase]:
    out = [c for c in expand(block(**sweep)) if isinstance(c, SceneCase)]
    assert out
    return out


def test_each_point_has_its_travel_and_its_impact_inside_the_step_it_names() -> None:
    for case in points(step_travel=[0.1, 2.0, 10.0], phase=[0.1, 0.9]):
        assert math.isclose(scenes.step_travel(case), case.coords["step_travel"], rel_tol=1e-12)
        impacts = oracle.truth(case).impacts
        assert impacts is not None and len(impacts) == 1
        dt = case.dt or 0.0
        assert math.isclose(impacts[0] / dt, case.approach_steps + case.coords["phase"],
                            rel_tol=1e-9)
        assert scenes.aligned(case, impacts) == []


def free_flight(case: SceneCase) -> Observation:
    t = float(scenes.simulated_time(case))
    return scenes.observation(
        [tuple(c + v * t for c, v in zip(b.center, b.velocity, strict=True))
         for b in case.bodies], [b.velocity for b in case.bodies], [b.mass for b in case.bodies])


def test_a_missed_impact_is_named_and_is_timestep_only_for_a_declared_sampler() -> None:
    (case,) = points(step_travel=[2.0], phase=[0.5])[:1]
    truth, passed = oracle.truth(case), free_flight(case)
    sampler = judge(case, Conventions(sampled_contacts=True), "velocities", passed.velocities,
                    truth, passed)
    assert sampler.status is Status.DISAGREE and sampler.category == Category.TIMESTEP
    assert "passed through each other at step travel 2" in sampler.reason
    continuous = judge(case, Conventions(), "velocities", passed.velocities, truth, passed)
    assert continuous.category == Category.ERROR
    assert "passed through each other" in continuous.reason


def test_a_miss_while_a_step_start_finds_the_pair_approaching_is_an_error() -> None:
    slow = points(step_travel=[0.25], phase=[0.5])[0]
    passed = free_flight(slow)
    verdict = judge(slow, Conventions(sampled_contacts=True), "velocities", passed.velocities,
                    oracle.truth(slow), passed)
    assert verdict.category == Category.ERROR
    assert "overlap, approaching, at the start of step" in verdict.reason


def test_a_declared_per_step_speed_cap_explains_the_capped_run() -> None:
    case = points(step_travel=[10.0], phase=[0.5])[0]
    dt = case.dt or 0.0
    top = max(math.hypot(*b.velocity) for b in case.bodies)
    cap = Conventions(max_speed=0.5 * top, max_speed_at="step", time_step=dt)
    slow = scene_runs.capped(case, cap)
    assert slow is not None
    engine = oracle.truth(slow)
    verdict = judge(case, cap, "positions", engine.positions, oracle.truth(case), engine)
    assert verdict.status is Status.DISAGREE and verdict.category == Category.CONVENTION
    assert "caps speeds" in verdict.reason
    uncapped = judge(case, Conventions(), "positions", engine.positions, oracle.truth(case),
                     engine)
    assert uncapped.category != Category.CONVENTION


def test_a_pass_that_only_slows_down_is_named_from_the_side_the_bodies_end_on() -> None:
    case = points(step_travel=[2.0], phase=[0.5])[0]
    truth = oracle.truth(case)
    t = float(scenes.simulated_time(case))
    slowed = [tuple(0.9 * v for v in b.velocity) for b in case.bodies]
    engine = scenes.observation(
        [tuple(c + 0.9 * v * t for c, v in zip(b.center, b.velocity, strict=True))
         for b in case.bodies], slowed, [b.mass for b in case.bodies])
    verdict = judge(case, Conventions(), "velocities", engine.velocities, truth, engine)
    assert "passed through each other" in verdict.reason and "past A" in verdict.reason
    bounced = judge(case, Conventions(), "velocities", truth.velocities, truth, truth)
    assert bounced.status is Status.AGREE


def test_a_slow_impact_under_a_declared_restitution_threshold_is_a_convention() -> None:
    case = points(step_travel=[0.1], phase=[0.5])[0]  # closing at 1.2 m/s
    stuck = oracle.truth(case.model_copy(update={"restitution": 0.0}))
    below = Conventions(restitution_threshold=2.0)
    verdict = judge(case, below, "velocities", stuck.velocities, oracle.truth(case), stuck)
    assert verdict.category == Category.CONVENTION and "restitution threshold" in verdict.reason
    above = Conventions(restitution_threshold=1.0)  # the impact closes faster: it must bounce
    assert judge(case, above, "velocities", stuck.velocities, oracle.truth(case),
                 stuck).category != Category.CONVENTION


def test_declared_damping_explains_no_more_energy_than_it_can_remove() -> None:
    case = points(step_travel=[0.1], phase=[0.5])[0]
    truth = oracle.truth(case)
    assert isinstance(truth.energy, float)
    damped = Conventions(damping=0.04)
    small = judge(case, damped, "energy", truth.energy * (1 - 1e-4), truth, truth)
    assert small.category == Category.CONVENTION
    large = judge(case, damped, "energy", truth.energy * 0.5, truth, truth)
    assert large.category != Category.CONVENTION


def test_step_lag_and_damping_explain_velocities_only_with_positions_within_them() -> None:
    case = points(step_travel=[8.0], phase=[0.5])[0]
    truth = oracle.truth(case)
    t = float(scenes.simulated_time(case))
    half = [tuple(0.5 * v for v in b.velocity) for b in case.bodies]  # never reached each other
    engine = scenes.observation(
        [tuple(c + 0.5 * v * t for c, v in zip(b.center, b.velocity, strict=True))
         for b in case.bodies], half, [b.mass for b in case.bodies])
    verdict = judge(case, Conventions(damping=0.04), "velocities", engine.velocities, truth,
                    engine)
    assert verdict.category == Category.ERROR
