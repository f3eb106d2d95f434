"""Event-driven reference simulation of N free spheres (2-D discs or 3-D balls).

The exact reference that time-stepping engines (PyBullet, pymunk) are compared
against: spheres fly freely (no gravity, friction or rotation) and collide
pairwise with the textbook response and restitution ``e``.

(Longer than the usual 400 lines on purpose: the interval certification of
impact times, its exact fallback and the tie rule are one argument about
correctness and are read together; the generators at the end are short.)

* **Exact state.**  Positions and velocities are exact rationals starting from
  the input doubles; free flight ``p(t) = p0 + v (t - t0)`` is exact.
* **Time of impact** of balls ``i < j``: with ``dp = pj - pi``, ``dv = vj - vi``,
  ``R = ri + rj``: ``a = dv.dv``, ``b = dp.dv``, ``c = dp.dp - R**2``.  Only an
  approaching pair (``b < 0``) collides; touching with ``b == 0`` does not.  If
  ``c <= 0`` (touching or overlapping) the impact is now, else, if
  ``b**2 - a c >= 0``, after ``c / (-b + sqrt(b**2 - a c))``.
* **Event times are doubles**: the double nearest to the exact absolute time
  (correctly rounded, ties to even; beyond the double range: no event).  Event
  times and the start are doubles and rounding is monotone, so an event is
  never before the current time (it is clamped to it anyway).  The state is
  *exact up to correctly rounded event times*: a pair may collide at a gap or
  overlap of ``|dv|`` times half an ulp of the time.
* **Response** along the line of centres ``d = pi - pj`` rounded componentwise
  to doubles: ``vi += (1+e) mj/(mi+mj) d (d.(vj-vi))/(d.d)``, ``vj -= (1+e)
  mi/(mi+mj) d (d.(vj-vi))/(d.d)``, exactly.  If ``pi - pj`` is a vector of
  doubles (every closed-form scene) this is ``exact.sphere_response``.  For
  *any* ``d`` it conserves momentum, and kinetic energy if ``e = 1``, exactly;
  rounding ``d`` (by less than ``2**-53``) makes the numbers grow linearly
  with the collisions (~200 bits each) where the exact ``d`` makes them grow
  exponentially (~3x per collision).  An event whose pair does not approach
  along the rounded ``d`` (a grazing contact at the rounding level) is
  dropped and not recorded.
* **Simultaneous impacts**, one pair at a time: after an event at ``t``, every
  pair touching or overlapping and approaching at ``t`` has an event at ``t``;
  events at the same time run in lexicographic order of ``(i, j)``, each seeing
  the velocities the previous one left, before time advances.  So a Newton's
  cradle of touching balls passes the momentum pair by pair, ``(0, 1), (1, 2),
  ...`` at one instant: with equal masses and ``e = 1`` ball 0 stops and the
  last ball leaves with its velocity.
* **Walls** (``walls``: static axis-aligned half-spaces, :class:`Wall`): a ball meets
  wall ``w`` when its gap ``sign * x[axis] - offset - r`` (linear in time) reaches 0 while
  closing, at the correctly rounded time; the bounce sets ``v[axis] -> -e v[axis]``
  exactly.  Its event is ``Event(t, i, N + w)``.  Walls break momentum conservation, not
  the energy's at ``e = 1``.  Under gravity, see :mod:`reference_impl.gravity`.
* The run ends at ``duration`` (exact); events at exactly ``duration`` are
  handled.  More than ``max_events`` events (inelastic collapse, say) raise
  :class:`RuntimeError`.

Implementation: all numerators share one integer denominator, so no step
needs a gcd (which dominates :class:`~fractions.Fraction` arithmetic at
thousands of bits); as a collision rescales every numerator by a small factor
anyway, all balls are advanced to each event time (O(N)).  Each pair's
predicted impact sits in a heap stamped with both balls' collision counts
(stale entries are skipped); an event re-predicts only its two balls' pairs.
A prediction is decided by interval arithmetic on the state truncated to 64,
256, then 1024 bits, and by exact :func:`impact_time` only if those cannot.

>>> a = Ball((-2.0, 0.0), 0.5, 1.0, (1.0, 0.0))
>>> b = Ball((2.0, 0.0), 0.5, 1.0, (-1.0, 0.0))
>>> state = simulate([a, b], restitution=1.0, duration=3.0)
>>> state.events
(Event(time=Fraction(3, 2), i=0, j=1),)
>>> state.positions_float(), state.velocities_float()
(((-2.0, 0.0), (2.0, 0.0)), ((-1.0, 0.0), (1.0, 0.0)))
>>> [(e.i, e.j) for e in simulate(cradle(4, 0.5, 1.0), 1.0, 0.0).events]
[(0, 1), (1, 2), (2, 3)]
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from .rounding import Bounds, round_with_sqrt, sqrt_bounds, to_float

FVec = tuple[Fraction, ...]
Interval = tuple[int, int]

_PRECISIONS = (64, 256, 1024)


@dataclass(frozen=True, slots=True)
class Ball:
    """Initial state of one sphere: centre, radius, mass and velocity (doubles).

    >>> Ball((0.0, 0.0), 0.5, 1.0, (1.0, 0.0)).radius
    0.5
    """

    center: tuple[float, ...]
    radius: float
    mass: float
    velocity: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Event:
    """A collision of balls ``i < j`` at ``time`` (a double's exact value).

    >>> Event(Fraction(1, 2), 0, 3)
    Event(time=Fraction(1, 2), i=0, j=3)
    """

    time: Fraction
    i: int
    j: int


@dataclass(frozen=True, slots=True)
class FloatState:
    """A state correctly rounded to doubles: the time, every centre and velocity."""

    time: float
    positions: tuple[tuple[float, ...], ...]
    velocities: tuple[tuple[float, ...], ...]


def is_axis_normal(normal: Sequence[float], dim: int) -> bool:
    """Whether ``normal`` is a unit axis vector of ``dim`` components (one +1 or -1).

    >>> is_axis_normal((0.0, -1.0), 2), is_axis_normal((0.6, 0.8), 2), is_axis_normal((1.0,), 2)
    (True, False, False)
    """
    return len(normal) == dim and sorted(map(abs, normal)) == [0.0] * (dim - 1) + [1.0]


@dataclass(frozen=True, slots=True)
class Wall:
    """A static wall: solid where ``normal . x < offset``; ``normal`` a unit axis vector
    pointing into the free side (:func:`is_axis_normal`).

    >>> Wall((0.0, 0.0, 1.0), 0.0).axis, Wall((0.0, -1.0), -2.0).sign  # a ground; y = 2 above
    (2, -1)
    >>> Wall((0.0, 1.0), -2.0).gap((3.0, 0.5), 0.5)  # a disc's gap above the ground y = -2
    2.0
    """

    normal: tuple[float, ...]
    offset: float

    @property
    def axis(self) -> int:
        """The axis the wall is perpendicular to."""
        return next(k for k, n in enumerate(self.normal) if n != 0.0)

    @property
    def sign(self) -> int:
        """+1 when the free side is towards +axis, else -1."""
        return 1 if self.normal[self.axis] > 0 else -1

    def gap(self, center: Sequence[float], radius: float) -> float:
        """A sphere's signed gap to the wall's surface in float64 (negative: penetrating)."""
        return math.fsum(n * x for n, x in zip(self.normal, center, strict=True)) \
            - self.offset - radius


@dataclass(frozen=True, slots=True)
class SceneState:
    """Exact state of the scene at ``time`` and the events that led to it.

    >>> s = initial_state([Ball((0.0, 0.0), 0.5, 2.0, (1.5, 0.0))])
    >>> s.momentum(), s.kinetic_energy(), s.velocities_float()
    ((Fraction(3, 1), Fraction(0, 1)), Fraction(9, 4), ((1.5, 0.0),))
    """

    time: Fraction
    positions: tuple[FVec, ...]
    velocities: tuple[FVec, ...]
    masses: tuple[Fraction, ...]
    events: tuple[Event, ...]

    def positions_float(self) -> tuple[tuple[float, ...], ...]:
        """Each coordinate correctly rounded to a double."""
        return tuple(tuple(map(to_float, p)) for p in self.positions)

    def velocities_float(self) -> tuple[tuple[float, ...], ...]:
        """Each velocity component correctly rounded to a double."""
        return tuple(tuple(map(to_float, v)) for v in self.velocities)

    def momentum(self) -> FVec:
        """Total momentum, exact."""
        dim = len(self.velocities[0]) if self.velocities else 0
        return tuple(
            sum((m * v[k] for m, v in zip(self.masses, self.velocities, strict=True)), Fraction())
            for k in range(dim)
        )

    def kinetic_energy(self) -> Fraction:
        """Total kinetic energy ``sum m v.v / 2``, exact."""
        pairs = zip(self.masses, self.velocities, strict=True)
        return sum((m * _dot(v, v) for m, v in pairs), Fraction()) / 2


def _dot(a: FVec, b: FVec) -> Fraction:
    return sum((x * y for x, y in zip(a, b, strict=True)), Fraction())


def _sub(a: FVec, b: FVec) -> FVec:
    return tuple(x - y for x, y in zip(a, b, strict=True))


def _rounded_time(now: Fraction, b: Fraction, c: Fraction, disc: Fraction) -> float:
    """Correctly rounded ``now + c / (-b + sqrt(disc))`` (``b < 0 < c``)."""
    lo, hi = sqrt_bounds(disc, 0)
    if lo == hi:  # rational root: round the exact value (a tie stays a tie)
        return to_float(now + c / (lo - b))

    def enclose(lo: Fraction, hi: Fraction) -> Bounds:
        return now + c / (hi - b), now + c / (lo - b)

    return round_with_sqrt(disc, enclose)


def impact_time(dp: FVec, dv: FVec, radius_sum: Fraction, now: Fraction) -> Fraction | None:
    """Rounded absolute time of impact of a pair seen at ``now``, or ``None``.

    >>> h = Fraction(1, 2)
    >>> impact_time((Fraction(4), Fraction(0)), (Fraction(-2), Fraction(0)), 2 * h, h)
    Fraction(2, 1)
    >>> impact_time((Fraction(1), Fraction(0)), (Fraction(0), Fraction(1)), Fraction(1), h) is None
    True
    """
    b = _dot(dp, dv)
    if b >= 0:
        return None
    c = _dot(dp, dp) - radius_sum * radius_sum
    if c <= 0:
        return now
    disc = b * b - _dot(dv, dv) * c
    return None if disc < 0 else _as_time(_rounded_time(now, b, c, disc), now)


def _as_time(t: float, now: Fraction) -> Fraction | None:
    """A rounded impact time clamped to ``now``; beyond the double range, none."""
    return None if math.isinf(t) else max(now, Fraction(t))


def _iv(num: int, den: int, k: int) -> Interval:
    """``[lo, hi]`` enclosing ``num / den * 2**k`` (``den > 0``), a point when exact."""
    q, r = divmod(num << k, den)
    return q, q + (r != 0)


def _mul(x: Interval, y: Interval) -> Interval:
    p = (x[0] * y[0], x[0] * y[1], x[1] * y[0], x[1] * y[1])
    return min(p), max(p)


def _sq(x: Interval) -> Interval:
    lo, hi = x[0] * x[0], x[1] * x[1]
    return (0 if x[0] <= 0 <= x[1] else min(lo, hi)), max(lo, hi)


def _total(xs: Iterable[Interval]) -> Interval:
    los, his = zip(*xs, strict=True)
    return sum(los), sum(his)


def decide(a: Interval, b: Interval, c: Interval, now: Fraction) -> tuple[bool, Fraction | None]:
    """``(True, impact_time)`` if the enclosures of ``a, b, c`` decide it, else ``(False, None)``.

    ``f(t) = a t**2 + 2 b t + c`` lies between ``f_lo`` and ``f_hi`` (the ends'
    polynomials) for ``t >= 0``, so its first root lies between theirs; the
    root ``c / (-b + sqrt(b**2 - a c))`` does not depend on the common scale.
    """
    (alo, ahi), (blo, bhi), (clo, chi) = a, b, c
    if blo >= 0:
        return True, None
    if bhi >= 0:
        return False, None
    if chi <= 0:
        return True, now
    if clo <= 0:
        return False, None
    dlo, dhi = blo * blo - alo * clo, bhi * bhi - ahi * chi
    if dlo < 0:
        return True, None  # f >= f_lo > 0
    if dhi < 0:
        return False, None
    root = math.isqrt(dlo)
    early = now + Fraction(clo, root + (root * root != dlo) - blo)
    late = now + Fraction(chi, math.isqrt(dhi) - bhi)
    t = to_float(early)
    return (True, _as_time(t, now)) if t == to_float(late) else (False, None)


def _check_balls(balls: Sequence[Ball]) -> None:
    dims = {len(b.center) for b in balls} | {len(b.velocity) for b in balls}
    if not dims <= {2, 3} or len(dims) > 1:
        raise ValueError(f"balls must all be 2-D or all 3-D, got lengths {sorted(dims)}")
    for k, b in enumerate(balls):
        values = (*b.center, *b.velocity, b.radius, b.mass)
        if not all(math.isfinite(x) for x in values) or b.radius <= 0 or b.mass <= 0:
            raise ValueError(f"ball {k}: need finite values, radius > 0 and mass > 0")


def initial_state(balls: Sequence[Ball]) -> SceneState:
    """The exact state at time 0, with no events."""
    _check_balls(balls)
    return SceneState(
        Fraction(),
        tuple(tuple(map(Fraction, b.center)) for b in balls),
        tuple(tuple(map(Fraction, b.velocity)) for b in balls),
        tuple(Fraction(b.mass) for b in balls),
        (),
    )


def momentum(balls: Sequence[Ball]) -> FVec:
    """Exact total momentum of the initial state."""
    return initial_state(balls).momentum()


def kinetic_energy(balls: Sequence[Ball]) -> Fraction:
    """Exact total kinetic energy of the initial state."""
    return initial_state(balls).kinetic_energy()


class _Scene:
    """Exact state at ``now`` over shared integer denominators, and the event heap.

    Velocity ``k`` is ``vel[k] / den`` and position ``k`` is ``pos[k] / (den << shift)``.
    """

    def __init__(self, balls: Sequence[Ball], e: Fraction,
                 walls: Sequence[Wall] = ()) -> None:
        start = initial_state(balls)
        self.walls = [(w.axis, w.sign, Fraction(w.offset)) for w in walls]
        self.mass, self.e, self.now = start.masses, e, Fraction()
        self.radius = [Fraction(b.radius) for b in balls]
        self.den = max((x.denominator for v in start.velocities for x in v), default=1)
        pden = max((x.denominator for p in start.positions for x in p), default=1)
        self.shift = max(0, pden.bit_length() - self.den.bit_length())
        self.vel = [[int(x * self.den) for x in v] for v in start.velocities]
        self.pos = [[int(x * self.pden) for x in p] for p in start.positions]
        self.version, self.events = [0] * (len(balls) + len(walls)), list[Event]()
        self.heap: list[tuple[float, int, int, int, int]] = []
        self.n = len(balls)
        for i in range(len(balls)):
            for j in range(i + 1, len(balls)):
                self.predict(i, j)
            self.predict_walls(i)

    @property
    def pden(self) -> int:
        return self.den << self.shift

    def diffs(self, i: int, j: int) -> tuple[list[int], list[int]]:
        """Numerators of ``pj - pi`` (over ``pden``) and ``vj - vi`` (over ``den``)."""
        dp = [y - x for x, y in zip(self.pos[i], self.pos[j], strict=True)]
        return dp, [y - x for x, y in zip(self.vel[i], self.vel[j], strict=True)]

    def quadratic(self, i: int, j: int, k: int) -> tuple[Interval, Interval, Interval]:
        """Enclosures of ``a, b, c`` (see :func:`impact_time`) times ``4**k``."""
        dpn, dvn = self.diffs(i, j)
        dp, dv = [_iv(x, self.pden, k) for x in dpn], [_iv(x, self.den, k) for x in dvn]
        r2, s = (self.radius[i] + self.radius[j]) ** 2 * 4**k, _total(map(_sq, dp))
        c = (s[0] - math.ceil(r2), s[1] - math.floor(r2))
        return _total(map(_sq, dv)), _total(map(_mul, dp, dv)), c

    def impact(self, i: int, j: int) -> Fraction | None:
        for k in _PRECISIONS:
            sure, t = decide(*self.quadratic(i, j, k), self.now)
            if sure:
                return t
        dpn, dvn = self.diffs(i, j)
        dp = tuple(Fraction(x, self.pden) for x in dpn)
        dv = tuple(Fraction(x, self.den) for x in dvn)
        return impact_time(dp, dv, self.radius[i] + self.radius[j], self.now)

    def predict(self, i: int, j: int) -> None:
        t = self.impact(i, j)
        if t is not None:
            heapq.heappush(self.heap, (float(t), i, j, self.version[i], self.version[j]))

    def wall_impact(self, i: int, w: int) -> Fraction | None:
        """Rounded time at which ball ``i`` meets wall ``w`` (linear gap), or None."""
        axis, sign, offset = self.walls[w]
        b = sign * self.vel[i][axis]
        if b >= 0:
            return None
        gap = Fraction(sign * self.pos[i][axis], self.pden) - offset - self.radius[i]
        if gap <= 0:
            return self.now
        return _as_time(to_float(self.now + gap * self.den / -b), self.now)

    def predict_walls(self, i: int) -> None:
        for w in range(len(self.walls)):
            t = self.wall_impact(i, w)
            if t is not None:
                heapq.heappush(self.heap, (float(t), i, self.n + w, self.version[i], 0))

    def bounce(self, i: int, w: int) -> bool:
        """Reverse ball ``i``'s normal velocity at wall ``w`` (times e), if it closes."""
        axis, sign, _ = self.walls[w]
        if sign * self.vel[i][axis] >= 0:
            return False
        num, den = self.e.numerator, self.e.denominator
        if den != 1:
            self.rescale(den)  # every numerator x den: this one divides exactly below
        self.vel[i][axis] = -(self.vel[i][axis] // den) * num
        return True

    def advance(self, t: Fraction) -> None:
        """Move every ball to the double ``t >= now``."""
        dt = t - self.now
        if dt:
            sh = dt.denominator.bit_length() - 1
            new = max(self.shift, sh)
            for p, v in zip(self.pos, self.vel, strict=True):
                for c, (x, y) in enumerate(zip(p, v, strict=True)):
                    p[c] = (x << (new - self.shift)) + (y * dt.numerator << (new - sh))
            self.shift, self.now = new, t

    def respond(self, i: int, j: int) -> bool:
        """Apply the response to ``i, j`` if they approach along the rounded ``d``."""
        dpn, dv = self.diffs(i, j)
        d = [Fraction(-x / self.pden) for x in dpn]  # int / int is correctly rounded
        scale = max(x.denominator for x in d)
        n = [int(x * scale) for x in d]
        dot = sum(x * y for x, y in zip(n, dv, strict=True))
        if dot <= 0:
            return False
        mi, mj = self.mass[i], self.mass[j]
        ci, cj = (1 + self.e) * mj / (mi + mj), (1 + self.e) * mi / (mi + mj)
        lden = math.lcm(ci.denominator, cj.denominator)
        self.rescale(sum(x * x for x in n) * lden)
        gi, gj = (dot * c.numerator * (lden // c.denominator) for c in (ci, cj))
        for c, x in enumerate(n):
            self.vel[i][c] += gi * x
            self.vel[j][c] -= gj * x
        return True

    def rescale(self, f: int) -> None:
        """Multiply the shared denominator (and every numerator) by ``f``."""
        self.den *= f
        for vec in (*self.pos, *self.vel):
            vec[:] = [x * f for x in vec]

    def run(self, end: Fraction, max_events: int) -> None:
        while self.heap and self.heap[0][0] <= end:
            t, i, j, vi, vj = heapq.heappop(self.heap)
            if (vi, vj) != (self.version[i], self.version[j]):
                continue
            self.advance(Fraction(t))
            if not (self.respond(i, j) if j < self.n else self.bounce(i, j - self.n)):
                continue
            if len(self.events) >= max_events:
                raise RuntimeError(f"more than {max_events} events by t = {t!r} (collapse?)")
            self.events.append(Event(self.now, i, j))
            moved = (i, j) if j < self.n else (i,)
            for b in moved:
                self.version[b] += 1
            for k in range(self.n):
                for b in moved:
                    if k not in moved:
                        self.predict(min(b, k), max(b, k))
            if j < self.n:
                self.predict(i, j)
            for b in moved:
                self.predict_walls(b)

    def floats(self, t: Fraction) -> FloatState:
        """The state at ``t >= now`` correctly rounded to doubles, without building a
        Fraction (an int / int quotient is correctly rounded): cheap at thousands of bits."""
        (num, den), pden = (t - self.now).as_integer_ratio(), self.pden
        positions = tuple(tuple((x * den + (y * num << self.shift)) / (pden * den)
                                for x, y in zip(p, v, strict=True))
                          for p, v in zip(self.pos, self.vel, strict=True))
        velocities = tuple(tuple(x / self.den for x in v) for v in self.vel)
        return FloatState(float(t), positions, velocities)

    def state(self, end: Fraction) -> SceneState:
        """The exact state at ``end >= now`` (any rational)."""
        (num, den), pden = (end - self.now).as_integer_ratio(), self.pden
        positions = tuple(
            tuple(
                Fraction(x * den + (y * num << self.shift), pden * den)
                for x, y in zip(p, v, strict=True)
            )
            for p, v in zip(self.pos, self.vel, strict=True)
        )
        velocities = tuple(tuple(Fraction(x, self.den) for x in v) for v in self.vel)
        return SceneState(end, positions, velocities, self.mass, tuple(self.events))


def simulate(
    balls: Sequence[Ball],
    restitution: float,
    duration: float | Fraction,
    max_events: int = 1_000_000,
    walls: Sequence[Wall] = (),
    sample_times: Sequence[Fraction] = (),
    samples: list[FloatState] | None = None,
) -> SceneState:
    """Run the scene from time 0 to ``duration``; see the module docstring.

    The states at ``sample_times`` (ascending, within the run), correctly rounded, are
    appended to ``samples``."""
    if not (math.isfinite(restitution) and restitution >= 0):
        raise ValueError(f"restitution must be finite and >= 0, got {restitution!r}")
    if not math.isfinite(duration) or duration < 0:
        raise ValueError(f"duration must be finite and >= 0, got {duration!r}")
    end = Fraction(duration)
    scene = _Scene(balls, Fraction(restitution), walls)
    for t in sample_times:
        if not scene.now <= t <= end:
            raise ValueError(f"sample time {float(t)} is not ascending within the run")
        scene.run(t, max_events)
        if samples is not None:
            samples.append(scene.floats(t))
    scene.run(end, max_events)
    return scene.state(end)


def _exact_double(x: Fraction) -> float:
    if Fraction(float(x)) != x:
        raise ValueError(f"{x} is not a double; choose a dyadic radius such as 0.5")
    return float(x)


def cradle(n: int, radius: float, speed: float, dim: int = 2) -> list[Ball]:
    """``n`` touching unit-mass balls on the x axis, centres ``2 radius`` apart exactly.

    Ball 0 (at the origin) moves at ``+speed`` into the others, which rest.

    >>> [b.center for b in cradle(3, 0.5, 1.0)]
    [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]
    """
    pad, x = (0.0,) * (dim - 1), [_exact_double(2 * k * Fraction(radius)) for k in range(n)]
    return [Ball((x[k], *pad), radius, 1.0, (speed if k == 0 else 0.0, *pad)) for k in range(n)]


def billiards(dim: int = 2, offset: float = 0.0) -> list[Ball]:
    """A 15-ball triangle rack and a cue ball (index 0) shot at its apex.

    Unit-mass balls of radius 0.5.  Row ``k`` (0..4, apex row 0) sits at
    ``x = k * s * sqrt(3)/2``, its balls at ``y = (m - k/2) * s`` for
    ``m = 0..k``, with spacing ``s = 1.001`` (a gap of 0.001, ``2e-3`` radius, to the
    nearest neighbours).  The cue ball starts at ``(-2, 0)`` with velocity
    ``(2, 0)`` and reaches the apex at ``t = 0.5``; ``offset`` moves it sideways
    (``y = offset``).  Centred, the break is symmetric: the apex meets both balls
    of row 1 at the same instant, an impact with no unique answer (this module
    resolves it pair by pair, an engine's solver simultaneously), so a scene
    that compares engines should break slightly off-centre.

    >>> rack = billiards()
    >>> len(rack), rack[0].velocity, rack[1].center
    (16, (2.0, 0.0), (0.0, 0.0))
    """
    s, pad = 1.001, (0.0,) * (dim - 2)
    zero = (0.0,) * dim
    balls = [Ball((-2.0, offset, *pad), 0.5, 1.0, (2.0, *zero[1:]))]
    for k in range(5):
        for m in range(k + 1):
            centre = (k * s * math.sqrt(3) / 2, (m - k / 2) * s, *pad)
            balls.append(Ball(centre, 0.5, 1.0, zero))
    return balls


def _separated(c: np.ndarray, r: float, placed: list[Ball]) -> bool:
    centre = tuple(map(Fraction, c.tolist()))
    for b in placed:
        d = _sub(centre, tuple(map(Fraction, b.center)))
        if _dot(d, d) <= (Fraction(r) + Fraction(b.radius)) ** 2:
            return False
    return True


def cluster(
    n: int, seed: int, dim: int, extent: float, radius: tuple[float, float], speed: float
) -> list[Ball]:
    """``n`` non-overlapping balls in ``[-extent, extent]**dim`` flying at the centre.

    Deterministic (``numpy.random.default_rng(seed)``).  Radii are uniform in
    ``radius``, ``mass = radius**dim``, centres are drawn by rejection sampling
    (exact no-overlap test), and each velocity is ``speed`` times the unit
    vector towards the origin plus Gaussian noise of deviation ``0.3 speed``.

    >>> balls = cluster(5, seed=1, dim=3, extent=2.0, radius=(0.2, 0.3), speed=1.0)
    >>> len(balls), len(balls[0].center), balls == cluster(5, 1, 3, 2.0, (0.2, 0.3), 1.0)
    (5, 3, True)
    """
    rng = np.random.default_rng(seed)
    balls: list[Ball] = []
    for _ in range(1000 * n):
        if len(balls) == n:
            break
        c, r = rng.uniform(-extent, extent, dim), float(rng.uniform(*radius))
        if not _separated(c, r, balls):
            continue
        aim = -c / max(float(np.linalg.norm(c)), 1e-12)
        v = speed * (aim + 0.3 * rng.standard_normal(dim))
        balls.append(Ball(tuple(c.tolist()), r, r**dim, tuple(v.tolist())))
    if len(balls) < n:
        raise ValueError(f"could not place {n} balls without overlap; enlarge extent")
    return balls
