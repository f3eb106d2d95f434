"""Tests of the event-driven N-sphere reference simulator (reference_impl.events).

Closed forms (head-on, oblique 3-4-5, cradles), exact conservation, the tie
rule, determinism, and properties against a slow, independent Fraction
re-implementation of the documented semantics.
"""

from __future__ import annotations

import doctest
import itertools
import math
from collections.abc import Callable, Sequence
from decimal import Decimal, localcontext
from fractions import Fraction

import pytest
from hypothesis import assume, given, reject, settings
from hypothesis import strategies as st

from reference_impl import events, exact, rounding
from reference_impl.events import Ball, Event, SceneState, simulate
from reference_impl.types import Undefined

F = Fraction
FVec = tuple[Fraction, ...]


def x_ball(x: float, v: float, radius: float = 0.5, mass: float = 1.0, dim: int = 2) -> Ball:
    pad = (0.0,) * (dim - 1)
    return Ball((x, *pad), radius, mass, (v, *pad))


def dot(a: Sequence[Fraction], b: Sequence[Fraction]) -> Fraction:
    return sum((x * y for x, y in zip(a, b, strict=True)), F(0))


def sub(a: Sequence[Fraction], b: Sequence[Fraction]) -> FVec:
    return tuple(x - y for x, y in zip(a, b, strict=True))


def worst_overlap(state: SceneState, balls: Sequence[Ball]) -> float:
    """Largest ``1 - |pj - pi| / (ri + rj)`` over all pairs (< 0: no overlap).

    From the correctly rounded positions: off by ~1e-16, far below the tolerances.
    """
    p, n = state.positions_float(), len(balls)
    return max(1 - math.dist(p[i], p[j]) / (balls[i].radius + balls[j].radius)
               for i in range(n) for j in range(i + 1, n))


# ------------------------------------------------ an independent slow oracle


def naive_time(dp: FVec, dv: FVec, r: Fraction, now: Fraction) -> Fraction | None:
    """The documented impact time via ``(-b - sqrt(disc)) / a`` (another form)."""
    a, b, c = dot(dv, dv), dot(dp, dv), dot(dp, dp) - r * r
    if b >= 0:
        return None
    if c <= 0:
        return now
    disc = b * b - a * c
    if disc < 0:
        return None
    t = rounding.round_with_sqrt(disc, lambda lo, hi: (now + (-b - hi) / a, now + (-b - lo) / a))
    return max(now, F(t))


MAX_EVENTS = 200
"""Random scenes with e = 0 can collapse inelastically (endless events): such draws are
rejected by the guard instead of running until the default million events."""


def bounded(run: Callable[[], SceneState]) -> SceneState:
    """``run()``, or reject the hypothesis example if it hits the event guard."""
    try:
        return run()
    except RuntimeError:
        reject()
        raise  # unreachable: reject() raises


def naive(balls: Sequence[Ball], e: float, duration: float,
          max_events: int = MAX_EVENTS) -> SceneState:
    """O(N**2) per event, all Fractions, everything re-predicted at every step."""
    pos = [tuple(map(F, b.center)) for b in balls]
    vel = [tuple(map(F, b.velocity)) for b in balls]
    m, r, ee = [F(b.mass) for b in balls], [F(b.radius) for b in balls], F(e)
    now, end, log, count, dropped = F(0), F(duration), list[Event](), [0] * len(balls), set()
    while True:
        found = []
        for i in range(len(balls)):
            for j in range(i + 1, len(balls)):
                t = naive_time(sub(pos[j], pos[i]), sub(vel[j], vel[i]), r[i] + r[j], now)
                if t is not None and t <= end and (i, j, count[i], count[j]) not in dropped:
                    found.append((t, i, j))
        if not found:
            break
        t, i, j = min(found)
        if len(log) >= max_events:
            raise RuntimeError(f"more than {max_events} events")
        pos = [tuple(x + y * (t - now) for x, y in zip(p, v, strict=True))
               for p, v in zip(pos, vel, strict=True)]
        now = t
        d = tuple(F(float(x)) for x in sub(pos[i], pos[j]))
        k = dot(d, sub(vel[j], vel[i])) / dot(d, d)
        if k <= 0:
            dropped.add((i, j, count[i], count[j]))
            continue
        ci, cj = (1 + ee) * m[j] / (m[i] + m[j]) * k, (1 + ee) * m[i] / (m[i] + m[j]) * k
        vel[i] = tuple(v + ci * x for v, x in zip(vel[i], d, strict=True))
        vel[j] = tuple(v - cj * x for v, x in zip(vel[j], d, strict=True))
        log.append(Event(t, i, j))
        count[i] += 1
        count[j] += 1
    pos = [tuple(x + y * (end - now) for x, y in zip(p, v, strict=True))
           for p, v in zip(pos, vel, strict=True)]
    return SceneState(end, tuple(pos), tuple(vel), tuple(m), tuple(log))


