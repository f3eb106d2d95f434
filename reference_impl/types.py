"""Small immutable value types shared by the float formulas and the exact oracle.

The reference package imports nothing from the harness; the harness builds on
these types.  A quantity that has no defined value (the normal of two spheres
whose centres coincide, the response of two massless bodies) is an explicit
:class:`Undefined` carrying a reason, never NaN and never an exception.

>>> Undefined("coincident centres")
Undefined(reason='coincident centres')
>>> Contact(hit=True, distance=-0.5, normal=(1.0, 0.0))
Contact(hit=True, distance=-0.5, normal=(1.0, 0.0))
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Generic, TypeVar

Vec = tuple[float, ...]
"""A 2-D or 3-D vector of Python floats."""

N = TypeVar("N", float, Fraction)


@dataclass(frozen=True, slots=True)
class Undefined:
    """A quantity with no defined value, and why."""

    reason: str


@dataclass(frozen=True, slots=True)
class Contact:
    """Result of a detection query between body A and body B.

    ``hit`` is the kind's own verdict (touching overlaps for AABBs, does not
    collide for spheres).  ``distance`` is signed: a gap is positive,
    penetration negative.  ``normal`` is a unit vector pointing from A to B.
    """

    hit: bool
    distance: float
    normal: Vec | Undefined


@dataclass(frozen=True, slots=True)
class Response(Generic[N]):
    """Velocities of A and B after the collision response.

    Float formulas give ``Response[float]``; the exact oracle gives
    ``Response[Fraction]`` so conservation laws can be checked exactly.
    """

    v1: tuple[N, ...]
    v2: tuple[N, ...]
