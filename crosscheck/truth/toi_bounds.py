"""The float64 bounds of a time of impact: the relative motion, the agree bounds of ``toi``
and ``normal`` and what an engine's precision allows (kind ``sphere_toi``).

What the bounds are and why is :mod:`crosscheck.truth.toi`'s module docstring ("Agree
bounds"); the categories that use them are there too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, norm
from crosscheck.core.model import Observation
from crosscheck.core.schema import ToiCase
from crosscheck.truth.bounds import K_ANGLE, TINY, U

K_TOI = 16
"""Operation-count factor of the time bound (a dozen roundings of ``f``, with room)."""


@dataclass(frozen=True, slots=True)
class Motion:
    """The relative motion of B seen from A, in float64: ``d(t) = dp + dv t``, ``R``."""

    dp: Vec
    dv: Vec
    radius: float

    @classmethod
    def of(cls, case: ToiCase) -> Motion:
        dp = tuple(y - x for x, y in zip(case.a.center, case.b.center, strict=True))
        dv = tuple(y - x for x, y in zip(case.a.velocity, case.b.velocity, strict=True))
        return cls(dp, dv, case.a.radius + case.b.radius)

    def at(self, t: float) -> Vec:
        return tuple(p + v * t for p, v in zip(self.dp, self.dv, strict=True))

    def gap(self, t: float) -> float:
        """The distance between the surfaces at ``t`` (negative: overlapping)."""
        return norm(self.at(t)) - self.radius

    def closest(self, end: float) -> float:
        """The time in ``[0, end]`` at which the centres are closest."""
        a = math.fsum(v * v for v in self.dv)
        if a == 0:
            return 0.0
        return min(end, max(0.0, -math.fsum(p * v for p, v in zip(self.dp, self.dv,
                                                                    strict=True)) / a))

    def time_bound(self, t: float, unit: float) -> float:
        """How far rounding at relative ``unit`` moves the first root ``t``
        (:mod:`crosscheck.truth.toi`)."""
        a = math.fsum(v * v for v in self.dv)
        if a == 0:  # at t = 0 the root still moves: a pair touching at the start rounds apart
            return K_TOI * TINY
        b = math.fsum(p * v for p, v in zip(self.dp, self.dv, strict=True))
        c = math.fsum(p * p for p in self.dp) - self.radius**2
        disc = max(0.0, b * b - a * c)
        size = (math.sqrt(a) * t + norm(self.dp)) ** 2 + self.radius**2
        graze = math.sqrt(size / (K_TOI * unit * a))
        slope = size / (2.0 * math.sqrt(disc)) if disc > 0 else math.inf
        return K_TOI * unit * (t + min(slope, graze)) + K_TOI * TINY


def bound(case: ToiCase, quantity: str, want: Observation, unit: float = U) -> float:
    """The agree tolerance of ``quantity``: the case's own, or the bound at relative ``unit``."""
    own = case.tolerance
    if quantity == "hit":
        return 0.0
    if quantity == "toi" and own and own.toi is not None:
        return own.toi
    if quantity == "normal" and own and own.normal is not None:
        return own.normal
    return _computed(case, quantity, want, unit)


def _computed(case: ToiCase, quantity: str, want: Observation, unit: float) -> float:
    """The bound of ``toi`` or ``normal`` at relative ``unit`` (:mod:`crosscheck.truth.toi`)."""
    motion = Motion.of(case)
    t = want.toi if isinstance(want.toi, float) else 0.0
    dt = motion.time_bound(t, unit)
    if quantity == "toi":
        return dt
    if motion.radius <= 0:
        return math.pi
    lengths = norm(motion.dp) + norm(motion.dv) * t
    return K_ANGLE * unit + (norm(motion.dv) * dt + K_ANGLE * unit * lengths) / motion.radius


def unit_allowance(case: ToiCase, conv: Conventions, truth: Observation) -> float:
    """How far from 1 the length of the engine's normal may be: the normal's own bound at
    the engine's precision ``max(u, rtol)`` (never a case's own tolerance).  Its first term
    is the ``K_ANGLE`` roundings of a normalisation, as for a pair's normal
    (:func:`crosscheck.truth.bounds.unit_allowance`); the rest is what the time error and
    the magnitudes do to ``d / R``: an engine that builds the normal as the centre difference
    over the radius sum without normalising it (parry: ``dpt / radius``) carries the error
    of ``d`` in its length as much as in its direction."""
    return _computed(case, "normal", truth, max(U, conv.rtol))


def precision(conv: Conventions, case: ToiCase) -> float:
    """What the engine's arithmetic precision ``rtol`` allows a separation to be off by:
    ``K_TOI rtol`` of the magnitudes it holds (the coordinates, as an engine in float32
    rounds them, the travel over the interval and the radii)."""
    a, b = case.a, case.b
    magnitude = (max(norm(a.center), norm(b.center))
                 + (norm(a.velocity) + norm(b.velocity)) * case.duration + a.radius + b.radius)
    return K_TOI * max(U, conv.rtol) * magnitude
