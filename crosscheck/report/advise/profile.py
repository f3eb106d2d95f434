"""The scene profile of ``advise``: its envelope, the accuracy it needs and what matters.

A profile states the scene: dimensions, kinds, body sizes, largest offset from the origin;
the dimensions of the moving kinds (largest body speed, mass ratio; a scene's time step,
per-step travel and least simulated time; a time of impact's interval), each bounding the
cases of the kinds that have it (:mod:`crosscheck.report.advise.units`); for scenes, the
case tags that name the family (e.g. ``resting``).  It states the accuracy it needs, one
tolerance per unit (metres, radians, m/s, seconds, a share of the quantity's own scale) and
``rtol`` relative to the smallest extent of the case's bodies (on lengths); the quantities
that matter; whether touching must count as contact; whether declared definitions are
judged like any other answer; and whether float32 is acceptable.  An option that applies to
none of the asked kinds, or a tolerance in a unit no asked quantity has, is refused before
any work (:meth:`Envelope.check`).  Cases are placed inside or outside from their own typed
inputs, never from their ids; cases tagged ``bad-input`` are never inside: they are judged
apart, as robustness.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from crosscheck.core.geometry import norm
from crosscheck.core.kinds import ANGLE, FRACTION, LENGTH, PAIR_KINDS, TIME, VELOCITY
from crosscheck.core.schema import DEFAULT_DT, AabbCase, AnyCase, ResponseCase, SceneCase, ToiCase
from crosscheck.report.advise.units import (
    TOLERANCE_OPTIONS,
    UNITS,
    kind_quantities,
    refused_limit,
    refused_tolerance,
)
from crosscheck.truth.scenes import largest_step_travel

Range = tuple[float, float]
"""An inclusive range ``(lo, hi)`` of a dimension (``MAX`` alone: ``(0, MAX)``)."""


class EnvelopeError(ValueError):
    """A profile that cannot hold any scene; ``option`` names the offending option."""

    def __init__(self, option: str, message: str) -> None:
        super().__init__(f"{option}: {message}")
        self.option = option


@dataclass(frozen=True)
class Envelope:
    """The scene's profile; ``None`` or empty: no limit (all quantities matter).

    >>> Envelope(scale=(5.0, 1.0)).check()
    Traceback (most recent call last):
    ...
    crosscheck.report.advise.profile.EnvelopeError: --scale: LO must be <= HI, got 5.0:1.0
    >>> Envelope(tolerance=1e-9, rtol=1e-6).allowed("distance", 8.0)
    8e-06
    >>> Envelope(tolerance=1e-9, velocity_tolerance=1e-3).allowed("v1", 8.0)
    0.001
    >>> Envelope(tolerance=1e-9).allowed("normal", 8.0)  # no angle tolerance: agree only
    0.0
    """

    dims: tuple[int, ...] = ()
    kinds: tuple[str, ...] = ()
    scale: Range | None = None
    offset: float | None = None
    speed: float | None = None
    """Largest speed |v| of any body (responses, times of impact, scenes)."""
    mass_ratio: float | None = None
    tolerance: float | None = None
    """Absolute accuracy needed on lengths, in metres (``hit``, ``distance``, ``settle``)."""
    rtol: float | None = None
    """Accuracy needed relative to the case's smallest extent (lengths only)."""
    quantities: tuple[str, ...] = ()
    """The quantities that matter; empty: every quantity of the kinds."""
    touching_contact: bool = False
    """Touching (exact gap 0) must count as contact: a touching rule is then a failure."""
    strict_conventions: bool = False
    """Every declared convention is judged on its error like any other answer (a behaviour
    always is: only a definition is ever excused)."""
    float32: bool = True
    """Whether a float32 engine is acceptable."""
    tags: tuple[str, ...] = ()
    """Tags every case must carry (a scene family: ``resting``, ``bounce``, ``gas``)."""
    duration: float | None = None
    """Least simulated seconds of a scene."""
    angle_tolerance: float | None = None
    """Absolute accuracy needed on angles, in radians (``normal``)."""
    velocity_tolerance: float | None = None
    """Absolute accuracy needed on velocities, in m/s (``v1``, ``v2``, ``jitter``)."""
    time_tolerance: float | None = None
    """Absolute accuracy needed on times, in seconds (``toi``, ``bounce_time``)."""
    fraction_tolerance: float | None = None
    """Accuracy needed on the quantities measured as a share of their own scale (a scene's
    ``positions`` in mean radii, ``velocities``, ``momentum``, ``energy``, ``energy_drift``
    per second, ``apex``, ``divergence``)."""
    dt: Range | None = None
    """A scene's time step (s)."""
    step_travel: float | None = None
    """Largest per-step travel of a scene's fastest pair at the start."""
    interval: Range | None = None
    """A time of impact's interval length (s)."""

    def tolerances(self) -> dict[str, float | None]:
        """The tolerance of each unit (None: not stated, agree only)."""
        return {LENGTH: self.tolerance, ANGLE: self.angle_tolerance,
                VELOCITY: self.velocity_tolerance, TIME: self.time_tolerance,
                FRACTION: self.fraction_tolerance}

    @property
    def asked_kinds(self) -> tuple[str, ...]:
        """The kinds asked (default: every pair kind, before a run says which it holds)."""
        return self.kinds or PAIR_KINDS

    def check(self) -> None:
        """Raise :class:`EnvelopeError` naming the option if a limit is impossible, or if it
        applies to none of the asked kinds and quantities."""
        self._check_values()
        self._check_scope()

    def _check_values(self) -> None:
        for dim in self.dims:
            if dim not in (2, 3):
                raise EnvelopeError("--dim", f"must be 2 or 3, got {dim}")
        for option, span in (("--scale", self.scale), ("--dt", self.dt),
                             ("--interval", self.interval)):
            if span is not None:
                _check_range(option, span)
        numbers = [("--offset", self.offset), ("--speed", self.speed), ("--rtol", self.rtol),
                   ("--duration", self.duration), ("--step-travel", self.step_travel),
                   *((TOLERANCE_OPTIONS[u], v) for u, v in self.tolerances().items())]
        for option, value in numbers:
            if value is not None:
                _non_negative(option, value)
        if self.mass_ratio is not None and not self.mass_ratio >= 1.0:
            raise EnvelopeError("--mass-ratio", f"must be a number >= 1, got {self.mass_ratio}")

    def _check_scope(self) -> None:
        kinds = self.asked_kinds
        known = kind_quantities(kinds)
        for quantity in self.quantities:
            if quantity not in known:
                raise EnvelopeError("--quantities", f"{quantity!r} is no quantity of the asked "
                                                    f"kinds ({', '.join(kinds)}): "
                                                    f"choose from {', '.join(known)}")
        limits = {"--speed": self.speed, "--mass-ratio": self.mass_ratio,
                  "--duration": self.duration, "--dt": self.dt,
                  "--step-travel": self.step_travel, "--interval": self.interval,
                  "--touching-contact": self.touching_contact or None}
        asked = self.quantities or known
        refusals = [(option, refused_limit(option, kinds)) for option, value in limits.items()
                    if value is not None]
        refusals += [(TOLERANCE_OPTIONS[unit], refused_tolerance(unit, asked))
                     for unit, value in self.tolerances().items() if value is not None]
        if self.rtol is not None:
            refusals.append(("--rtol", refused_tolerance(LENGTH, asked)))
        for option, reason in refusals:
            if reason is not None:
                raise EnvelopeError(option, reason)

    def holds(self, case: AnyCase) -> bool:
        """Whether the case's own inputs lie inside this envelope (never a bad-input case)."""
        if case.bad_input or (self.dims and case.dim not in self.dims):
            return False
        if not set(self.tags) <= set(case.tags):
            return False
        return (_within_scale(case, self.scale) and _within(centres(case), self.offset)
                and _within(speeds(case), self.speed)
                and _within([mass_ratio(case)], self.mass_ratio)
                and _in_range(time_step(case), self.dt)
                and (self.step_travel is None
                     or _within(_present(step_travel(case)), self.step_travel))
                and _in_range(interval(case), self.interval)
                and _lasts(case, self.duration))

    def allowed(self, quantity: str, size: float) -> float:
        """The error allowed on ``quantity`` for a case whose smallest body is ``size``: the
        tolerance of its unit (none stated: 0, agree only), and on lengths ``rtol`` x size."""
        unit = UNITS[quantity]
        absolute = self.tolerances()[unit] or 0.0
        if self.rtol is None or unit != LENGTH or not math.isfinite(size):
            return absolute
        return max(absolute, self.rtol * size)


