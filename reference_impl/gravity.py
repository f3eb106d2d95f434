"""Event-driven reference of N spheres under uniform gravity between static axis-aligned walls.

The exact reference for scenes with a ground, a box or gravity (:mod:`reference_impl.events`
is the open-space one, with the same rules between spheres).  Everything is an exact rational
starting from the input doubles; frictionless, no rotation.

* **Motion.**  A flying body moves as ``p(t) = p0 + v0 (t - t0) + g (t - t0)**2 / 2``.  Every
  flying body has the same acceleration ``g``, so the relative motion of two flying spheres
  is linear and their contact time is :func:`reference_impl.events.impact_time`'s quadratic.
* **Walls.**  Wall ``w`` is solid where ``n . x < offset`` (``n`` a unit axis vector into the
  free side).  A sphere's gap ``n . p - offset - r`` is ``c + b s + a s**2 / 2`` after ``s``
  seconds, with ``b = n . v`` and ``a = n . g``; it reaches 0 at
  ``s = 2 c / (sqrt(b**2 - 2 a c) - b)`` (no cancellation; no contact when the square root is
  not real or the denominator is not positive).  The bounce reverses the normal component:
  ``v_n -> -e v_n``.  Walls do not conserve momentum (their normal component changes by
  ``(1 + e) m |v_n|`` per bounce); the total energy ``sum m v.v / 2 - m g . (p - p0)`` is
  conserved exactly when ``e = 1``.
* **Event times** are the doubles nearest the exact times (ties to even), as in
  :mod:`reference_impl.events`: the state is exact up to correctly rounded event times.
* **Resting contact, explicitly.**  A body *rests* when it touches a wall whose normal is
  opposite to gravity with no normal velocity (``gap == 0``, ``b == 0``, ``a < 0``), or touches a
  resting sphere straight below it (their centre line parallel to gravity) with the same
  velocity.  A resting body does not accelerate (the support's normal force cancels gravity
  exactly) and gets no wall or sphere events from its supports; it stays at rest until an
  impact gives it a velocity.  Resting is decided at the start, after an inelastic bounce
  that leaves no normal velocity (``e = 0``) and at the end of a bounce series (below).
* **No chattering.**  With ``e < 1`` a sphere bouncing on a ground makes infinitely many
  bounces in finite time: after a bounce leaving at normal speed ``u`` the flights last
  ``2 u e**k / |a|`` and end at ``t_rest = t + 2 u / (|a| (1 - e))`` exactly.  Bounces are
  simulated one by one while a flight lasts at least :data:`MIN_FLIGHT` seconds; then the
  rest of the series is summed in closed form: the body rests on the wall from ``t_rest``
  (rounded like an event time), and until then it is within ``u**2 / (2 |a|)`` of the wall
  (less than ``1e-21`` m with ``|a| = 9.81``).  The shortened series is a ``settle`` event.
* **Simultaneous events** run one at a time in the order (time, sphere pairs before walls,
  indices), each seeing the velocities the previous one left, as in
  :mod:`reference_impl.events`.
* **Not modelled:** a resting body and a flying one under gravity both able to meet (their
  relative motion is a quartic in time) raise ValueError naming the pair.  A body touching a
  side wall, or a sphere not straight below it, with no normal velocity does not rest: it
  flies on (frictionless), and meeting a resting sphere that way raises as above.

>>> ground = Wall((0.0, 1.0), 0.0)
>>> drop = Ball((0.0, 1.5), 0.5, 1.0, (0.0, 0.0))
>>> run = simulate([drop], [ground], (0.0, -8.0), 1.0, 1.0)
>>> [(float(e.time), e.i, e.j) for e in run.state.events]
[(0.5, 0, 1)]
>>> run.state.positions_float(), run.state.velocities_float()
(((0.0, 1.5),), ((0.0, 0.0),))
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

from .events import Ball, Event, SceneState, Wall, impact_time, is_axis_normal
from .rounding import round_with_sqrt, to_float

FVec = tuple[Fraction, ...]

MIN_FLIGHT = Fraction(1, 2**30)
"""Seconds: a bounce series whose next flight is shorter is summed in closed form (rest)."""

SETTLE = -1
"""``Event.j`` of a settle event: a bounce series summed up, the body rests from then on."""


@dataclass(frozen=True, slots=True)
class Run:
    """The end state (``state.events``: ``j < N`` a sphere, ``j == N + w`` wall ``w``,
    ``j == SETTLE`` a bounce series summed up) and the states at the sample times."""

    state: SceneState
    samples: tuple[SceneState, ...]
    resting: tuple[bool, ...]
    """Which bodies rest at the end."""
    bounces: tuple[tuple[Fraction, int, int, Fraction], ...] = ()
    """Every wall bounce: ``(time, body, wall, outgoing normal speed)``."""
    rest_since: Fraction | None = None
    """Since when every body rests (None: not all rest at the end)."""


def _dot(a: Sequence[Fraction], b: Sequence[Fraction]) -> Fraction:
    return sum((x * y for x, y in zip(a, b, strict=True)), Fraction())


def wall_time(now: Fraction, a: Fraction, b: Fraction, c: Fraction) -> Fraction | None:
    """Rounded absolute time at which a gap ``c + b s + a s**2 / 2`` next reaches 0 closing.

    With ``c > 0`` that is ``s = 2 c / (sqrt(b**2 - 2 a c) - b)``; with ``c <= 0`` (an event
    time rounded after the exact contact leaves a sub-ulp overlap) it is now when the gap
    still closes, else the return after leaving, ``s = (b + sqrt(b**2 - 2 a c)) / -a``
    (gravity towards the wall, ``a < 0``), else never.

    >>> wall_time(Fraction(0), Fraction(-8), Fraction(0), Fraction(1))  # 4 s**2 = 1
    Fraction(1, 2)
    >>> wall_time(Fraction(0), Fraction(8), Fraction(1), Fraction(1)) is None  # moving away
    True
    >>> wall_time(Fraction(0), Fraction(-8), Fraction(2), Fraction(0))  # leaving: back at 1/2
    Fraction(1, 2)
    """
    if c <= 0:
        if b < 0 or (b == 0 and a < 0):
            return now
        if a >= 0:
            return None
        disc = b * b - 2 * a * c
        t = round_with_sqrt(disc, lambda lo, hi: (now + (b + lo) / -a, now + (b + hi) / -a))
        return None if math.isinf(t) else max(now, Fraction(t))
    disc = b * b - 2 * a * c
    if disc < 0 or (b >= 0 and a >= 0):  # a >= 0 <= b: sqrt(disc) <= b, never closes
        return None
    t = round_with_sqrt(disc, lambda lo, hi: (now + 2 * c / (hi - b), now + 2 * c / (lo - b)))
    return None if math.isinf(t) else max(now, Fraction(t))


class _World:
    """The exact state: each body's position and velocity at ``now`` and whether it rests."""

    def __init__(self, balls: Sequence[Ball], walls: Sequence[Wall], gravity: FVec,
                 e: Fraction) -> None:
        self.n, self.walls, self.g, self.e = len(balls), list(walls), gravity, e
        self.p = [list(map(Fraction, b.center)) for b in balls]
        self.v = [list(map(Fraction, b.velocity)) for b in balls]
        self.p0 = [tuple(p) for p in self.p]
        self.r = [Fraction(b.radius) for b in balls]
        self.m = [Fraction(b.mass) for b in balls]
        self.now, self.events = Fraction(), list[Event]()
        self.rest = [False] * self.n
        self.settle_at: dict[int, tuple[Fraction, int]] = {}  # body: (time, wall)
        self.bounces: list[tuple[Fraction, int, int, Fraction]] = []
        self._find_rest()
        self.rest_since: Fraction | None = Fraction() if all(self.rest) else None

    def gap(self, i: int, w: int) -> Fraction:
        wall = self.walls[w]
        return wall.sign * self.p[i][wall.axis] - Fraction(wall.offset) - self.r[i]

    def _down(self, w: int) -> bool:
        """Wall ``w`` faces gravity: a body can rest on it."""
        wall = self.walls[w]
        along = wall.sign * self.g[wall.axis]
        return along < 0 and all(x == 0 for k, x in enumerate(self.g) if k != wall.axis)

    def _rests_on_wall(self, i: int, w: int) -> bool:
        wall = self.walls[w]
        return self._down(w) and self.gap(i, w) == 0 and self.v[i][wall.axis] == 0

    def _rests_on(self, i: int, j: int) -> bool:
        """Sphere ``i`` touches resting ``j`` straight below it, with j's velocity."""
        d = [x - y for x, y in zip(self.p[i], self.p[j], strict=True)]
        if _dot(d, d) != (self.r[i] + self.r[j]) ** 2 or self.v[i] != self.v[j]:
            return False
        up = [-x for x in self.g]
        cross_zero = all(d[a] * up[b] == d[b] * up[a] for a in range(len(d)) for b in range(a))
        return cross_zero and _dot(d, up) > 0

    def _find_rest(self) -> None:
        changed = True
        while changed:
            changed = False
            for i in range(self.n):
                if self.rest[i]:
                    continue
                on = any(self._rests_on_wall(i, w) for w in range(len(self.walls))) or any(
                    self.rest[j] and self._rests_on(i, j) for j in range(self.n) if j != i)
                if on:
                    self.rest[i] = changed = True

    def advance(self, t: Fraction) -> None:
        s = t - self.now
        if s:
            for i in range(self.n):
                a = (Fraction(0),) * len(self.g) if self.rest[i] else self.g
                self.p[i] = [x + v * s + q * s * s / 2 for x, v, q in zip(self.p[i], self.v[i], a,
                                                                          strict=True)]
                self.v[i] = [v + q * s for v, q in zip(self.v[i], a, strict=True)]
            self.now = t

    def pair_time(self, i: int, j: int) -> Fraction | None:
        if self.rest[i] and self.rest[j]:
            return None
        if self.rest[i] != self.rest[j] and any(self.g):
            raise ValueError(f"spheres {i} and {j}: one rests and one flies under gravity; "
                             "their contact time is a quartic, not modelled")
        dp = tuple(y - x for x, y in zip(self.p[i], self.p[j], strict=True))
        dv = tuple(y - x for x, y in zip(self.v[i], self.v[j], strict=True))
        return impact_time(dp, dv, self.r[i] + self.r[j], self.now)

    def wall_time(self, i: int, w: int) -> Fraction | None:
        if self.rest[i] or i in self.settle_at:  # a summed series has no more bounces
            return None
        wall = self.walls[w]
        b, a = wall.sign * self.v[i][wall.axis], wall.sign * self.g[wall.axis]
        return wall_time(self.now, a, b, self.gap(i, w))

    def next_event(self) -> tuple[Fraction, int, int] | None:
        """The earliest ``(time, i, j)``; at a tie sphere pairs, then walls, then settles,
        each in index order."""
        found: list[tuple[Fraction, int, int, int]] = []
        for i in range(self.n):
            for j in range(i + 1, self.n):
                if (t := self.pair_time(i, j)) is not None:
                    found.append((t, 0, i, j))
            for w in range(len(self.walls)):
                if (t := self.wall_time(i, w)) is not None:
                    found.append((t, 1, i, self.n + w))
        found += [(t, 2, i, SETTLE) for i, (t, _) in self.settle_at.items()]
        if not found:
            return None
        t, _, i, j = min(found)
        return t, i, j

    def respond_pair(self, i: int, j: int) -> bool:
        d = [Fraction(to_float(x - y)) for x, y in zip(self.p[i], self.p[j], strict=True)]
        dv = [y - x for x, y in zip(self.v[i], self.v[j], strict=True)]
        dot = _dot(d, dv)
        if dot <= 0:
            return False
        mi, mj, dd = self.m[i], self.m[j], _dot(d, d)
        gi, gj = (1 + self.e) * mj / (mi + mj) * dot / dd, (1 + self.e) * mi / (mi + mj) * dot / dd
        self.v[i] = [v + gi * x for v, x in zip(self.v[i], d, strict=True)]
        self.v[j] = [v - gj * x for v, x in zip(self.v[j], d, strict=True)]
        self.rest[i] = self.rest[j] = False
        return True

    def respond_wall(self, i: int, w: int) -> bool:
        wall = self.walls[w]
        b = wall.sign * self.v[i][wall.axis]
        if b > 0 or (b == 0 and not self._down(w)):
            return False
        self.v[i][wall.axis] = -self.e * self.v[i][wall.axis]
        u, a = self.e * -b, -wall.sign * self.g[wall.axis]  # a: pull towards the wall
        self.bounces.append((self.now, i, w, u))
        if self._down(w) and (u == 0 or (self.e < 1 and 2 * u / a < MIN_FLIGHT)):
            if u == 0:
                self.settle(i, w)
            else:  # the rest of the series, summed: rest from t_rest on
                t_rest = self.now + 2 * u / (a * (1 - self.e))
                self.settle_at[i] = (max(self.now, Fraction(to_float(t_rest))), w)
        return True

    def settle(self, i: int, w: int) -> None:
        """The body rests on wall ``w`` (gap 0, normal speed 0): after a bounce that leaves no
        normal speed, or at the end of a summed bounce series on that wall."""
        self.settle_at.pop(i, None)
        wall = self.walls[w]
        self.p[i][wall.axis] = wall.sign * (Fraction(wall.offset) + self.r[i])
        self.v[i][wall.axis] = Fraction()
        self.rest[i] = True

    def run(self, end: Fraction, max_events: int) -> None:
        while (nxt := self.next_event()) is not None and nxt[0] <= end:
            t, i, j = nxt
            self.advance(t)
            if j == SETTLE:
                self.settle(i, self.settle_at[i][1])
            elif not (self.respond_pair(i, j) if j < self.n else self.respond_wall(i, j - self.n)):
                raise RuntimeError(f"event ({i}, {j}) at {t} does not approach")  # pragma: no cover
            if len(self.events) >= max_events:
                raise RuntimeError(f"more than {max_events} events by t = {float(t)!r}")
            self.events.append(Event(self.now, i, j))
            self._find_rest()
            if all(self.rest) and self.rest_since is None:
                self.rest_since = self.now
        self.advance(end)

    def state(self) -> SceneState:
        return SceneState(self.now, tuple(tuple(p) for p in self.p),
                          tuple(tuple(v) for v in self.v), tuple(self.m), tuple(self.events))


