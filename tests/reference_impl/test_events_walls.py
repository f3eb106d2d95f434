"""Gases between walls: the exact references (:mod:`reference_impl.events` with ``walls``, and
:mod:`reference_impl.gravity`) against an independent float64 simulation written here, and
against each other.

The float64 simulation (:func:`float_run`) is deliberately plain: numpy arrays of doubles,
every candidate event recomputed after every event, the textbook root formulas and the
impulse written with a unit normal.  It shares nothing with the references but the physics.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction

import numpy as np
import pytest

from reference_impl import events, gravity
from reference_impl.events import Ball, FloatState, Wall

F = Fraction
HALF = 2.0  # the box is [-HALF, HALF]**2
BOX = [Wall((1.0, 0.0), -HALF), Wall((-1.0, 0.0), -HALF), Wall((0.0, 1.0), -HALF),
       Wall((0.0, -1.0), -HALF)]
BOX_WALLS = BOX  # one wall type serves both references


# ------------------------------------------------------- an independent float64 simulation


def _wall_time(c: float, b: float, a: float) -> float:
    """The first s >= 0 at which a gap c + b s + a s**2 / 2 reaches 0 while closing."""
    if a == 0.0:
        return -c / b if b < 0.0 else math.inf
    disc = b * b - 2.0 * a * c
    if disc < 0.0:
        return math.inf
    q = -(b + math.copysign(math.sqrt(disc), b)) / 2.0  # the stable pair of roots
    roots = [q / (a / 2.0), c / q if q != 0.0 else math.inf]
    closing = [s for s in roots if s >= -1e-12 and b + a * s < 0.0]
    return max(min(closing), 0.0) if closing else math.inf


WallTuple = tuple[int, int, float]
"""A wall as the float64 run takes it: axis, sign, offset."""


def float_run(balls: Sequence[Ball], walls: Sequence[WallTuple], g: Sequence[float],
              e: float, end: float) -> tuple[np.ndarray, int, int]:
    """Final centres, pair collisions and wall bounces of a float64 event-driven run."""
    p = np.array([b.center for b in balls], dtype=np.float64)
    v = np.array([b.velocity for b in balls], dtype=np.float64)
    r = np.array([b.radius for b in balls])
    m = np.array([b.mass for b in balls])
    acc = np.array(g, dtype=np.float64)
    n, t, pairs, bounces = len(balls), 0.0, 0, 0
    last: tuple[int, int] | None = None
    while True:
        best, what = end - t, None
        for i in range(n):
            for j in range(i + 1, n):
                if last == (i, j):
                    continue  # just collided: separating
                dp, dv = p[j] - p[i], v[j] - v[i]
                bb, aa = float(dp @ dv), float(dv @ dv)
                cc = float(dp @ dp) - (r[i] + r[j]) ** 2
                disc = bb * bb - aa * cc
                if bb < 0.0 and disc >= 0.0:
                    s = max(cc / (-bb + math.sqrt(disc)), 0.0)
                    if s < best:
                        best, what = s, (i, j)
            for w, (axis, sign, offset) in enumerate(walls):
                s = _wall_time(sign * p[i, axis] - offset - r[i], sign * v[i, axis],
                               sign * acc[axis])
                if s < best:
                    best, what = s, (i, n + w)
        p += v * best + acc * best * best / 2.0
        v += acc * best
        t += best
        if what is None:
            return p, pairs, bounces
        i, j = what
        last = what
        if j < n:
            normal = (p[i] - p[j]) / np.linalg.norm(p[i] - p[j])
            impulse = (1.0 + e) * float((v[j] - v[i]) @ normal) / (1.0 / m[i] + 1.0 / m[j])
            v[i] += impulse / m[i] * normal
            v[j] -= impulse / m[j] * normal
            pairs += 1
        else:
            axis = walls[j - n][0]
            v[i, axis] = -e * v[i, axis]
            bounces += 1


# ------------------------------------------------------------------ the scenes


GAS = [Ball((-1.2, -1.1), 0.25, 1.0, (1.35, 0.525)),
       Ball((0.6, -1.3), 0.2, 0.64, (-0.6, 1.2)),
       Ball((1.1, 0.9), 0.3, 1.44, (-1.05, -0.9)),
       Ball((-0.8, 1.0), 0.25, 1.0, (0.75, -1.425)),
       Ball((0.2, 0.1), 0.2, 0.64, (1.65, 0.3))]
"""Five discs in the box, speeds about 1.5, no overlap and clear of the walls: in 5 s they
collide 5 times with each other and bounce 12 times on the walls."""
GAS_TIME = 5.0

FALLING = [Ball((-1.0, 1.0), 0.25, 1.0, (1.5, 2.0)), Ball((1.0, 0.5), 0.3, 1.5, (-1.0, 1.0))]
"""Two discs thrown across the box under gravity: 2 collisions and 8 wall bounces in 3 s."""
G = (0.0, -9.81)
FALLING_TIME = 3.0


def tuples(walls: Sequence[Wall]) -> list[WallTuple]:
    return [(w.axis, w.sign, w.offset) for w in walls]


def pair_collisions(state: events.SceneState) -> int:
    return sum(1 for e in state.events if e.j < len(state.positions))


def divergence_bound(balls: Sequence[Ball], collisions: int, walls: int) -> float:
    """How far an honest float64 run may end from the exact one, from how rounding grows.

    Every event and flight of the float64 run commits a relative rounding error of a few
    units in 2**-53 (positions of size 2: about 1e-15 m each; take 1e-14 per event).  A wall
    bounce passes a position error on unchanged (a reflection).  A collision of two discs
    turns a position error dx into an error of the impact normal of dx / (ri + rj), hence of
    the outgoing velocities of |v| dx / (ri + rj), which the flight to the next event (at most
    the box's diagonal L) turns into a position error L dx / (ri + rj): each collision
    multiplies the error by at most 1 + L / (2 r_min).  (Under gravity a flight is a
    parabola inside the box; its length stays within a few diagonals, far inside the margin:
    the runs below agree to 1e-13, against bounds of 1e-7 and 1e-11.)
    """
    gain = 1.0 + 2.0 * math.sqrt(2.0) * HALF / (2.0 * min(b.radius for b in balls))
    return 1e-14 * (collisions + walls + 1) * gain**collisions


def test_a_gas_in_a_box_agrees_with_an_independent_float64_run() -> None:
    state = events.simulate(GAS, 1.0, GAS_TIME, walls=BOX)
    positions, pairs, bounces = float_run(GAS, tuples(BOX), (0.0, 0.0), 1.0, GAS_TIME)
    assert pairs == pair_collisions(state) >= 5  # a gas, not free flights
    assert bounces == len(state.events) - pairs >= 10
    bound = divergence_bound(GAS, pairs, bounces)
    assert bound <= 1e-6  # short enough that float64 should follow the exact run closely
    error = float(np.max(np.abs(positions - np.array(state.positions_float()))))
    assert error <= bound, (error, bound)
    # and the exact run keeps its energy exactly (walls change the momentum, not the energy)
    assert state.kinetic_energy() == events.kinetic_energy(GAS)
    assert state.momentum() != events.momentum(GAS)


def test_a_gas_under_gravity_agrees_with_an_independent_float64_run() -> None:
    run = gravity.simulate(FALLING, BOX_WALLS, G, 1.0, FALLING_TIME)
    positions, pairs, bounces = float_run(FALLING, tuples(BOX), G, 1.0, FALLING_TIME)
    assert pairs == pair_collisions(run.state) >= 2
    assert bounces == len(run.bounces) == len(run.state.events) - pairs >= 8
    # the same growth of rounding errors; gravity adds none to a collision's gain (the
    # relative motion of two flying discs is still linear)
    bound = divergence_bound(FALLING, pairs, bounces)
    assert bound <= 1e-9
    error = float(np.max(np.abs(positions - np.array(run.state.positions_float()))))
    assert error <= bound, (error, bound)
    assert gravity.energy(run.state, G, [b.center for b in FALLING]) == events.kinetic_energy(
        FALLING)


@pytest.mark.parametrize(("balls", "duration"), [(GAS, GAS_TIME), (GAS[:2], 10.0)],
                         ids=["five-discs", "two-discs"])
def test_walls_without_gravity_give_the_same_run_in_both_references(
        balls: list[Ball], duration: float) -> None:
    fast = events.simulate(balls, 1.0, duration, walls=BOX)
    slow = gravity.simulate(balls, BOX_WALLS, (0.0, 0.0), 1.0, duration).state
    assert len(fast.events) >= 5
    assert fast.events == slow.events
    assert fast.positions == slow.positions and fast.velocities == slow.velocities


def test_the_walls_of_a_box_reverse_the_normal_velocity_at_the_closed_form_times() -> None:
    """One disc bouncing between x = -2 and x = 2 at speed 1: it meets x = 2 - r first at
    (2 - r - x0) / v, then every (4 - 2r) / v."""
    ball = Ball((0.0, 0.0), 0.5, 1.0, (1.0, 0.0))
    state = events.simulate([ball], 1.0, 10.0, walls=BOX)
    assert [(e.time, e.j) for e in state.events] == [
        (F(3, 2), 2), (F(9, 2), 1), (F(15, 2), 2)]
    assert state.positions == ((F(-1), F(0)),) and state.velocities == ((F(-1), F(0)),)


def test_inelastic_walls_take_the_normal_velocity_times_e() -> None:
    ball = Ball((0.0, 0.0), 0.5, 1.0, (1.0, 0.5))
    state = events.simulate([ball], 0.5, 2.0, walls=BOX)
    assert [(e.time, e.j) for e in state.events] == [(F(3, 2), 2)]
    assert state.velocities == ((F(-1, 2), F(1, 2)),)  # only the normal component


def test_samples_are_the_correctly_rounded_states_at_their_times() -> None:
    times = [F(1), F(3, 2), F(5, 2)]
    samples: list[FloatState] = []
    ball = Ball((0.0, 0.0), 0.5, 1.0, (1.0, 0.0))
    events.simulate([ball], 1.0, 3.0, walls=BOX, sample_times=times, samples=samples)
    assert samples == [FloatState(1.0, ((1.0, 0.0),), ((1.0, 0.0),)),
                       FloatState(1.5, ((1.5, 0.0),), ((-1.0, 0.0),)),
                       FloatState(2.5, ((0.5, 0.0),), ((-1.0, 0.0),))]
    with pytest.raises(ValueError, match="not ascending within the run"):
        events.simulate([ball], 1.0, 3.0, walls=BOX, sample_times=[F(2), F(1)], samples=[])
