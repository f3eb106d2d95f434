"""The scene measures under gravity and between walls (:mod:`crosscheck.truth.scene_measures`)
on hand-made trajectories, and the exact measures :func:`crosscheck.truth.scenes.truth`
gives small gravity scenes (expected values from closed forms: a dyadic drop with g = 8
from a gap of 1 falls for 1/2 s and, at e = 1/2, rests on the ground from 3/2 s).
"""

from __future__ import annotations

import itertools
import math
from fractions import Fraction
from typing import Any

import pytest

from crosscheck.core.model import Trajectory, Undefined
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.truth import scene_measures as sm
from crosscheck.truth import scenes

F = Fraction
GROUND = {"normal": [0.0, 1.0], "offset": 0.0}


def scene(bodies: list[dict[str, Any]], **fields: Any) -> SceneCase:
    case = CASE_ADAPTER.validate_python({
        "id": "m", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": 1.0,
        "bodies": bodies, **fields})
    assert isinstance(case, SceneCase)
    return case


def body(center: list[float], radius: float = 0.5, mass: float = 1.0,
         velocity: tuple[float, float] = (0.0, 0.0)) -> dict[str, Any]:
    return {"center": center, "radius": radius, "mass": mass, "velocity": list(velocity)}


def drop_case(**fields: Any) -> SceneCase:
    """A unit-mass disc r = 1/2 with its bottom 1 above the ground, g = 8."""
    return scene([body([0.0, 1.5])], gravity=[0.0, -8.0], walls=[GROUND], **fields)


def track(heights: list[float], speeds: list[float], dt: float = 0.1,
          radius: float = 0.5) -> Trajectory:
    """Body 0 straight above the ground at 0: its gap and vertical speed at each record."""
    return Trajectory(tuple(k * dt for k in range(len(heights))),
                      tuple(((0.0, h + radius),) for h in heights),
                      tuple(((0.0, v),) for v in speeds), (0.0,) * len(heights))


# ------------------------------------------------------------------ bounces


def test_bounces_are_turns_from_closing_to_opening_with_the_apex_of_each_flight() -> None:
    case = drop_case()
    heights = [1.0, 0.375, 0.0, 0.25, 0.5, 0.4375, 0.125, 0.0625, 0.125, 0.25, 0.1875]
    speeds = [-1.0, -2.0, 2.0, 1.5, 0.1, -0.5, -1.8, 1.7, 1.0, 0.2, -0.3]
    apexes, times = sm.bounces(case, track(heights, speeds))
    assert times == pytest.approx((0.2, 0.7))  # the records where the speed turned up
    assert apexes == (0.5, 0.25)  # the largest gap of each flight, not the last record


def test_a_bounce_recorded_through_a_speed_of_exactly_zero_counts() -> None:
    case = drop_case()
    apexes, times = sm.bounces(case, track([0.3, 0.0, 0.0, 0.2, 0.4, 0.3],
                                           [-2.0, 0.0, 1.0, 0.5, 0.0, -0.5]))
    assert times == pytest.approx((0.2,)) and apexes == (0.4,)


def test_an_apex_not_reached_by_the_end_is_not_counted() -> None:
    case = drop_case()
    apexes, times = sm.bounces(case, track([0.5, 0.0, 0.3, 0.6], [-2.0, 2.0, 1.0, 0.5]))
    assert times == pytest.approx((0.1,)) and apexes == ()


def test_resting_or_falling_records_make_no_bounce() -> None:
    case = drop_case()
    assert sm.bounces(case, track([0.0] * 5, [0.0] * 5)) == ((), ())
    assert sm.bounces(case, track([1.0, 0.9, 0.6], [-0.5, -1.0, -2.0])) == ((), ())


def test_bounces_read_the_normal_of_the_ground_wherever_it_is() -> None:
    """A ceiling at y = 2 with gravity up: closing is +y, the gap is 2 - y - r."""
    case = scene([body([0.0, 0.5])], gravity=[0.0, 8.0],
                 walls=[{"normal": [0.0, -1.0], "offset": -2.0}])
    ys = [1.0, 1.5, 1.2, 0.9, 1.1]
    vs = [1.0, -1.0, -1.0, 1.0, 1.0]
    run = Trajectory((0.0, 0.1, 0.2, 0.3, 0.4), tuple(((3.0, y),) for y in ys),
                     tuple(((0.0, v),) for v in vs), (0.0,) * 5)
    apexes, times = sm.bounces(case, run)
    assert times == (0.1,) and apexes == (2.0 - 0.9 - 0.5,)  # the largest gap, at y = 0.9


def test_no_ground_means_no_bounces() -> None:
    walls_only = scene([body([0.0, 1.5])], walls=[GROUND])  # no gravity: nothing faces it
    assert sm.ground(walls_only) is None
    assert sm.bounces(walls_only, track([1.0, 0.0, 1.0], [-1.0, 1.0, -1.0])) == ((), ())


