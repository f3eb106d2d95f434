"""A dropped body's bounces, each judged against its own one-step bound.

Under gravity above a ground, body 0's recorded bounces (:func:`~crosscheck.truth.
scene_measures.bounces`: apex heights and bounce times) are a sequence of events.  Each is
judged from the engine's *own* state before it, never against a sum over the run:

- **apex**: from the engine's previous apex ``H`` (the first: the exact drop height), the
  body hits the ground at ``v = min(sqrt(2 |g| H), cap)`` (``cap``: a declared speed cap,
  which acts at every step) and, bouncing with ``e`` (0 below a declared restitution
  threshold; an engine that compares it with the approach at the step's start, declared
  ``bounce_from_step_start``, may also give none up to ``|g| dt`` above it), rises to
  ``A = (e v)**2 / (2 |g|)``.  Found up to one step late, it turns
  back up to ``depth = v dt + |g| dt**2`` below the ground, so it may **lose** up to that
  much height (plus what sampling the apex every ``s`` steps hides, ``|g| (s dt)**2 / 2``);
  step lag never **adds** energy, so an apex above ``A`` beyond the precision (the float
  tolerance, the declared ``rtol`` of the coordinates and a declared response precision) is
  a gain that no step explains;
- **bounce time**: the first bounce comes after the (capped) fall from the drop height, the
  others one flight ``2 e v / |g|`` (from the engine's apex between them) after the last;
  each is seen up to one step late and recorded up to one stride late at either end, so an
  interval is off by at most ``2 (s + 1) dt`` (the first bounce ``(s + 1) dt``).

:func:`apexes` and :func:`intervals` return every event with its numbers; the worst one
(:func:`worst`) is what a reason cites.

>>> e = Event(1, previous=1.0, expected=1.0, engine=0.93, depth=0.0765, precision=0.0)
>>> e.within, round(e.change, 3)
(True, -0.07)
>>> Event(2, 1.0, 1.0, 1.076, 0.0765, 0.0).gain
True
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import norm
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import scene_measures as sm


@dataclass(frozen=True, slots=True)
class Event:
    """One bounce's apex: expected from the engine's previous apex, and the engine's."""

    index: int
    """1 for the first bounce."""
    previous: float
    """The height (m) the body fell from: the engine's previous apex (the first: the drop)."""
    expected: float
    """The apex that height gives: ``(e v)**2 / 2|g|``."""
    engine: float
    depth: float
    """One step's lag at this impact (m): the height a late bounce may lose."""
    precision: float
    """What the float tolerance and the engine's precision allow either way (m)."""
    inelastic: bool = False
    """The declared restitution threshold made this bounce inelastic."""
    early: float = 0.0
    """When the threshold met the approach at the step's start (declared
    ``bounce_from_step_start``) above the impact's speed: how much slower it may be, one
    step of gravity ``|g| dt`` (m/s)."""

    @property
    def change(self) -> float:
        """The apex's change from the expected one, over the height fallen from."""
        return (self.engine - self.expected) / self.previous if self.previous > 0 else 0.0

    @property
    def bound(self) -> float:
        """The one-step loss allowed, over the height fallen from."""
        return (self.depth + self.precision) / self.previous if self.previous > 0 else 0.0

    @property
    def gain(self) -> bool:
        """Above the expected apex beyond the precision: energy no step lag adds."""
        return self.engine > self.expected + self.precision

    @property
    def within(self) -> bool:
        return not self.gain and self.engine >= self.expected - self.depth - self.precision

    def __str__(self) -> str:
        way = "gains" if self.change > 0 else "loses"
        return (f"bounce {self.index} {way} {abs(self.change):.3g} of the {self.previous:.3g} m "
                f"it fell from (apex {self.engine:.4g} m against {self.expected:.4g} m"
                + (", inelastic under the declared restitution threshold" if self.inelastic
                   else "")
                + (f" met by the approach at the step's start, up to |g| dt = {self.early:.3g}"
                   " m/s slower than the impact (declared bounce_from_step_start)"
                   if self.inelastic and self.early > 0 else "")
                + (f"; only the precision's {self.precision:.3g} m is allowed either way: "
                   "step lag never adds height)" if self.gain else
                   f"; one step's lag allows a loss of {self.bound:.3g}: v dt + |g| dt^2 = "
                   f"{self.depth:.3g} m)"))


@dataclass(frozen=True, slots=True)
class Interval:
    """One bounce time: expected from the engine's previous bounce and apex."""

    index: int
    expected: float
    engine: float
    bound: float

    @property
    def off(self) -> float:
        return self.engine - self.expected

    @property
    def within(self) -> bool:
        return abs(self.off) <= self.bound

    def __str__(self) -> str:
        return (f"bounce {self.index} at t = {self.engine:.4g} s, {self.off:+.3g} s from the "
                f"{self.expected:.4g} s its fall gives (one step late at either end and the "
                f"recording stride allow {self.bound:.3g} s)")


