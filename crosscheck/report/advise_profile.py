"""The scene profile of ``advise``: its envelope, the accuracy it needs and what matters.

A profile states the scene (dimensions, kinds, body sizes, largest offset from
the origin, largest speed and mass ratio; for stepped scenes, the case tags that name the
family, e.g. ``resting``, and the least simulated time), the accuracy it needs (``tolerance``
absolute, ``rtol`` relative to the smallest extent of the case's bodies, on
lengths),
the quantities that matter, whether touching must count as contact, whether
declared conventions are judged like any other answer, and whether float32 is
acceptable.  Cases are placed inside or outside it from their own typed inputs,
never from their ids; cases tagged ``bad-input`` are never inside: they are
judged apart, as robustness.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from crosscheck.core.schema import DEFAULT_DT, AabbCase, AnyCase, ResponseCase, SceneCase

LENGTHS = frozenset({"hit", "distance", "positions", "settle"})
"""Quantities measured in lengths: ``rtol`` scales with the body size for them (for
``hit``, the length is the exact gap of the pair)."""


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
    crosscheck.report.advise_profile.EnvelopeError: --scale: LO must be <= HI, got 5.0:1.0
    >>> Envelope(tolerance=1e-9, rtol=1e-6).allowed("distance", 8.0)
    8e-06
    >>> Envelope(tolerance=1e-9, rtol=1e-6).allowed("v1", 8.0)
    1e-09
    """

    dims: tuple[int, ...] = ()
    kinds: tuple[str, ...] = ()
    scale: tuple[float, float] | None = None
    offset: float | None = None
    speed: float | None = None
    mass_ratio: float | None = None
    tolerance: float | None = None
    """Absolute accuracy needed, in the quantity's own unit."""
    rtol: float | None = None
    """Accuracy needed relative to the case's smallest extent (lengths only)."""
    quantities: tuple[str, ...] = ()
    """The quantities that matter; empty: every quantity of the kinds."""
    touching_contact: bool = False
    """Touching (exact gap 0) must count as contact: a touching rule is then a failure."""
    strict_conventions: bool = False
    """Every declared convention is judged on its error like any other answer."""
    float32: bool = True
    """Whether a float32 engine is acceptable."""
    tags: tuple[str, ...] = ()
    """Tags every case must carry (a scene family: ``resting``, ``bounce``, ``gas``)."""
    duration: float | None = None
    """Least simulated seconds of a scene (pair cases, which have none, are then outside)."""

    def check(self) -> None:
        """Raise :class:`EnvelopeError` naming the option if a limit is impossible."""
        for dim in self.dims:
            if dim not in (2, 3):
                raise EnvelopeError("--dim", f"must be 2 or 3, got {dim}")
        if self.scale is not None:
            lo, hi = self.scale
            _non_negative("--scale", lo)
            _non_negative("--scale", hi)
            if lo > hi:
                raise EnvelopeError("--scale", f"LO must be <= HI, got {lo}:{hi}")
        for option, value in (("--offset", self.offset), ("--speed", self.speed),
                              ("--tolerance", self.tolerance), ("--rtol", self.rtol),
                              ("--duration", self.duration)):
            if value is not None:
                _non_negative(option, value)
        if self.mass_ratio is not None and not self.mass_ratio >= 1.0:
            raise EnvelopeError("--mass-ratio", f"must be a number >= 1, got {self.mass_ratio}")

    def holds(self, case: AnyCase) -> bool:
        """Whether the case's own inputs lie inside this envelope (never a bad-input case)."""
        if case.bad_input or (self.dims and case.dim not in self.dims):
            return False
        if not set(self.tags) <= set(case.tags) or not _lasts(case, self.duration):
            return False
        return (_within_scale(case, self.scale) and _within(centres(case), self.offset)
                and _within(velocity_components(case), self.speed)
                and _within([mass_ratio(case)], self.mass_ratio))

    def allowed(self, quantity: str, size: float) -> float:
        """The error allowed on ``quantity`` for a case whose smallest body is ``size``."""
        absolute = self.tolerance or 0.0
        if self.rtol is None or quantity not in LENGTHS or not math.isfinite(size):
            return absolute
        return max(absolute, self.rtol * size)


def _non_negative(option: str, value: float) -> None:
    if not (math.isfinite(value) and value >= 0.0):
        raise EnvelopeError(option, f"must be a finite number >= 0, got {value}")


def _lasts(case: AnyCase, duration: float | None) -> bool:
    """A scene simulating at least ``duration`` seconds (its steps times its dt); no limit:
    True.

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> scene = CASE_ADAPTER.validate_python({"id": "s", "description": "d",
    ...     "kind": "sphere_scene", "dim": 2, "duration": 10.0, "bodies": [
    ...     {"center": [0, 0], "radius": 1, "mass": 1, "velocity": [0, 0]}]})
    >>> _lasts(scene, 10.0), _lasts(scene, 20.0), _lasts(scene, None)
    (True, False, True)
    """
    if duration is None:
        return True
    if not isinstance(case, SceneCase):
        return False
    return case.step_count * (case.dt or DEFAULT_DT) >= duration * (1 - 1e-9)


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


def velocity_components(case: AnyCase) -> list[float]:
    """Every velocity component of every body (none for detection cases)."""
    if not isinstance(case, ResponseCase | SceneCase):
        return []
    return [float(v) for body in _bodies(case) for v in body.velocity]


def mass_ratio(case: AnyCase) -> float:
    """max(m) / min(m) of the bodies (1 for detection cases; inf when a mass is <= 0)."""
    if not isinstance(case, ResponseCase | SceneCase):
        return 1.0
    masses = [float(body.mass) for body in _bodies(case)]
    if any(math.isnan(m) for m in masses):
        return math.nan
    return max(masses) / min(masses) if min(masses) > 0.0 else math.inf