def test_the_ground_is_the_first_wall_facing_gravity() -> None:
    box = scene([body([0.0, 1.5])], gravity=[0.0, -8.0], walls=[
        {"normal": [1.0, 0.0], "offset": -2.0}, {"normal": [0.0, -1.0], "offset": -4.0},
        {"normal": [0.0, 1.0], "offset": 0.25}])
    assert sm.ground(box) == 2
    assert sm.gap(box, 2, (1.0, 1.5), 0.5) == 0.75
    assert sm.gap(box, 1, (1.0, 1.5), 0.5) == 2.0  # 4 - 1.5 - 0.5


# ------------------------------------------------------------------ divergence


def test_divergence_is_the_first_record_further_than_diverge_at_mean_radii() -> None:
    case = scene([body([0.0, 1.5], radius=0.5), body([3.0, 1.5], radius=1.5)],
                 gravity=[0.0, -8.0], walls=[GROUND], diverge_at=0.25)  # reach 0.25 x 1 = 0.25
    exact = Trajectory((0.0, 0.5, 1.0, 1.5),
                       tuple(((0.0, 1.5), (3.0, 1.5)) for _ in range(4)),
                       tuple(((0.0, 0.0), (0.0, 0.0)) for _ in range(4)), (0.0,) * 4)

    def moved(shifts: list[float]) -> Trajectory:
        return Trajectory(exact.times, tuple(((0.0, 1.5), (3.0 + s, 1.5)) for s in shifts),
                          exact.velocities, exact.energy)

    assert sm.divergence(case, moved([0.0, 0.25, 0.3, 0.0]), exact) == 1.0  # 0.25 is inside
    assert sm.divergence(case, moved([0.0, 0.1, -0.2, 0.24]), exact) == 1.5  # never: the end
    assert sm.divergence(case, moved([0.0, math.nan, 0.0, 0.0]), exact) == 0.5  # NaN is out
    assert sm.divergence(case, Trajectory((), (), (), ()), exact) == 0.0


# ------------------------------------------------------------------ recording


def test_open_space_records_nothing_and_a_surrounded_scene_every_step() -> None:
    open_space = scene([body([0.0, 0.0]), body([2.0, 0.0])], dt=0.01)
    assert not sm.surrounded(open_space)
    assert sm.record_every(open_space) == 0 and sm.sample_steps(open_space) == []
    drop = drop_case(dt=0.01, duration=2.0)  # 200 steps x 1 body: within MAX_SAMPLES
    assert sm.surrounded(drop)
    assert sm.record_every(drop) == 1 and sm.sample_steps(drop) == list(range(201))
    walls_only = scene([body([0.0, 1.5])], walls=[GROUND], dt=0.01)
    assert sm.surrounded(walls_only) and sm.record_every(walls_only) == 1


@pytest.mark.parametrize(("count", "duration", "every"), [
    (1, 200.0, 1),      # 20,000 steps x 1 body: exactly MAX_SAMPLES
    (1, 200.01, 2),     # one step more: every other
    (10, 30.01, 2),     # 3001 steps x 10 bodies = 30,010: ceil(1.5005)
    (7, 100.0, 4),      # 10,000 x 7 = 70,000: ceil(3.5)
])
def test_the_recording_stride_keeps_bodies_times_samples_within_the_cap(
        count: int, duration: float, every: int) -> None:
    bodies = [body([2.0 * k, 1.5]) for k in range(count)]
    case = scene(bodies, gravity=[0.0, -8.0], walls=[GROUND], dt=0.01, duration=duration)
    steps = case.step_count
    assert sm.record_every(case) == every == math.ceil(steps * count / sm.MAX_SAMPLES)
    samples = sm.sample_steps(case)
    assert samples[0] == 0 and samples[-1] == steps  # the start and the last step always
    assert all(b - a == every for a, b in itertools.pairwise(samples[:-1]))
    assert 0 < samples[-1] - samples[-2] <= every
    assert (len(samples) - 2) * count <= sm.MAX_SAMPLES


# ------------------------------------------------------------------ energy


def test_energy_scale_is_kinetic_plus_each_centre_height_times_m_g() -> None:
    case = scene([body([0.0, 1.5], mass=2.0, velocity=(3.0, 4.0)),
                  body([4.0, 0.75], radius=0.25, mass=0.5)],
                 gravity=[0.0, -10.0], walls=[{"normal": [0.0, 1.0], "offset": 0.5}])
    # kinetic 2 x 25 / 2 = 25; heights of the centres above y = 0.5: 1 and 0.25
    assert sm.energy_scale(case) == 25.0 + 2.0 * 10.0 * 1.0 + 0.5 * 10.0 * 0.25
    no_ground = scene([body([0.0, 1.5], mass=2.0, velocity=(3.0, 4.0))],
                      gravity=[0.0, -10.0])
    assert sm.energy_scale(no_ground) == 25.0 + 2.0 * 10.0 * 0.5  # the radius stands in
    no_gravity = scene([body([0.0, 1.5], mass=2.0, velocity=(3.0, 4.0))], walls=[GROUND])
    assert sm.energy_scale(no_gravity) == 25.0


