"""The event-driven reference under uniform gravity between static walls
(:mod:`reference_impl.gravity`) against closed forms.

A drop from a gap ``h`` under gravity ``g`` falls for ``tau = sqrt(2 h / g)`` and meets the
ground at speed ``u = sqrt(2 g h)``.  Elastic (``e = 1``): bounce ``k`` is at
``(2k + 1) tau`` and every apex is ``h``.  Inelastic: bounce ``k`` leaves at ``u e**(k+1)``,
reaches the apex ``h e**(2(k+1))``, the flights last ``2 u e**j / g`` and the series ends at
``t_rest = tau + 2 u e / (g (1 - e))``, after which the body rests exactly on the ground.

Two kinds of scene: dyadic ones (``g = 8``, ``h = 1``, ``e = 1/2``: every event time is a
double, so the reference must match the closed form exactly) and ones with ``g = 9.81``,
where each event time is rounded to the nearest double and the bounds below are derived
from how one rounding carries over to the later events.  The closed forms are evaluated
with :mod:`decimal` at 60 digits, independently of the reference's own rounding.
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext
from fractions import Fraction

import pytest

from reference_impl import gravity
from reference_impl.events import Ball, Wall
from reference_impl.gravity import SETTLE, simulate

F = Fraction
GROUND_2D = Wall((0.0, 1.0), 0.0)
GROUND_3D = Wall((0.0, 0.0, 1.0), 0.0)


def dec(x: Fraction | float) -> Decimal:
    """The exact value of a double, or a rational to 60 digits."""
    if isinstance(x, float):
        return Decimal(x)
    return Decimal(x.numerator) / Decimal(x.denominator)


def ulp(x: float) -> Decimal:
    return Decimal(math.ulp(x))


def drop(top: float, radius: float, dim: int = 2) -> Ball:
    """A unit-mass sphere at rest with its centre at height ``top``."""
    pad = (0.0,) * (dim - 1)
    return Ball((*pad, top), radius, 1.0, (0.0,) * dim)


def height(p: tuple[Fraction, ...], radius: float) -> Fraction:
    """The exact gap to a ground at 0 (the last axis is up)."""
    return p[-1] - F(radius)


# ------------------------------------------------------------------ elastic drops


@pytest.mark.parametrize(("g", "top", "radius", "duration"), [
    (8.0, 1.5, 0.5, 20.0),   # dyadic: tau = 1/2, every bounce time exact
    (9.81, 1.1, 0.1, 10.0),  # the drop: tau irrational, event times rounded
], ids=["dyadic", "g9.81"])
def test_an_elastic_drop_bounces_at_odd_multiples_of_the_fall_time(
        g: float, top: float, radius: float, duration: float) -> None:
    run = simulate([drop(top, radius)], [GROUND_2D], (0.0, -g), 1.0, duration)
    h = F(top) - F(radius)  # the exact gap (1.1 - 0.1 is not exactly 1 in doubles)
    with localcontext() as ctx:
        ctx.prec = 60
        tau = (2 * dec(h) / dec(g)).sqrt()
        count = int((dec(duration) / tau + 1) / 2)  # bounces with (2k + 1) tau <= duration
        assert len(run.bounces) == count >= 10
        for k, (t, body, wall, u) in enumerate(run.bounces):
            assert (body, wall) == (0, 0)
            # Bounce k is rounded to the nearest double (half an ulp), and an earlier rounding
            # by d moves every later bounce by 2 d (the flight after a bounce is the mirror
            # image of the one before it about the rounded time; the apex height, set by the
            # exactly conserved energy, does not change): |t_k - (2k + 1) tau| <=
            # ulp(t_k) / 2 + sum_{j<k} ulp(t_j) <= (k + 1/2) ulp(t_k).  Dyadic: exact.
            error = abs(dec(t) - (2 * k + 1) * tau)
            assert error <= (k + Decimal("0.5")) * ulp(float(t)), (k, error)
            if g == 8.0:
                assert t == F(2 * k + 1, 2)
            # The apex from the outgoing speed, u**2 / 2g, is h minus the gap at the rounded
            # bounce time, which is at most u times half an ulp of the time.
            apex = dec(u * u / (2 * F(g)))
            assert abs(apex - dec(h)) <= dec(u) * ulp(float(t)) / 2, (k, apex)


def test_every_elastic_apex_is_exactly_the_drop_height() -> None:
    """Energy is exact at e = 1, so at any time in flight the apex the state will reach,
    gap + v**2 / 2g, is exactly the starting gap (no rounding, g = 9.81)."""
    g, top, radius = 9.81, 1.1, 0.1
    tau = math.sqrt(2 * (top - radius) / g)
    times = [F(2 * k * tau) for k in range(1, 11)]  # near every apex
    run = simulate([drop(top, radius)], [GROUND_2D], (0.0, -g), 1.0, 21 * tau, times)
    h = F(top) - F(radius)
    for sample in run.samples:
        p, v = sample.positions[0], sample.velocities[0]
        assert height(p, radius) + v[1] ** 2 / (2 * F(g)) == h
        assert abs(float(height(p, radius)) - float(h)) < 1e-9  # and it is near the apex
    start = [(0.0, top)]
    assert gravity.energy(run.state, (0.0, -g), start) == 0  # the initial energy, exactly


# ------------------------------------------------------------------ inelastic drops


def test_a_dyadic_inelastic_drop_follows_the_geometric_series_exactly() -> None:
    """g = 8, h = 1, e = 1/2: tau = 1/2, u = 4, the flights last 2^-j and every bounce time
    t_k = 3/2 - 2^-k is a double; the series rests at exactly t_rest = 1/2 + 1 = 3/2."""
    e = F(1, 2)
    run = simulate([drop(1.5, 0.5)], [GROUND_2D], (0.0, -8.0), float(e), 3.0)
    u, g = F(4), F(8)
    rest = F(1, 2) + 2 * u * e / (g * (1 - e))
    assert rest == F(3, 2)
    # simulated one by one while a flight lasts MIN_FLIGHT = 2^-30 s or more: bounces 0..30
    assert len(run.bounces) == 31
    for k, (t, _, _, out) in enumerate(run.bounces):
        assert t == F(1, 2) + sum((2 * u * e**j / g for j in range(1, k + 1)), F(0))
        assert out == u * e ** (k + 1)
        assert out * out / (2 * g) == e ** (2 * (k + 1))  # apex k + 1 = h e^(2(k+1)), h = 1
    settle = run.state.events[-1]
    assert (settle.time, settle.i, settle.j) == (rest, 0, SETTLE)
    assert run.rest_since == rest and run.resting == (True,)
    assert run.state.positions[0] == (F(0), F(1, 2)) and run.state.velocities[0] == (F(0), F(0))


def series_bound(times: list[Fraction], e: float, upto: int) -> Decimal:
    """How far bounce ``upto`` (or the settle time, ``upto = len(times)``) may be from the
    closed form when every event time is rounded to the nearest double.

    A bounce rounded by ``d`` (|d| <= ulp / 2) happens at gap ``-w d`` (w the speed): later
    events move by ``d`` (the shift itself), ``-d / e`` (the next flight starts from that
    gap) and ``-2 d / (1 - e)`` (the speed leaves ``g d / e`` lower, and the remaining
    flights, ``2 e w / g`` each with w shrinking by e, sum that to ``2 d / (1 - e)``).  To
    first order (the next term is d**2 g / w, below 1e-22 s here) each rounding moves the
    result by at most ``(1 + 1/e + 2/(1 - e)) ulp / 2``, plus the result's own rounding; the
    factor 2 covers the first-order approximation.
    """
    gain = Decimal(1 + 1 / e + 2 / (1 - e))
    spread = sum((ulp(float(t)) / 2 for t in times[:upto]), Decimal(0))
    last = times[min(upto, len(times) - 1)]
    return 2 * (gain * spread + ulp(float(last)))


def apex_bound(times: list[Fraction], e: float, upto: int, u: Decimal) -> Decimal:
    """How far, relatively, the apex after bounce ``upto`` (its outgoing speed squared over
    2g) may be from ``h e**(2(upto + 1))`` when every event time is rounded.

    A bounce rounded by ``d`` meets the ground at a speed ``g d`` off, and leaves the next
    one ``g d / e`` off (it starts from the gap ``-w d``); the ``e`` of every later bounce
    scales that error down with the speed.  So the speed at bounce k is off by at most
    ``g (1 + 1/e) sum_j e**(k-j) |d_j|`` against ``u e**k``, and the apex (a square) by
    twice that relatively; the factor 2 covers the first-order approximation.
    """
    g, E = Decimal(9.81), Decimal(e)  # noqa: RUF032 (the double, exactly)
    spread = sum((ulp(float(t)) / 2 / E**j for j, t in enumerate(times[:upto + 1])),
                 Decimal(0))
    return 2 * 2 * g * (1 + 1 / E) * spread / u


@pytest.mark.parametrize("e", [0.5, 0.8])
def test_an_inelastic_drop_with_rounded_times_follows_the_series_and_rests_at_its_sum(
        e: float) -> None:
    g, top, radius = 9.81, 1.1, 0.1
    run = simulate([drop(top, radius)], [GROUND_2D], (0.0, -g), e, 5.0)
    times = [t for t, _, _, _ in run.bounces]
    with localcontext() as ctx:
        ctx.prec = 60
        h = dec(F(top) - F(radius))
        tau, u, E, G = (2 * h / dec(g)).sqrt(), (2 * dec(g) * h).sqrt(), dec(e), dec(g)
        for k, (t, _, _, out) in enumerate(run.bounces[:12]):
            closed = tau + sum((2 * u * E**j / G for j in range(1, k + 1)), Decimal(0))
            assert abs(dec(t) - closed) <= series_bound(times, e, k), (k, dec(t) - closed)
            apex = dec(out * out / (2 * F(g)))
            assert abs(apex / (h * E ** (2 * (k + 1))) - 1) <= apex_bound(times, e, k, u), k
        rest = tau + 2 * u * E / (G * (1 - E))
        settle = run.state.events[-1]
        assert (settle.i, settle.j) == (0, SETTLE)
        assert abs(dec(settle.time) - rest) <= series_bound(times, e, len(times))
        assert float(settle.time) == pytest.approx(float(rest), rel=1e-13)
    # the series is summed once a flight would be shorter than MIN_FLIGHT
    last = run.bounces[-1][3]
    assert 2 * last / F(g) < gravity.MIN_FLIGHT <= 2 * run.bounces[-2][3] / F(g)
    assert run.rest_since == settle.time and run.resting == (True,)
    # at rest on the ground: gap exactly 0, velocity exactly 0
    assert height(run.state.positions[0], radius) == 0
    assert run.state.velocities[0] == (F(0), F(0))


def test_restitution_zero_rests_at_the_first_contact() -> None:
    g, top, radius = 9.81, 1.1, 0.1
    run = simulate([drop(top, radius)], [GROUND_2D], (0.0, -g), 0.0, 2.0)
    h = F(top) - F(radius)
    with localcontext() as ctx:
        ctx.prec = 60
        tau = (2 * dec(h) / dec(g)).sqrt()
    (event,) = run.state.events
    assert (event.i, event.j) == (0, 1)  # the ground, wall 0 = sphere index N + 0
    assert event.time == F(float(tau))  # the correctly rounded first contact
    assert run.rest_since == event.time and run.resting == (True,)
    assert height(run.state.positions[0], radius) == 0 and run.state.velocities[0] == (F(0), F(0))


def test_a_series_settles_on_the_wall_it_bounced_on() -> None:
    """Two grounds facing gravity (y >= -1, listed first, and y >= 1/2): the body can only
    touch the upper one, and its bounce series must end resting on that one."""
    walls = [Wall((0.0, 1.0), -1.0), Wall((0.0, 1.0), 0.5)]
    run = simulate([drop(2.0, 0.5)], walls, (0.0, -8.0), 0.5, 3.0)  # gap 1 above y = 1/2
    assert {w for _, _, w, _ in run.bounces} == {1}
    assert run.state.events[-1].time == F(3, 2) and run.resting == (True,)
    assert run.state.positions[0] == (F(0), F(1))  # the centre r = 1/2 above y = 1/2


# ------------------------------------------------------------------ resting contact


@pytest.mark.parametrize("duration", [0.0, 1e-9, 10.0, 1e6])
@pytest.mark.parametrize("dim", [2, 3])
def test_a_sphere_starting_on_the_ground_stays_exactly_there(duration: float, dim: int) -> None:
    ball, wall = drop(0.1, 0.1, dim), GROUND_2D if dim == 2 else GROUND_3D
    g = (*(0.0,) * (dim - 1), -9.81)
    run = simulate([ball], [wall], g, 1.0, duration, [F(duration) / 2])
    for state in (run.state, *run.samples):
        assert state.positions_float() == (ball.center,)
        assert state.velocities == (tuple(F(0) for _ in range(dim)),)
    assert run.state.events == () and run.bounces == ()
    assert run.resting == (True,) and run.rest_since == 0


def test_a_column_of_dyadic_spheres_stays() -> None:
    column = [drop(0.125 + 0.25 * k, 0.125, 3) for k in range(4)]
    run = simulate(column, [GROUND_3D], (0.0, 0.0, -9.81), 0.5, 10.0)
    assert [p for p in run.state.positions] == [tuple(map(F, b.center)) for b in column]
    assert all(v == (F(0),) * 3 for v in run.state.velocities)
    assert run.state.events == () and run.resting == (True,) * 4 and run.rest_since == 0


def test_a_ball_thrown_sideways_in_a_box_keeps_its_exact_energy() -> None:
    box = [Wall((0.0, 1.0), 0.0), Wall((1.0, 0.0), -2.0), Wall((-1.0, 0.0), -2.0),
           Wall((0.0, -1.0), -4.0)]
    ball = Ball((0.0, 1.0), 0.25, 2.0, (3.0, 1.5))
    g = (0.0, -9.81)
    run = simulate([ball], box, g, 1.0, 10.0)
    walls_hit = {e.j - 1 for e in run.state.events}
    assert {0, 1, 2} <= walls_hit and len(run.state.events) >= 20
    initial = F(ball.mass) * (F(3.0) ** 2 + F(1.5) ** 2) / 2
    assert gravity.energy(run.state, g, [ball.center]) == initial
    # the apex the state will reach (gap + v_y**2 / 2g) is the initial one, exactly
    p, v = run.state.positions[0], run.state.velocities[0]
    assert p[1] - F(0.25) + v[1] ** 2 / (2 * F(9.81)) == F(0.75) + F(1.5) ** 2 / (2 * F(9.81))
    assert abs(v[0]) == 3  # the side walls reverse v_x, and gravity does not touch it


def test_a_ceiling_with_gravity_up_is_a_ground() -> None:
    ceiling = Wall((0.0, -1.0), -2.0)  # solid above y = 2
    ball = Ball((0.0, 0.5), 0.5, 1.0, (0.0, 0.0))  # gap 1 below the ceiling
    bounced = simulate([ball], [ceiling], (0.0, 8.0), 1.0, 1.0)
    assert [(e.time, e.j) for e in bounced.state.events] == [(F(1, 2), 1)]  # 4 t**2 = 1
    assert bounced.state.positions[0] == (F(0), F(1, 2))
    assert bounced.state.velocities[0] == (F(0), F(0))
    assert bounced.bounces == ((F(1, 2), 0, 0, F(4)),)
    settled = simulate([ball], [ceiling], (0.0, 8.0), 0.5, 3.0)
    assert settled.state.events[-1].time == F(3, 2) and settled.resting == (True,)
    assert settled.state.positions[0] == (F(0), F(3, 2))  # touching the ceiling exactly
    resting = simulate([Ball((1.0, 1.5), 0.5, 1.0, (0.0, 0.0))], [ceiling], (0.0, 8.0), 1.0,
                       5.0)
    assert resting.resting == (True,) and resting.state.events == ()
    assert resting.state.positions[0] == (F(1), F(3, 2))


# ------------------------------------------------------------------ refused


def test_a_resting_and_a_flying_sphere_under_gravity_are_refused_naming_them() -> None:
    resting, flying = drop(0.5, 0.5), Ball((3.0, 4.0), 0.5, 1.0, (0.0, 0.0))
    with pytest.raises(ValueError, match=r"spheres 0 and 1: one rests and one flies"):
        simulate([resting, flying], [GROUND_2D], (0.0, -9.81), 1.0, 1.0)


@pytest.mark.parametrize("top", [0.25, 0.5 - 2**-40, -3.0])
def test_a_ball_starting_inside_a_wall_is_refused(top: float) -> None:
    with pytest.raises(ValueError, match="ball 0 starts inside wall 0"):
        simulate([drop(top, 0.5)], [GROUND_2D], (0.0, -9.81), 1.0, 1.0)


@pytest.mark.parametrize("e", [1.0 + 2**-52, 2.0, -0.5, math.nan])
def test_a_restitution_outside_zero_to_one_is_refused(e: float) -> None:
    with pytest.raises(ValueError, match="restitution must be in"):
        simulate([drop(2.0, 0.5)], [GROUND_2D], (0.0, -9.81), e, 1.0)


@pytest.mark.parametrize(("walls", "g", "words"), [
    ([Wall((0.0, 0.5), 0.0)], (0.0, -9.81), "wall 0: the normal must be a unit axis vector"),
    ([Wall((0.6, 0.8), 0.0)], (0.0, -9.81), "wall 0: the normal must be a unit axis vector"),
    ([GROUND_2D], (0.0, -9.81, 0.0), "wall 0: the normal must be a unit axis vector"),
    ([GROUND_2D], (0.0, math.inf), "gravity must be 2 or 3 finite components"),
], ids=["not-unit", "not-axis", "dimension", "infinite-gravity"])
def test_a_malformed_world_is_refused(walls: list[Wall], g: tuple[float, ...],
                                      words: str) -> None:
    with pytest.raises(ValueError, match=words):
        simulate([drop(2.0, 0.5)], walls, g, 1.0, 1.0)
