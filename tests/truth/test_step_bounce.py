"""A bounce added at the end of the step and taken from the approach at the step's start
(``bounce_at_step_end``, ``bounce_from_step_start``: Box2D v3's ``b2ApplyRestitution``): each
rule tested both ways, the run it describes labelled as its rule says, one just past its
bound an ``error``, and the same run an ``error`` without the declared convention.  The
engine runs are built from the rules' own models, never copied from an engine."""

from __future__ import annotations

import math
from typing import Any

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Category, Observation
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.truth import bounces, drop_rules, scene_runs, scenes
from crosscheck.truth.score import judge

LATE = Conventions(sampled_contacts=True, bounce_at_step_end=True)
STARTS = Conventions(restitution_threshold=1.0, bounce_from_step_start=True)


def head_on(phase: float, dt: float = 1.0 / 60.0) -> SceneCase:
    """Two discs (r 0.05, 1.5 m/s each) meeting ``phase`` of a step into step 4."""
    r, speed = 0.05, 1.5
    t = (4 + phase) * dt
    made = CASE_ADAPTER.validate_python({
        "id": "h", "description": "d", "kind": "sphere_scene", "dim": 2,
        "duration": 9 * dt, "dt": dt, "bodies": [
            {"center": [-(r + speed * t), 0.0], "radius": r, "mass": 1.0,
             "velocity": [speed, 0.0]},
            {"center": [r + speed * t, 0.0], "radius": r, "mass": 1.0,
             "velocity": [-speed, 0.0]}]})
    assert isinstance(made, SceneCase)
    return made


def judged(case: SceneCase, conv: Conventions, observed: Observation, quantity: str) -> Any:
    return judge(case, conv, quantity, observed.get(quantity), scenes.truth(case), observed)


def held_back(case: SceneCase, steps: int) -> Observation:
    """The run of an engine that finds the pair overlapping at a step start, stops the
    approach there (the contact solve) and adds the bounce ``steps`` step ends later."""
    found = scene_runs.first_overlap(case)
    assert found is not None
    dt = case.dt or 0.0
    stopped = scene_runs.resolve(case, found.centres, 0.0)
    after = scene_runs.resolve(case, found.centres, case.restitution)
    centres = tuple(tuple(p + v * steps * dt for p, v in zip(c, w, strict=True))
                    for c, w in zip(found.centres, stopped, strict=True))
    return scene_runs.final_state(case, found.step + steps, (centres[0], centres[1]), after)


def test_a_bounce_added_at_the_step_end_lags_the_discrete_run_by_one_step() -> None:
    case = head_on(0.7)  # overlapping by 0.3 of a step's closing at the start of step 5
    run = held_back(case, 1)
    verdict = judged(case, LATE, run, "positions")
    assert verdict.category == Category.TIMESTEP, verdict.reason
    assert "bounce_at_step_end" in verdict.reason and "start of step 5" in verdict.reason
    without = Conventions(sampled_contacts=True)
    assert judged(case, without, run, "positions").category == Category.ERROR
    two = held_back(case, 2)  # two steps late: beyond the one event's bound
    assert judged(case, LATE, two, "positions").category == Category.ERROR


def test_the_lag_is_each_body_s_share_of_the_bounce_for_one_step() -> None:
    case = head_on(0.7)
    found = scene_runs.first_overlap(case)
    assert found is not None
    lag = scene_runs.step_end_lag(case, LATE, found.centres, 1.0)
    assert math.isclose(lag, 0.5 * 1.0 * 3.0 * (case.dt or 0.0))  # m/M x e x closing x dt
    assert scene_runs.step_end_lag(case, Conventions(), found.centres, 1.0) == 0.0
    plastic = scene_runs.step_end_lag(case, LATE, found.centres, 0.0)
    assert plastic == 0.0  # no bounce, nothing added late