# ----------------------------------------------------------------- doctests


def test_doctests() -> None:
    result = doctest.testmod(events)
    assert result.failed == 0
    assert result.attempted >= 10


# ------------------------------------------------------------- closed forms


@pytest.fixture(params=["interval", "exact"])
def path(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Decide predictions by the interval path, or by exact ``impact_time`` only."""
    if request.param == "exact":
        monkeypatch.setattr(events, "_PRECISIONS", ())
    return str(request.param)



@pytest.mark.usefixtures("path")
def test_head_on_equal_masses_exchange_velocities() -> None:
    state = simulate([x_ball(-2.0, 1.0), x_ball(2.0, -1.0)], 1.0, 3.0)
    assert state.events == (Event(F(3, 2), 0, 1),)
    assert state.velocities == ((F(-1), F(0)), (F(1), F(0)))
    assert state.positions == ((F(-2), F(0)), (F(2), F(0)))
    assert state.time == 3


@pytest.mark.usefixtures("path")
@pytest.mark.parametrize("dim", [2, 3])
def test_head_on_unequal_masses_with_restitution(dim: int) -> None:
    m1, m2, v1, v2, e = 1.0, 3.0, 2.0, -1.0, 0.5
    state = simulate([x_ball(-3.0, v1, mass=m1, dim=dim), x_ball(3.0, v2, mass=m2, dim=dim)],
                     e, 4.0)
    (event,) = state.events
    assert event.time == F(float(F(5, 3)))  # gap 5 closing at 3, correctly rounded
    m1q, m2q, v1q, v2q, eq = map(F, (m1, m2, v1, v2, e))
    w1 = (m1q * v1q + m2q * v2q + m2q * eq * (v2q - v1q)) / (m1q + m2q)
    w2 = (m1q * v1q + m2q * v2q + m1q * eq * (v1q - v2q)) / (m1q + m2q)
    pad = (F(0),) * (dim - 1)
    assert state.velocities == ((w1, *pad), (w2, *pad))
    t = event.time
    assert state.positions[0] == (-3 + v1q * t + w1 * (4 - t), *pad)
    assert state.positions[1] == (3 + v2q * t + w2 * (4 - t), *pad)


@pytest.mark.usefixtures("path")
def test_oblique_345_elastic() -> None:
    # At t = 1, A is at (0, 0) and B at (3, 4): the line of centres is (3, 4)/5.
    a, b = Ball((-1.0, 0.0), 2.5, 1.0, (1.0, 0.0)), Ball((3.0, 4.0), 2.5, 1.0, (0.0, 0.0))
    state = simulate([a, b], 1.0, 2.0)
    assert state.events == (Event(F(1), 0, 1),)
    va, vb = state.velocities
    assert va == (F(16, 25), F(-12, 25)) and vb == (F(9, 25), F(12, 25))
    tangent = (F(4, 5), F(-3, 5))
    assert dot(va, tangent) == dot((F(1), F(0)), tangent) == F(4, 5)  # unchanged
    assert dot(vb, tangent) == 0
    assert state.positions == ((F(16, 25), F(-12, 25)), (3 + F(9, 25), 4 + F(12, 25)))


@pytest.mark.usefixtures("path")
def test_oblique_unequal_masses_match_sphere_response() -> None:
    a = Ball((-1.0, 0.0), 2.5, 1.5, (1.0, 0.25))
    b = Ball((3.0, 4.0), 2.5, 0.75, (0.0, 0.25))  # same vy: impact at (0, 0.25), (3, 4.25)
    state = simulate([a, b], 0.25, 1.0)
    assert state.events == (Event(F(1), 0, 1),)
    expected = exact.sphere_response((0.0, 0.25), 1.5, (1.0, 0.25), (3.0, 4.25), 0.75,
                                     (0.0, 0.25), 0.25)
    assert not isinstance(expected, Undefined)
    assert state.velocities == (expected.v1, expected.v2)


@pytest.mark.usefixtures("path")
def test_irrational_impact_time_is_correctly_rounded() -> None:
    # A moves along x at speed 1 towards B offset by y: t = 3 - sqrt(1 - y**2).
    y = 0.7
    state = simulate([Ball((0.0, 0.0), 0.5, 1.0, (1.0, 0.0)),
                      Ball((3.0, y), 0.5, 1.0, (0.0, 0.0))], 1.0, 3.0)
    with localcontext() as ctx:
        ctx.prec = 80
        yd = Decimal(y)
        closed = Decimal(3) - (Decimal(1) - yd * yd).sqrt()
    assert state.events[0].time == F(float(closed))
    assert F(float(closed)) != 3 - F(math.sqrt(1 - y * y))  # the float formula is off


def test_impact_time_rational_roots_round_to_nearest_even() -> None:
    # Head-on at distance x with R = 1 and closing speed 1: t = x - 1, sqrt(disc) = 1.
    one, zero = F(1), F(0)
    assert events.impact_time((F(4, 3), zero), (-one, zero), one, zero) == F(float(F(1, 3)))
    tie = 1 + F(1, 2**53)  # halfway between 1 and the next double: to even
    assert events.impact_time((1 + tie, zero), (-one, zero), one, zero) == 1
    tie = 1 + F(3, 2**53)  # halfway between 1 + 2**-52 and 1 + 2**-51: to even
    assert events.impact_time((1 + tie, zero), (-one, zero), one, zero) == 1 + F(1, 2**51)
    assert events.impact_time((F(2), zero), (-one, zero), one, F(7)) == 8


def test_decide_certifies_only_unambiguous_roundings() -> None:
    now = F(0)
    # a = 0: t = c / (-2 b), here in [1, 1 + 2**-61] (rounds to 1) or [1, 1 + 2**-52] (ambiguous)
    assert events.decide((0, 0), (-(2**60), -(2**60)), (2**61, 2**61 + 1), now) == (True, F(1))
    assert events.decide((0, 0), (-(2**60), -(2**60)), (2**61, 2**61 + 2**9), now) == (False, None)
    assert events.decide((1, 1), (-3, -3), (9, 9), now) == (True, F(3))  # tangent: disc == 0
    assert events.decide((1, 2), (-1, -1), (5, 6), now) == (True, None)  # f_lo has no root
    assert events.decide((1, 1), (0, 0), (-1, -1), now) == (True, None)  # b == 0
    assert events.decide((1, 1), (-1, 0), (-1, -1), now) == (False, None)  # sign of b unknown
    assert events.decide((1, 1), (-1, -1), (-1, 0), now) == (True, now)  # touching, approaching
    assert events.decide((1, 1), (-1, -1), (-1, 1), now) == (False, None)  # touching unknown


def test_exact_graze_is_predicted_then_dropped() -> None:
    # Tangent at t = 3 (b**2 == a c): the pair touches with zero normal velocity.
    balls = [Ball((0.0, 0.0), 0.5, 1.0, (1.0, 0.0)), Ball((3.0, 1.0), 0.5, 1.0, (0.0, 0.0))]
    assert events._Scene(balls, F(1)).heap[0][:3] == (3.0, 0, 1)
    state = simulate(balls, 1.0, 5.0)
    assert state.events == ()
    assert state.velocities == events.initial_state(balls).velocities


def test_separating_pair_gets_no_response() -> None:
    scene = events._Scene([x_ball(0.0, -1.0), x_ball(1.0, 1.0)], F(1))
    assert not scene.respond(0, 1)
    assert scene.state(F(0)).velocities == ((F(-1), F(0)), (F(1), F(0)))
    scene = events._Scene([x_ball(0.0, 1.0), x_ball(3.0, 0.0)], F(1))
    assert scene.respond(0, 1)  # the response itself does not look at the gap
    assert scene.state(F(0)).velocities == ((F(0), F(0)), (F(1), F(0)))


def test_event_exactly_at_duration_is_handled() -> None:
    balls = [x_ball(-2.0, 1.0), x_ball(2.0, -1.0)]
    assert len(simulate(balls, 1.0, 1.5).events) == 1
    assert simulate(balls, 1.0, math.nextafter(1.5, 0)).events == ()
    assert simulate(balls, 1.0, F(3, 2)).events == simulate(balls, 1.0, 1.5).events


def test_zero_normal_velocity_is_no_collision() -> None:
    sliding = [Ball((0.0, 0.0), 0.5, 1.0, (0.0, 1.0)), Ball((1.0, 0.0), 0.5, 1.0, (0.0, 0.0))]
    parallel = [x_ball(0.0, 1.0), x_ball(1.0, 1.0)]
    for balls in (sliding, parallel):
        state = simulate(balls, 1.0, 2.0)
        assert state.events == ()
        assert state.velocities == events.initial_state(balls).velocities


# ------------------------------------------------------------------ cradles


@pytest.mark.usefixtures("path")
def test_three_separated_balls_pass_the_momentum() -> None:
    state = simulate([x_ball(0.0, 1.0), x_ball(2.0, 0.0), x_ball(4.0, 0.0)], 1.0, 3.0)
    assert state.events == (Event(F(1), 0, 1), Event(F(2), 1, 2))
    assert [p[0] for p in state.positions] == [1, 3, 5]
    assert [v[0] for v in state.velocities] == [0, 0, 1]


@pytest.mark.usefixtures("path")
@pytest.mark.parametrize("dim", [2, 3])
def test_touching_cradle_uses_the_simultaneous_rule(dim: int) -> None:
    state = simulate(events.cradle(5, 0.5, 1.0, dim), 1.0, 2.0)
    assert state.events == tuple(Event(F(0), k, k + 1) for k in range(4))
    assert [p[0] for p in state.positions] == [0, 1, 2, 3, 6]
    assert [v[0] for v in state.velocities] == [0, 0, 0, 0, 1]


@pytest.mark.usefixtures("path")
def test_simultaneous_independent_pairs_run_in_lexicographic_order() -> None:
    far = [Ball((-2.0, 10.0), 0.5, 1.0, (1.0, 0.0)), Ball((2.0, 10.0), 0.5, 1.0, (-1.0, 0.0))]
    near = [Ball((-2.0, 0.0), 0.5, 1.0, (1.0, 0.0)), Ball((2.0, 0.0), 0.5, 1.0, (-1.0, 0.0))]
    state = simulate([near[0], far[0], far[1], near[1]], 1.0, 2.0)
    assert state.events == (Event(F(3, 2), 0, 3), Event(F(3, 2), 1, 2))


def test_inelastic_collapse_hits_the_guard() -> None:
    balls = [x_ball(0.0, 1.0), x_ball(2.0, 0.0), x_ball(4.0, -1.0)]
    with pytest.raises(RuntimeError, match="more than 500 events"):
        simulate(balls, 0.05, 2.0, max_events=500)
    with pytest.raises(RuntimeError):
        simulate(events.cradle(5, 0.5, 1.0), 1.0, 1.0, max_events=3)
    assert len(simulate(events.cradle(5, 0.5, 1.0), 1.0, 1.0, max_events=4).events) == 4


def test_billiards_break() -> None:
    rack = events.billiards()
    state = simulate(rack, 1.0, 3.0)
    assert state.events[0] == Event(F(1, 2), 0, 1)
    # The apex reaches the two balls of row 1 together (mirror images in y).
    assert state.events[1].time == state.events[2].time
    assert [(e.i, e.j) for e in state.events[1:3]] == [(1, 2), (1, 3)]
    assert state.momentum() == events.momentum(rack) == (F(2), F(0))
    assert state.kinetic_energy() == events.kinetic_energy(rack)
    assert worst_overlap(state, rack) < 1e-12
    assert worst_overlap(events.initial_state(rack), rack) < -4e-4  # the rack's gap


# ------------------------------------------------------------- conservation

CLUSTER = {"n": 30, "seed": 7, "dim": 2, "extent": 2.5, "radius": (0.2, 0.4), "speed": 2.0}


def test_elastic_cluster_conserves_momentum_and_energy_exactly(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # The work is counted, not timed: an event re-predicts only its two balls' pairs (2N - 3
    # predictions, not N^2 / 2), and interval arithmetic decides every prediction here, so
    # the exact Fraction fallback (impact_time) never runs.
    predictions, exact_fallbacks = [0], [0]
    predict, impact_time = events._Scene.predict, events.impact_time

    def counted_predict(scene: events._Scene, i: int, j: int) -> None:
        predictions[0] += 1
        predict(scene, i, j)

    def counted_impact_time(*args: object) -> Fraction | None:
        exact_fallbacks[0] += 1
        return impact_time(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(events._Scene, "predict", counted_predict)
    monkeypatch.setattr(events, "impact_time", counted_impact_time)
    balls = events.cluster(**CLUSTER)  # type: ignore[arg-type]
    state = simulate(balls, 1.0, 2.0)
    n, count = len(balls), len(state.events)
    assert count >= 100
    assert predictions[0] == n * (n - 1) // 2 + count * (2 * n - 3)
    assert exact_fallbacks[0] == 0
    assert state.momentum() == events.momentum(balls)
    assert state.kinetic_energy() == events.kinetic_energy(balls)
    assert worst_overlap(state, balls) < 1e-12


def test_inelastic_cluster_loses_energy_keeps_momentum() -> None:
    balls = events.cluster(20, seed=3, dim=3, extent=1.5, radius=(0.2, 0.4), speed=2.0)
    state = simulate(balls, 0.5, 2.0)
    assert len(state.events) >= 10
    assert state.momentum() == events.momentum(balls)
    assert state.kinetic_energy() < events.kinetic_energy(balls)


def test_determinism_and_permutation() -> None:
    balls = events.cluster(**CLUSTER)  # type: ignore[arg-type]
    first = simulate(balls, 1.0, 1.5)
    assert simulate(list(balls), 1.0, 1.5) == first
    swap = {0: 5, 5: 0}
    perm = [swap.get(k, k) for k in range(len(balls))]
    swapped = simulate([balls[k] for k in perm], 1.0, 1.5)
    assert swapped.positions == tuple(first.positions[k] for k in perm)
    assert swapped.velocities == tuple(first.velocities[k] for k in perm)
    renamed = [(e.time, *sorted((perm[e.i], perm[e.j]))) for e in first.events]
    assert [(e.time, e.i, e.j) for e in swapped.events] == renamed


@pytest.mark.parametrize("dim", [2, 3])
def test_small_cluster_matches_the_naive_oracle(dim: int) -> None:
    balls = events.cluster(10, seed=2, dim=dim, extent=1.4 if dim == 2 else 1.0,
                           radius=(0.2, 0.4), speed=2.0)
    state = simulate(balls, 0.9, 2.0)
    assert len(state.events) >= 10
    assert state == naive(balls, 0.9, 2.0)


def test_exact_fallback_agrees_with_the_interval_path(monkeypatch: pytest.MonkeyPatch) -> None:
    balls = events.cluster(12, seed=5, dim=2, extent=1.5, radius=(0.2, 0.4), speed=2.0)
    fast = simulate(balls, 0.75, 1.5)
    monkeypatch.setattr(events, "_PRECISIONS", ())
    assert simulate(balls, 0.75, 1.5) == fast
    assert len(fast.events) >= 5


def test_float_views_are_correctly_rounded() -> None:
    state = simulate([Ball((0.1, 0.0), 0.5, 1.0, (0.1, 0.0))], 1.0, 0.1)
    assert state.positions[0][0] == F(0.1) + F(0.1) * F(0.1)
    assert state.positions_float() == ((0.11, 0.0),)
    assert 0.1 + 0.1 * 0.1 == 0.11000000000000001  # float arithmetic rounds twice
    assert state.velocities_float() == ((0.1, 0.0),)


# --------------------------------------------------------------- generators


def test_generators() -> None:
    balls = events.cluster(**CLUSTER)  # type: ignore[arg-type]
    assert balls == events.cluster(**CLUSTER)  # type: ignore[arg-type]
    assert worst_overlap(events.initial_state(balls), balls) < 0
    assert all(b.mass == b.radius**2 and 0.2 <= b.radius <= 0.4 for b in balls)
    assert all(dot(tuple(map(F, b.center)), tuple(map(F, b.velocity))) < 0 for b in balls[:3])
    row = events.cradle(4, 0.25, 2.0, dim=3)
    assert [b.center for b in row] == [(k * 0.5, 0.0, 0.0) for k in range(4)]
    assert [b.velocity[0] for b in row] == [2.0, 0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match="not a double"):
        events.cradle(4, 0.3, 1.0)
    assert len(events.billiards(3)) == 16
    assert all(len(b.center) == 3 for b in events.billiards(3))


def test_invalid_input() -> None:
    with pytest.raises(ValueError, match="2-D or all 3-D"):
        simulate([x_ball(0.0, 1.0), x_ball(3.0, 0.0, dim=3)], 1.0, 1.0)
    with pytest.raises(ValueError, match="radius > 0"):
        simulate([x_ball(0.0, 1.0, radius=-1.0)], 1.0, 1.0)
    with pytest.raises(ValueError, match="restitution"):
        simulate([x_ball(0.0, 1.0)], -0.5, 1.0)
    with pytest.raises(ValueError, match="duration"):
        simulate([x_ball(0.0, 1.0)], 1.0, math.inf)


# --------------------------------------------------------------- properties

coord = st.floats(-2.5, 2.5, allow_nan=False)
speed = st.floats(-2, 2, allow_nan=False)


@st.composite
def scenes(draw: st.DrawFn) -> list[Ball]:
    dim, n = draw(st.sampled_from([2, 3])), draw(st.integers(2, 4))
    return [
        Ball(tuple(draw(coord) for _ in range(dim)), draw(st.floats(0.1, 1.0)),
             draw(st.floats(0.25, 4.0)), tuple(draw(speed) for _ in range(dim)))
        for _ in range(n)
    ]


@settings(max_examples=120, deadline=None)
@given(scenes(), st.sampled_from([1.0, 0.5, 0.0]))
def test_small_scenes_no_overlap_exact_momentum(balls: list[Ball], e: float) -> None:
    assume(worst_overlap(events.initial_state(balls), balls) < 0)
    state = bounded(lambda: simulate(balls, e, 5.0, max_events=MAX_EVENTS))
    assert worst_overlap(state, balls) <= 1e-12
    assert state.momentum() == events.momentum(balls)
    if e == 1.0:
        assert state.kinetic_energy() == events.kinetic_energy(balls)
    assert all(a.time <= b.time for a, b in itertools.pairwise(state.events))


@settings(max_examples=80, deadline=None)
@given(scenes(), st.sampled_from([1.0, 0.75, 0.0]))
def test_small_scenes_match_the_naive_oracle(balls: list[Ball], e: float) -> None:
    fast = bounded(lambda: simulate(balls, e, 4.0, max_events=MAX_EVENTS))
    assert fast == naive(balls, e, 4.0)


grid = st.integers(-64, 64).map(lambda k: k / 32)


@settings(max_examples=100, deadline=None)
@given(st.lists(grid, min_size=4, max_size=4), st.lists(speed, min_size=4, max_size=4),
       st.floats(0.25, 4.0), st.floats(0.25, 4.0), st.floats(0, 1))
def test_contact_response_equals_sphere_response(
    p: list[float], v: list[float], ma: float, mb: float, e: float
) -> None:
    # Centres on a 1/32 grid: pa - pb is exact, so the rounded line of centres is exact.
    pa, pb, va, vb = (p[0], p[1]), (p[2], p[3]), (v[0], v[1]), (v[2], v[3])
    assume(pa != pb)
    state = simulate([Ball(pa, 3.0, ma, va), Ball(pb, 3.0, mb, vb)], e, 0.0)
    response = exact.sphere_response(pa, ma, va, pb, mb, vb, e)
    assert not isinstance(response, Undefined)
    approaching = dot(sub(tuple(map(F, pb)), tuple(map(F, pa))),
                      sub(tuple(map(F, vb)), tuple(map(F, va)))) < 0
    assert len(state.events) == approaching
    expected = (response.v1, response.v2) if approaching else (
        tuple(map(F, va)), tuple(map(F, vb)))
    assert state.velocities == expected