def test_total_energy_and_drift_from_closed_forms() -> None:
    case = drop_case(duration=2.0, dt=0.25)
    # fallen by 1 at speed 4 (g = 8): the same energy as the start (0)
    assert sm.total_energy(case, [(0.0, 0.5)], [(0.0, -4.0)]) == 0.0
    # at rest on the ground: -m g . (p - p0) = -(1)(-8)(-1) = -8
    assert sm.total_energy(case, [(0.0, 0.5)], [(0.0, 0.0)]) == -8.0
    scale = sm.energy_scale(case)
    assert scale == 8.0 * 1.5  # m g times the centre's height
    assert sm.drift(case, -8.0, 2.0) == -8.0 / (12.0 * 2.0)
    assert sm.drift(case, 0.0, 2.0) == 0.0
    still = scene([body([0.0, 0.0]), body([2.0, 0.0])], walls=[GROUND | {"offset": -5.0}])
    assert sm.energy_scale(still) == 0.0 and sm.drift(still, 1.0, 2.0) == 0.5  # scale 1


def test_top_speed_adds_the_fall_to_the_ground() -> None:
    case = scene([body([0.0, 1.5], velocity=(3.0, 0.0)), body([2.0, 0.5])],
                 gravity=[0.0, -8.0], walls=[GROUND])
    assert sm.top_speed(case) == 5.0  # sqrt(9 + 2 x 8 x 1)


# ------------------------------------------------------------------ exact bounces


def test_exact_bounces_keep_flights_of_min_flight_steps_and_apexes_within_the_run() -> None:
    case = drop_case(duration=1.5, dt=1 / 64)
    g, dt = F(8), F(1, 64)
    e = F(1, 2)
    # the dyadic drop's bounces: t_k = 3/2 - 2^-k, leaving at u_k = 4 e^(k+1)
    events = [(F(3, 2) - F(1, 2**k), 0, 4 * e ** (k + 1)) for k in range(8)]
    events.insert(2, (F(1), 1, F(3)))  # another body's bounce is not body 0's
    apexes, times = sm.exact_bounces(case, events)
    # flights before the bounces: 1/2 (from the start), 1/2, 1/4, 1/8, 1/16 = 4 dt, then
    # 1/32 < MIN_FLIGHT_STEPS dt: cut there
    assert sm.MIN_FLIGHT_STEPS * dt == F(1, 16)
    assert times == (0.5, 1.0, 1.25, 1.375, 1.4375)
    # apex k+1 = u_k^2 / 2g = e^(2(k+1)), each at t_k + u_k / g <= 3/2
    assert apexes == tuple(float(e ** (2 * (k + 1))) for k in range(5))
    # a run of 70 steps (1.09375 s) has the bounces at 1/2 and 1; the apex after the second,
    # at 1 + 1/8 s, is past its end: not counted
    short = drop_case(duration=1.1, dt=1 / 64)
    end = short.step_count * dt
    assert end == F(70, 64)
    within = [event for event in events if event[0] <= end]
    assert sm.exact_bounces(short, within) == ((0.25,), (0.5, 1.0))
    assert F(1) + 4 * e**2 / g > end


# ------------------------------------------------------------------ exact measures


def defined(value: Any) -> bool:
    return not isinstance(value, Undefined)


def test_a_sphere_resting_on_the_ground_settles_at_zero_without_jitter() -> None:
    case = scene([body([0.0, 0.5])], gravity=[0.0, -9.81], walls=[GROUND], dt=1 / 64,
                 duration=2.0)
    truth = scenes.truth(case)
    assert truth.settle == (0.0,) and truth.jitter == 0.0 and truth.energy_drift == 0.0
    assert truth.divergence == 2.0
    assert isinstance(truth.apex, Undefined) and "never bounces" in truth.apex.reason
    assert isinstance(truth.bounce_time, Undefined)
    assert truth.trajectory is not None and len(truth.trajectory.times) == 129
    assert set(truth.trajectory.positions) == {((0.0, 0.5),)}