def _normal_state(case: SceneCase) -> tuple[float, float, float]:
    """Body 0's height above the ground, its upward speed and |g| at the start."""
    floor = sm.ground(case)
    assert floor is not None
    body = case.bodies[0]
    up = math.fsum(n * v for n, v in zip(case.walls[floor].normal, body.velocity, strict=True))
    return (sm.gap(case, floor, body.center, body.radius), up, norm(sm.gravity(case)))


def cap(case: SceneCase, conventions: Conventions) -> float:
    """The speed a falling body cannot exceed under the declared cap (inf: none).  A cap per
    coordinate acts on the fall alone (the ground's normal along an axis); a cap per step is
    a travel per step at the declared time step (Box2D's)."""
    if conventions.max_speed is None:
        return math.inf
    if conventions.max_speed_at == "step":
        dt = case.dt or DEFAULT_DT
        return conventions.max_speed * (conventions.time_step or dt) / dt
    return conventions.max_speed


def drop_height(case: SceneCase) -> float:
    """The height (m) of body 0's first apex-to-ground fall (its start, or higher if thrown
    up)."""
    height, up, g = _normal_state(case)
    return height + max(up, 0.0) ** 2 / (2 * g)


def first_fall(case: SceneCase, conventions: Conventions) -> float:
    """The time of body 0's first bounce under the cap, from its start."""
    _height, up, g = _normal_state(case)
    limit = cap(case, conventions)
    rise = max(up, 0.0) / g
    top = drop_height(case)
    free = math.sqrt(2 * top / g)
    if g * free <= limit:
        return rise + free
    reach = limit / g
    return rise + reach + (top - limit * limit / (2 * g)) / limit


def _stride(case: SceneCase) -> int:
    return max(1, sm.record_every(case))


def apexes(case: SceneCase, conventions: Conventions, engine: Sequence[float],
           slack: float) -> list[Event]:
    """Each of the engine's apexes (up to the exact run's count is the caller's choice)
    judged from the engine's previous one; ``slack`` the length the float tolerance and the
    precision allow, to which a declared response precision (``response_rtol``, relative to
    the speed) adds ``(2 r + r**2)`` of the expected apex (an apex goes as the speed
    squared)."""
    g, dt = norm(sm.gravity(case)), case.dt or DEFAULT_DT
    limit = cap(case, conventions)
    sampled = g * (_stride(case) * dt) ** 2 / 2
    out: list[Event] = []
    previous = drop_height(case)
    for k, apex in enumerate(engine, start=1):
        speed = min(math.sqrt(2 * g * max(previous, 0.0)), limit)
        threshold = conventions.restitution_threshold
        inelastic = 0.0 < speed < threshold
        depth = speed * dt + g * dt * dt + sampled
        event = _event(case, conventions, k, previous, apex, speed, depth, slack, inelastic)
        # an engine that compares the threshold with the approach at the step's start meets
        # it with a fall up to |g| dt slower: a bounce in that band may be inelastic
        early = g * dt if conventions.bounce_from_step_start else 0.0
        if (not inelastic and not event.within and threshold <= speed < threshold + early
                and case.restitution > 0):
            event = _event(case, conventions, k, previous, apex, speed, depth, slack, True,
                           early)
        out.append(event)
        previous = apex
    return out


def _event(case: SceneCase, conventions: Conventions, k: int, previous: float, apex: float,
           speed: float, depth: float, slack: float, inelastic: bool,
           early: float = 0.0) -> Event:
    """Bounce ``k`` from ``previous`` at ``speed``: with the scene's e, or none."""
    g, dt = norm(sm.gravity(case)), case.dt or DEFAULT_DT
    sampled = g * (_stride(case) * dt) ** 2 / 2
    e = 0.0 if inelastic else case.restitution
    expected = (e * speed) ** 2 / (2 * g)
    r = conventions.response_rtol or 0.0
    # a recorded previous apex may sit below the true one by what the stride hides, and
    # the bounce it gives by e**2 of that (the first falls from the exact drop height)
    hidden = e * e * sampled if k > 1 else 0.0
    return Event(k, previous, expected, apex, depth,
                 slack + (2 * r + r * r) * expected + hidden, inelastic, early)


def intervals(case: SceneCase, conventions: Conventions, times: Sequence[float],
              engine_apexes: Sequence[float]) -> list[Interval]:
    """Each of the engine's bounce times judged from its previous one and the apex between."""
    g, dt = norm(sm.gravity(case)), case.dt or DEFAULT_DT
    lag = (_stride(case) + 1) * dt
    out: list[Interval] = []
    for k, t in enumerate(times, start=1):
        if k == 1:
            out.append(Interval(1, first_fall(case, conventions), t, lag))
            continue
        if k - 2 >= len(engine_apexes):
            break
        flight = 2 * math.sqrt(2 * max(engine_apexes[k - 2], 0.0) / g)
        out.append(Interval(k, times[k - 2] + flight, t, 2 * lag))
    return out


def worst(events: Sequence[Event]) -> Event | None:
    """The event furthest outside its bound (else the one nearest to it)."""
    if not events:
        return None
    return max(events, key=lambda e: (not e.within, e.gain,
                                      abs(e.change) / e.bound if e.bound > 0 else math.inf))