def _check(balls: Sequence[Ball], walls: Sequence[Wall], gravity: Sequence[float]) -> None:
    dim = len(gravity)
    if dim not in (2, 3) or not all(map(math.isfinite, gravity)):
        raise ValueError(f"gravity must be 2 or 3 finite components, got {tuple(gravity)}")
    for k, w in enumerate(walls):
        if not is_axis_normal(w.normal, dim):
            raise ValueError(f"wall {k}: the normal must be a unit axis vector, got {w.normal}")
        if not math.isfinite(w.offset):
            raise ValueError(f"wall {k}: the offset must be finite")
    for k, b in enumerate(balls):
        if len(b.center) != dim or len(b.velocity) != dim:
            raise ValueError(f"ball {k}: centre and velocity need {dim} components")
        values = (*b.center, *b.velocity, b.radius, b.mass)
        if not all(map(math.isfinite, values)) or b.radius <= 0 or b.mass <= 0:
            raise ValueError(f"ball {k}: need finite values, radius > 0 and mass > 0")


def simulate(balls: Sequence[Ball], walls: Sequence[Wall], gravity: Sequence[float],
             restitution: float, duration: float | Fraction,
             sample_times: Sequence[Fraction] = (), max_events: int = 200_000) -> Run:
    """Run the scene from 0 to ``duration`` (see the module docstring), with the exact states
    at ``sample_times`` (ascending, within the run)."""
    _check(balls, walls, gravity)
    if not (math.isfinite(restitution) and 0 <= restitution <= 1):
        raise ValueError(f"restitution must be in [0, 1], got {restitution!r}")
    end = Fraction(duration)
    if not (end >= 0 and math.isfinite(end)):
        raise ValueError(f"duration must be finite and >= 0, got {duration!r}")
    world = _World(balls, walls, tuple(map(Fraction, gravity)), Fraction(restitution))
    for k in range(len(walls)):
        for i in range(len(balls)):
            if world.gap(i, k) < 0:
                raise ValueError(f"ball {i} starts inside wall {k}")
    samples = []
    for t in sample_times:
        if not world.now <= t <= end:
            raise ValueError(f"sample time {float(t)} is not ascending within [0, {float(end)}]")
        world.run(t, max_events)
        samples.append(world.state())
    world.run(end, max_events)
    return Run(world.state(), tuple(samples), tuple(world.rest), tuple(world.bounces),
               world.rest_since if all(world.rest) else None)


def energy(state: SceneState, gravity: Sequence[float], start: Sequence[Sequence[float]]
           ) -> Fraction:
    """Total energy ``sum m v.v / 2 - m g . (p - p0)``, exact (``start``: the p0s).

    >>> s = simulate([Ball((0.0, 1.5), 0.5, 1.0, (0.0, 0.0))], [Wall((0.0, 1.0), 0.0)],
    ...              (0.0, -8.0), 1.0, 0.25).state
    >>> energy(s, (0.0, -8.0), [(0.0, 1.5)])
    Fraction(0, 1)
    """
    g = tuple(map(Fraction, gravity))
    total = Fraction()
    for m, p, v, p0 in zip(state.masses, state.positions, state.velocities, start, strict=True):
        total += m * _dot(v, v) / 2 - m * _dot(g, [x - Fraction(y) for x, y in zip(p, p0,
                                                                                   strict=True)])
    return total