def test_a_dyadic_inelastic_drop_settles_on_the_ground_at_the_end_of_its_series() -> None:
    case = drop_case(restitution=0.5, duration=4.0, dt=1 / 64)
    truth = scenes.truth(case)
    assert truth.settle == (0.0,)
    assert truth.jitter == 0.0  # rests from 3/2 s, before the second half (2 s)
    assert truth.bounce_time == (0.5, 1.0, 1.25, 1.375, 1.4375)
    assert truth.apex == (0.25, 0.0625, 0.015625, 0.00390625, 0.0009765625)
    # at rest: -m g . (p - p0) = -8; the scale is m g x the centre's height 1.5 = 12
    assert truth.energy_drift == -8.0 / (12.0 * 4.0)
    assert truth.positions == ((0.0, 0.5),) and truth.velocities == ((0.0, 0.0),)


def test_jitter_needs_rest_over_the_whole_second_half() -> None:
    resting_late = scenes.truth(drop_case(restitution=0.5, duration=2.5, dt=1 / 64))
    assert resting_late.settle == (0.0,)  # rests at the end (from 3/2 s)...
    assert isinstance(resting_late.jitter, Undefined)  # ...but not since 5/4 s
    assert "second half" in resting_late.jitter.reason
    exactly_half = scenes.truth(drop_case(restitution=0.5, duration=3.0, dt=1 / 64))
    assert exactly_half.jitter == 0.0  # from 3/2 s of 3 s: the whole second half


def test_an_elastic_drop_has_apexes_and_bounces_but_no_settle() -> None:
    case = drop_case(restitution=1.0, duration=4.0, dt=1 / 64)
    truth = scenes.truth(case)
    assert isinstance(truth.settle, Undefined) and "rests" in truth.settle.reason
    assert isinstance(truth.jitter, Undefined)
    assert truth.bounce_time == (0.5, 1.5, 2.5, 3.5)
    assert truth.apex == (1.0,) * 4  # the last apex is at exactly 4 s, the end: kept
    assert truth.energy_drift == 0.0


def test_restitution_zero_rests_at_first_contact_exactly_on_the_ground() -> None:
    case = scene([body([0.0, 1.1], radius=0.1)], gravity=[0.0, -9.81], walls=[GROUND],
                 restitution=0.0, duration=1.0, dt=0.01)
    truth = scenes.truth(case)
    assert truth.settle == (0.0,)  # touching, not a rounding above or below it
    assert truth.jitter == 0.0  # rests from 0.45 s
    assert isinstance(truth.bounce_time, tuple) and len(truth.bounce_time) == 1
    assert truth.bounce_time[0] == pytest.approx(math.sqrt(2.0 / 9.81), rel=1e-15)
    assert truth.apex == (0.0,)  # it leaves at speed 0


def test_body_zero_must_bounce_for_apexes() -> None:
    """Body 1 bounces; body 0 starts higher and has not reached the ground by the end."""
    case = scene([body([0.0, 9.5]), body([3.0, 1.5])], gravity=[0.0, -8.0], walls=[GROUND],
                 duration=1.0, dt=1 / 64)
    truth = scenes.truth(case)
    assert truth.impacts == (0.5,)  # body 1 on the ground
    assert isinstance(truth.apex, Undefined) and "body 0 never bounces" in truth.apex.reason
    assert isinstance(truth.bounce_time, Undefined)
    assert isinstance(truth.settle, Undefined)


def test_open_space_measures_are_undefined_with_the_reason() -> None:
    case = scene([body([0.0, 0.0], velocity=(1.0, 0.0)), body([3.0, 0.0])], dt=1 / 64)
    truth = scenes.truth(case)
    for quantity in ("settle", "jitter", "apex", "bounce_time", "divergence"):
        value = truth.get(quantity)
        assert isinstance(value, Undefined) and value.reason == scenes.OPEN_SPACE, quantity
    assert truth.energy_drift == 0.0 and truth.trajectory is None


def test_walls_without_gravity_have_no_ground_and_keep_the_energy() -> None:
    case = scene([body([0.0, 1.5], velocity=(0.0, -1.0))], walls=[GROUND], duration=2.0,
                 dt=1 / 64)
    truth = scenes.truth(case)
    assert truth.impacts == (1.0,) and truth.positions == ((0.0, 1.5),)
    assert truth.velocities == ((0.0, 1.0),) and truth.energy_drift == 0.0
    assert isinstance(truth.settle, Undefined) and isinstance(truth.apex, Undefined)
    assert isinstance(truth.jitter, Undefined)
    assert truth.divergence == 2.0 and truth.trajectory is not None
    assert len(truth.trajectory.times) == 129


def test_a_scene_the_reference_cannot_run_has_every_measure_undefined() -> None:
    case = scene([body([0.0, 0.5]), body([3.0, 4.0])], gravity=[0.0, -9.81], walls=[GROUND],
                 dt=1 / 64)
    truth = scenes.truth(case)
    for quantity in ("positions", *sm.MEASURES):
        value = truth.get(quantity)
        assert isinstance(value, Undefined) and "one rests and one flies" in value.reason
