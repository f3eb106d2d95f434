"""Why a dropped body's run disagrees: its bounces, each against its own bound, give the
pair one category that every quantity of the run takes.

A scene whose exact run bounces body 0 on a ground (``apex`` defined) is a sequence of
events (:mod:`crosscheck.truth.bounces`): each bounce's apex from the engine's own previous
apex, each bounce time from its own previous bounce.  :func:`sequence` judges them once:

1. an apex above the one its fall gives, beyond the precision: energy that no step lag
   adds, an ``error`` (nothing declared adds energy);
2. a loss beyond one step's lag ``v dt + |g| dt**2``: ``convention`` for a declared soft or
   predictive contact model (it keeps any part of a bounce) or within the declared
   damping over the flight; else ``error``;
3. a bounce time beyond one step late at either end and the recording stride:
   ``convention`` for a soft contact (a contact lasting several steps), else ``error``;
4. every event within its bound: ``convention`` when a declared speed cap or restitution
   threshold shaped a bounce (named; with a declared ``bounce_from_step_start`` the
   threshold meets the approach at the step's start, up to ``|g| dt`` slower than the
   impact), else ``timestep``.

The ``apex`` and ``bounce_time`` rows cite their own worst event; positions, velocities,
momentum, energy, the energy drift and the divergence of the same run take the sequence's
category with its words (:func:`inherited`): one mechanism, one category.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import norm
from crosscheck.core.model import Category, Observation
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import bounces
from crosscheck.truth import scene_measures as sm
from crosscheck.truth.scenes import held


@dataclass(frozen=True, slots=True)
class Drop:
    """The verdict on a drop's bounces: the category, the words, the events."""

    category: str
    why: str
    events: tuple[bounces.Event, ...]
    intervals: tuple[bounces.Interval, ...]

    @property
    def worst_interval(self) -> bounces.Interval | None:
        return max(self.intervals, key=lambda i: (not i.within, abs(i.off) / i.bound
                                                  if i.bound > 0 else math.inf),
                   default=None)


def _apexes(observed: Observation, truth: Observation) -> list[float] | None:
    mine, exact = observed.apex, truth.apex
    times = observed.bounce_time
    if not (isinstance(mine, tuple) and isinstance(exact, tuple) and isinstance(times, tuple)):
        return None
    apexes = [float(x) for x in mine[:len(exact)]]
    if len(times) < len(exact):  # bounces the engine never made: it did not rise
        apexes += [0.0] * (len(exact) - len(apexes))
    return apexes


def sequence(case: SceneCase, conventions: Conventions, observed: Observation,
             truth: Observation) -> Drop | None:
    """The verdict on body 0's bounces (None: the exact run has none, or the engine
    recorded no trajectory)."""
    apexes = _apexes(observed, truth)
    times, exact_times = observed.bounce_time, truth.bounce_time
    if apexes is None or not isinstance(times, tuple) or not isinstance(exact_times, tuple):
        return None
    slack = held(case, conventions) + 8 * math.ulp(max(sm.top_speed(case), 1.0))
    events = tuple(bounces.apexes(case, conventions, apexes, slack))
    intervals = tuple(bounces.intervals(case, conventions, times[:len(exact_times)],
                                        observed.apex if isinstance(observed.apex, tuple)
                                        else ()))
    category, why = _verdict(case, conventions, events, intervals)
    return Drop(category, why, events, intervals)


def _damped(case: SceneCase, conventions: Conventions, event: bounces.Event) -> bool:
    """The loss is within one step's lag plus what the declared damping takes over the
    fall and the rise of that bounce."""
    if conventions.damping <= 0:
        return False
    g = norm(sm.gravity(case))
    speed = math.sqrt(2 * g * max(event.previous, 0.0))
    flight = 2 * speed / g if g > 0 else 0.0
    kept = math.exp(-conventions.damping * (1.0 + speed) * flight)
    return event.engine >= event.expected * kept * kept - event.depth - event.precision


def _verdict(case: SceneCase, conventions: Conventions, events: tuple[bounces.Event, ...],
             intervals: tuple[bounces.Interval, ...]) -> tuple[str, str]:
    count = f"{len(events)} bounce(s) judged, each from the engine's own previous apex"
    gains = [e for e in events if e.gain]
    if gains:
        model = conventions.restitution_model
        keeps = (f"; the declared {model} contact model only keeps part of a bounce"
                 if model else "")
        return Category.ERROR, (f"{gains[0]}: no step lag adds energy, and nothing declared "
                                f"does{keeps} ({count})")
    lost = [e for e in events if not e.within]
    model = conventions.restitution_model
    if lost and conventions.bounce_may_lose:
        return Category.CONVENTION, (f"{bounces.worst(lost)}: the declared {model} contact "
                                     f"model keeps any part of a bounce ({count})")
    if lost and all(_damped(case, conventions, e) for e in lost):
        return Category.CONVENTION, (
            f"{bounces.worst(lost)}, within it plus the declared damping "
            f"{conventions.damping:g} per s over that bounce's flight ({count})")
    if lost:
        return Category.ERROR, (f"{bounces.worst(lost)}: beyond one step's lag, and no "
                                f"declared damping, threshold or soft contact takes it ({count})")
    late = [i for i in intervals if not i.within]
    if late and model == "soft":
        return Category.CONVENTION, (f"{late[0]}: the declared soft contact lasts several "
                                     f"steps and holds the body on the ground ({count})")
    if late:
        return Category.ERROR, f"{late[0]}: beyond one step at either end ({count})"
    worst = bounces.worst(events)
    detail = f"worst: {worst}" if worst else "no bounce recorded"
    limit = bounces.cap(case, conventions)
    g = norm(sm.gravity(case))
    capped = [e for e in events if math.sqrt(2 * g * max(e.previous, 0.0)) > limit]
    if capped:
        return Category.CONVENTION, (
            f"every bounce within one step's lag of the bounce its fall gives with speeds "
            f"capped at {limit:.4g} m/s (declared max_speed, acting {conventions.max_speed_at}"
            f" at every step; {len(capped)} bounce(s) hit it) ({detail}; {count})")
    inelastic = [e for e in events if e.inelastic]
    early = [e for e in inelastic if e.early > 0]
    if inelastic:
        g = norm(sm.gravity(case))
        landing = math.sqrt(2 * g * max(early[0].previous, 0.0)) if early else 0.0
        return Category.CONVENTION, (
            f"every bounce within one step's lag; {len(inelastic)} close below the declared "
            f"restitution threshold {conventions.restitution_threshold:g} m/s and do not "
            "bounce" + (f" ({len(early)} of them above it, within |g| dt = "
                        f"{early[0].early:.3g} m/s: bounce {early[0].index} lands at "
                        f"{landing:.4g} m/s, and the engine compares the threshold with the "
                        "approach at the step's start, declared bounce_from_step_start)"
                        if early else "")
            + f" ({detail}; {count})")
    return Category.TIMESTEP, (f"every bounce within one step's lag of the bounce its fall "
                               f"gives ({detail}; {count})")


def inherited(case: SceneCase, conventions: Conventions, quantity: str, what: str,
              observed: Observation, truth: Observation) -> tuple[str, str] | None:
    """A drop's quantity that follows its bounces: the sequence's category and words."""
    drop = sequence(case, conventions, observed, truth)
    if drop is None:
        return None
    dt = case.dt or DEFAULT_DT
    return drop.category, (f"{what}: the run's bounces decide it (dt = {dt:.3g} s): "
                           f"{drop.why}")