def _check_range(option: str, span: Range) -> None:
    lo, hi = span
    _non_negative(option, lo)
    _non_negative(option, hi)
    if lo > hi:
        raise EnvelopeError(option, f"LO must be <= HI, got {lo}:{hi}")


def _non_negative(option: str, value: float) -> None:
    if not (math.isfinite(value) and value >= 0.0):
        raise EnvelopeError(option, f"must be a finite number >= 0, got {value}")


def _lasts(case: AnyCase, duration: float | None) -> bool:
    """A scene simulating at least ``duration`` seconds (its steps times its dt); no limit,
    or a case of another kind: True.

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> scene = CASE_ADAPTER.validate_python({"id": "s", "description": "d",
    ...     "kind": "sphere_scene", "dim": 2, "duration": 10.0, "bodies": [
    ...     {"center": [0, 0], "radius": 1, "mass": 1, "velocity": [0, 0]}]})
    >>> _lasts(scene, 10.0), _lasts(scene, 20.0), _lasts(scene, None)
    (True, False, True)
    """
    lasts = simulated(case)
    return duration is None or lasts is None or lasts >= duration * (1 - SLACK)


SLACK = 1e-9
"""Relative room of a time limit: a dt of 1/60 written as 0.016666666666666666 is within
``--dt 1/60``, and 600 steps of it last 10 s."""