def cradle(gap: float = 0.0, speed: float = 2.0) -> SceneCase:
    made = CASE_ADAPTER.validate_python({
        "id": "c", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": 1.0,
        "dt": 0.01, "bodies": [
            {"center": [0.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [speed, 0.0]},
            {"center": [1.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [0.0, 0.0]},
            {"center": [2.0 + gap, 0.0], "radius": 0.5, "mass": 1.0,
             "velocity": [0.0, 0.0]}]})
    assert isinstance(made, SceneCase)
    return made


def chain_step(case: SceneCase, extra: float = 0.0) -> Observation:
    """One step of an engine that takes the bounce from the approach at the step's start:
    the solve stops every approach (all three at the common speed), then only the pair that
    approached when the step started, (0, 1), bounces with e; ``extra`` moves momentum from
    body 0 to body 1 on top (it keeps the momentum and adds energy)."""
    v0 = case.bodies[0].velocity[0]
    common = v0 / 3
    kick = 0.5 * case.restitution * v0  # m_eff x e x the approach at the step's start
    vx = (common - kick - extra, common + kick + extra, common)
    t = float(scenes.simulated_time(case))
    return scenes.observation([(b.center[0] + v * t, 0.0) for b, v in zip(case.bodies, vx,
                                                                          strict=True)],
                              [(v, 0.0) for v in vx], [b.mass for b in case.bodies])


def test_a_chain_within_a_step_gets_no_bounce_under_a_declared_step_start_approach() -> None:
    case = cradle()  # touching: the exact run's impacts (0, 1) and (1, 2) at one instant
    run = chain_step(case)
    exact = scenes.truth(case)
    assert isinstance(run.energy, float) and isinstance(exact.energy, float)
    assert run.energy < exact.energy  # energy lost, momentum kept
    for quantity in ("positions", "velocities", "energy"):
        verdict = judged(case, STARTS, run, quantity)
        assert verdict.category == Category.CONVENTION, verdict.reason
        assert "bounce_from_step_start" in verdict.reason
    assert judged(case, Conventions(restitution_threshold=1.0), run,
                  "positions").category == Category.ERROR


def test_a_chain_that_gains_energy_or_is_not_within_a_step_is_an_error() -> None:
    case = cradle()
    hot = chain_step(case, extra=0.5)
    assert isinstance(hot.energy, float) and hot.energy > 2.0  # above the initial 0.5 m v^2
    assert judged(case, STARTS, hot, "positions").category == Category.ERROR
    apart = cradle(gap=0.5)  # body 1 needs 0.25 s to reach body 2: 25 steps, no chain
    assert judged(apart, STARTS, chain_step(apart), "positions").category == Category.ERROR


G, DT = 8.0, 1.0 / 64.0


def drop() -> SceneCase:
    made = CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": 4.0,
        "dt": DT, "restitution": 0.8, "gravity": [0.0, -G],
        "walls": [{"normal": [0.0, 1.0], "offset": 0.0}],
        "bodies": [{"center": [0.0, 1.5], "radius": 0.5, "mass": 1.0,
                    "velocity": [0.0, 0.0]}]})
    assert isinstance(made, SceneCase)
    return made


def test_a_fall_within_one_step_of_gravity_above_the_threshold_may_not_bounce() -> None:
    case = drop()  # falls 1 m: hits the ground at 4 m/s; |g| dt = 0.125 m/s
    exact = scenes.truth(case)
    assert isinstance(exact.apex, tuple) and len(exact.apex) > 1
    conv = Conventions()
    dead = Observation(apex=(0.0,), bounce_time=(bounces.first_fall(case, conv),))
    band = Conventions(restitution_threshold=3.9, bounce_from_step_start=True)
    inside = drop_rules.sequence(case, band, dead, exact)
    assert inside is not None and inside.category == Category.CONVENTION, inside
    assert "bounce_from_step_start" in inside.why
    plain = drop_rules.sequence(case, Conventions(restitution_threshold=3.9), dead, exact)
    assert plain is not None and plain.category == Category.ERROR
    beyond = Conventions(restitution_threshold=3.87, bounce_from_step_start=True)
    outside = drop_rules.sequence(case, beyond, dead, exact)  # 4 >= 3.87 + 0.125
    assert outside is not None and outside.category == Category.ERROR
