"""Dynamics labels from one event's bound or a declared value (:mod:`crosscheck.truth.bounces`,
:mod:`crosscheck.truth.drop_rules`, :mod:`crosscheck.truth.scene_runs`,
:mod:`crosscheck.truth.scene_rules`): each bound tested both ways, a run the rule describes
inside it and one just past it outside.  The engine runs here are built from the rules'
own models (a bounce found one or two steps late, a contact met at a step start), never
copied from an engine."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Category, Observation
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.truth import bounces, drop_rules, scene_runs, scenes
from crosscheck.truth.score import judge

G, DT = 8.0, 1.0 / 64.0


def drop(restitution: float = 1.0, duration: float = 4.0) -> SceneCase:
    made = CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": duration,
        "dt": DT, "restitution": restitution, "gravity": [0.0, -G],
        "walls": [{"normal": [0.0, 1.0], "offset": 0.0}],
        "bodies": [{"center": [0.0, 1.5], "radius": 0.5, "mass": 1.0,
                    "velocity": [0.0, 0.0]}]})
    assert isinstance(made, SceneCase)
    return made


def bounced(case: SceneCase, conv: Conventions, lose_steps: float,
            gain: float = 0.0) -> Observation:
    """Body 0's apexes and bounce times as an engine that meets every bounce ``lose_steps``
    steps late (losing that many steps' depth ``v dt + |g| dt**2`` of height) or gains
    ``gain`` of its height each bounce, from its own previous apex."""
    exact = scenes.truth(case)
    assert isinstance(exact.apex, tuple) and isinstance(exact.bounce_time, tuple)
    apexes: list[float] = []
    times = [bounces.first_fall(case, conv)]
    previous = bounces.drop_height(case)
    for _ in exact.apex:
        speed = math.sqrt(2 * G * previous)
        expected = (case.restitution * speed) ** 2 / (2 * G)
        apex = expected * (1 + gain) - lose_steps * (speed * DT + G * DT * DT)
        apexes.append(apex)
        times.append(times[-1] + 2 * math.sqrt(2 * max(apex, 0.0) / G))
        previous = apex
    return Observation(apex=tuple(apexes), bounce_time=tuple(times[:len(exact.bounce_time)]))


def test_a_bounce_met_one_step_late_is_inside_its_bound_and_two_steps_late_outside() -> None:
    case, conv = drop(), Conventions()
    exact = scenes.truth(case)
    inside = drop_rules.sequence(case, conv, bounced(case, conv, 0.9), exact)
    assert inside is not None and inside.category == Category.TIMESTEP
    assert "within one step's lag" in inside.why
    outside = drop_rules.sequence(case, conv, bounced(case, conv, 2.2), exact)
    assert outside is not None and outside.category == Category.ERROR
    assert "loses" in outside.why and "beyond one step's lag" in outside.why


def test_a_gain_per_bounce_is_never_step_lag() -> None:
    case, conv = drop(), Conventions()
    gained = drop_rules.sequence(case, conv, bounced(case, conv, 0.0, gain=0.05),
                                 scenes.truth(case))
    assert gained is not None and gained.category == Category.ERROR
    assert "gains" in gained.why and "no step lag adds energy" in gained.why
    # a declared soft contact keeps any part of a bounce, but never adds to it
    soft = Conventions(restitution_model="soft")
    more = drop_rules.sequence(case, soft, bounced(case, soft, 0.0, gain=0.05),
                               scenes.truth(case))
    less = drop_rules.sequence(case, soft, bounced(case, soft, 3.0), scenes.truth(case))
    assert more is not None and more.category == Category.ERROR
    assert less is not None and less.category == Category.CONVENTION


def test_each_bounce_is_judged_from_the_engines_own_previous_apex() -> None:
    # a loss of one step per bounce compounds over the run (the apexes fall well below the
    # exact ones) yet each bounce is within its own bound: no sum over the run is needed
    case, conv = drop(), Conventions()
    run = bounced(case, conv, 0.9)
    assert isinstance(run.apex, tuple)
    events = bounces.apexes(case, conv, run.apex, 0.0)
    assert all(e.within for e in events)
    assert 1.0 - run.apex[-1] > max(e.depth for e in events)  # more than one step's depth


def pair(step_travel: float, phase: float, angle: float = 0.0) -> SceneCase:
    """Two discs at 1 m/s each, their impact ``phase`` of a step into the step it falls in."""
    r, speed = 0.05, 1.0
    dt = step_travel * 2 * (2 * r) / (2 * speed)
    offset = 2 * r * math.sin(angle)
    along = math.sqrt((2 * r) ** 2 - offset ** 2)
    t = (4 + phase) * dt
    made = CASE_ADAPTER.validate_python({
        "id": "p", "description": "d", "kind": "sphere_scene", "dim": 2,
        "duration": 9 * dt, "dt": dt, "bodies": [
            {"center": [-(along / 2 + speed * t), 0.0], "radius": r, "mass": 1.0,
             "velocity": [speed, 0.0]},
            {"center": [along / 2 + speed * t, offset], "radius": r, "mass": 1.0,
             "velocity": [-speed, 0.0]}]})
    assert isinstance(made, SceneCase)
    return made


def judged(case: SceneCase, conv: Conventions, observed: Observation, quantity: str) -> Any:
    exact = scenes.truth(case)
    return judge(case, conv, quantity, observed.get(quantity), exact, observed)


def test_the_discrete_run_is_timestep_and_a_run_a_step_later_is_not() -> None:
    case = pair(0.5, 0.5, angle=0.6)
    found = scene_runs.first_overlap(case)
    assert found is not None
    run = scene_runs.final_state(case, found.step, found.centres,
                                 scene_runs.resolve(case, found.centres, 1.0))
    for quantity in ("positions", "velocities"):
        verdict = judged(case, Conventions(), run, quantity)
        assert verdict.category == Category.TIMESTEP, verdict.reason
        assert f"start of step {found.step}" in verdict.reason
    later = tuple(tuple(p + v * (case.dt or 0.0) for p, v in zip(c, b.velocity, strict=True))
                  for c, b in zip(found.centres, case.bodies, strict=True))
    late = scene_runs.final_state(case, found.step + 1, (later[0], later[1]),
                                  scene_runs.resolve(case, (later[0], later[1]), 1.0))
    assert judged(case, Conventions(), late, "velocities").category == Category.ERROR


def test_a_speculative_contact_is_timestep_only_when_declared() -> None:
    case = pair(0.75, 0.7, angle=0.6)
    first = scenes.truth(case).impacts
    assert first
    k = math.floor(first[0] / (case.dt or 0.0))
    at = scene_runs.centres_at(case, k * (case.dt or 0.0))
    run = scene_runs.final_state(case, k, at, scene_runs.resolve(case, at, 1.0))
    speculative = Conventions(speculative_contacts=True)
    verdict = judged(case, speculative, run, "velocities")
    assert verdict.category == Category.TIMESTEP and "speculative_contacts" in verdict.reason
    assert judged(case, Conventions(), run, "velocities").category == Category.ERROR


def test_declared_friction_explains_a_tangential_impulse_up_to_mu_times_the_normal() -> None:
    case = pair(0.1, 0.5, angle=0.6)
    exact = scenes.truth(case)
    assert exact.impacts
    t = exact.impacts[0]
    at = scene_runs.centres_at(case, t)
    va, vb = scene_runs.resolve(case, at, 1.0)
    d = [y - x for x, y in zip(*at, strict=True)]
    n = [x / math.hypot(*d) for x in d]
    tangent = (-n[1], n[0])
    normal = abs(vb[0] * n[0] + vb[1] * n[1] - (-1.0 * n[0]))  # B's normal speed change
    slip = 0.3 * normal  # a tangential impulse of 0.3 x the normal one, per unit mass
    rubbed = ((va[0] - slip * tangent[0], va[1] - slip * tangent[1]),
              (vb[0] + slip * tangent[0], vb[1] + slip * tangent[1]))
    run = scene_runs.flown(case, t, at, rubbed)
    within = judged(case, Conventions(friction=0.5), run, "velocities")
    assert within.category == Category.CONVENTION and "declared friction 0.5" in within.reason
    assert judged(case, Conventions(friction=0.1), run, "velocities").category == Category.ERROR


def three() -> SceneCase:
    made = CASE_ADAPTER.validate_python({
        "id": "t", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": 3.0,
        "dt": 0.01, "bodies": [
            {"center": [-2.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [1.0, 0.0]},
            {"center": [0.0, 0.3], "radius": 0.5, "mass": 2.0, "velocity": [0.0, 0.0]},
            {"center": [2.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [-1.0, 0.0]}]})
    assert isinstance(made, SceneCase)
    return made


def test_chained_impacts_keep_what_every_run_of_them_keeps_or_are_an_error() -> None:
    case = three()
    exact = scenes.truth(case)
    assert exact.impacts and len(exact.impacts) >= 2
    assert isinstance(exact.positions, tuple)
    moved = replace(exact, positions=tuple((p[0] + 0.2, p[1]) for p in exact.positions))
    kept = judged(case, Conventions(), moved, "positions")
    assert kept.category == Category.TIMESTEP and "keeps momentum" in kept.reason
    assert isinstance(exact.energy, float)
    hot = replace(moved, energy=exact.energy * 1.01)
    assert judged(case, Conventions(), hot, "positions").category == Category.ERROR


def test_a_first_impact_below_the_declared_threshold_explains_the_energy_lost() -> None:
    case = three()  # the first impact closes at 1 m/s
    exact = scenes.truth(case)
    assert isinstance(exact.energy, float)
    cold = replace(exact, energy=0.5 * exact.energy)
    above = judged(case, Conventions(restitution_threshold=1.5), cold, "energy")
    assert above.category == Category.CONVENTION and "threshold" in above.reason
    assert judged(case, Conventions(restitution_threshold=0.5), cold,
                  "energy").category == Category.ERROR


def test_a_cap_per_coordinate_clips_each_axis_and_a_cap_on_the_speed_scales_it() -> None:
    per_axis = Conventions(max_speed=100.0, max_speed_at="per coordinate")
    assert per_axis.clip((150.0, -50.0), 100.0) == (100.0, -50.0)
    on_speed = Conventions(max_speed=100.0, max_speed_at="step")
    clipped = on_speed.clip((150.0, -50.0), 100.0)
    assert math.isclose(math.hypot(*clipped), 100.0) and clipped[0] < 100.0


def test_a_float32_scene_whose_precision_reaches_its_bodies_is_tolerance_throughout() -> None:
    case = pair(0.5, 0.5)
    far = case.model_copy(update={"bodies": tuple(
        b.model_copy(update={"center": (b.center[0] + 1e7, b.center[1])}) for b in case.bodies)})
    f32 = Conventions(rtol=2.0**-21)
    assert scenes.coarse(far, f32) and not scenes.coarse(case, f32)
    exact = scenes.truth(far)
    assert isinstance(exact.positions, tuple)
    off = replace(exact, positions=tuple((p[0] + 0.01, p[1]) for p in exact.positions))
    assert judged(far, f32, off, "positions").category == Category.TOLERANCE
    assert judged(far, Conventions(), off, "positions").category != Category.TOLERANCE