def _in_range(value: float | None, span: Range | None) -> bool:
    """``value`` within ``span``, to :data:`SLACK` (no value or no limit: True)."""
    if value is None or span is None:
        return True
    return span[0] * (1 - SLACK) <= value <= span[1] * (1 + SLACK)


def _present(value: float | None) -> list[float]:
    return [] if value is None else [value]


def _within(values: Iterable[float], limit: float | None) -> bool:
    """Every |value| <= limit (NaN is never within); no limit: True."""
    return limit is None or all(abs(v) <= limit for v in values)


def _within_scale(case: AnyCase, scale: tuple[float, float] | None) -> bool:
    """Every radius and half-width within ``scale``; with no ``--scale``, every one positive:
    a scene's bodies have a size, and a zero-size body (a point, a flat plate) is in the
    envelope only when the profile says so with ``--scale 0:HI``.

    >>> from crosscheck.testing.samples import sphere_pair
    >>> point = sphere_pair(0.0, 1.0, ra=0.0)
    >>> _within_scale(point, None), _within_scale(point, (0.0, 1.0))
    (False, True)
    """
    sizes = extents(case)
    if scale is None:
        return all(s > 0 for s in sizes)
    return all(scale[0] <= s <= scale[1] for s in sizes)


def _bodies(case: AnyCase) -> tuple[Any, ...]:
    return case.bodies if isinstance(case, SceneCase) else (case.a, case.b)


def sizes(case: AnyCase) -> list[float]:
    """Each body's size: its radius, or its largest half-width (NaN if any is NaN).

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> sizes(CASE_ADAPTER.validate_python({"id": "b", "description": "d", "kind": "aabb",
    ...     "dim": 2, "a": {"center": [0, 0], "half": [1, 3]},
    ...     "b": {"center": [5, 0], "half": [2, 2]}}))
    [3.0, 2.0]
    """
    if isinstance(case, AabbCase):
        return [math.nan if any(math.isnan(h) for h in body.half) else max(body.half)
                for body in (case.a, case.b)]
    return [float(body.radius) for body in _bodies(case)]


def extents(case: AnyCase) -> list[float]:
    """Every radius and every half-width of every body: what ``--scale`` bounds (a box
    of half-widths 0, 1, 1 is a flat plate, not a body of size 1)."""
    if isinstance(case, AabbCase):
        return [float(h) for body in (case.a, case.b) for h in body.half]
    return [float(body.radius) for body in _bodies(case)]


def smallest_size(case: AnyCase) -> float:
    """The smallest extent of the case (:func:`extents`): the length ``rtol`` is relative to
    (NaN when an extent is not finite: then only the absolute tolerance applies)."""
    values = extents(case)
    return min(values) if all(math.isfinite(v) for v in values) else math.nan


def centres(case: AnyCase) -> list[float]:
    """Every centre coordinate of every body."""
    return [float(c) for body in _bodies(case) for c in body.center]


def speeds(case: AnyCase) -> list[float]:
    """Every body's speed |v| (none for detection cases)."""
    if not isinstance(case, ResponseCase | SceneCase | ToiCase):
        return []
    return [norm(body.velocity) for body in _bodies(case)]


def time_step(case: AnyCase) -> float | None:
    """A scene's time step (None for other kinds)."""
    return (case.dt or DEFAULT_DT) if isinstance(case, SceneCase) else None


def step_travel(case: AnyCase) -> float | None:
    """A scene's largest per-step travel at the start
    (:func:`crosscheck.truth.scenes.largest_step_travel`; None for other kinds)."""
    return largest_step_travel(case) if isinstance(case, SceneCase) else None


def simulated(case: AnyCase) -> float | None:
    """A scene's simulated seconds, its steps times its dt (None for other kinds)."""
    return case.step_count * (case.dt or DEFAULT_DT) if isinstance(case, SceneCase) else None


def interval(case: AnyCase) -> float | None:
    """A time of impact's interval length (None for other kinds)."""
    return case.duration if isinstance(case, ToiCase) else None


def mass_ratio(case: AnyCase) -> float:
    """max(m) / min(m) of the bodies (1 for detection cases; inf when a mass is <= 0)."""
    if not isinstance(case, ResponseCase | SceneCase):
        return 1.0
    masses = [float(body.mass) for body in _bodies(case)]
    if any(math.isnan(m) for m in masses):
        return math.nan
    return max(masses) / min(masses) if min(masses) > 0.0 else math.inf
