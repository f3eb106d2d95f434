"""The geometry kit: the one vector type and the few vector rules every layer shares.

:data:`Vec` is the one vector type (a tuple of floats, 2-D or 3-D; the same
as :data:`reference_impl.types.Vec`).  Sums of products use ``math.fsum``, so
a result does not depend on the order of the terms.

>>> norm((3.0, 4.0))
5.0
>>> to3((1.0, 2.0))
(1.0, 2.0, 0.0)
>>> z_half((0.5, 0.25), (1.5, 0.0))
3.0
>>> approach_speed((0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (-1.0, 0.0))
2.0
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from reference_impl.types import Vec

__all__ = ["Vec", "Vec3", "approach_speed", "difference", "dot", "norm", "to3", "z_half"]

Vec3 = tuple[float, float, float]
"""A vector in 3-D, the form every 3-D engine takes (2-D cases embedded at z = 0)."""


def dot(a: Sequence[float], b: Sequence[float]) -> float:
    """The dot product, summed exactly before its one rounding (``math.fsum``)."""
    return math.fsum(x * y for x, y in zip(a, b, strict=True))


def norm(v: Sequence[float]) -> float:
    """The Euclidean length: ``sqrt(fsum(x**2))``."""
    return math.sqrt(math.fsum(x * x for x in v))


def difference(a: Sequence[float], b: Sequence[float]) -> Vec:
    """``b - a``, component by component (from A to B)."""
    return tuple(y - x for x, y in zip(a, b, strict=True))


def to3(v: Sequence[float]) -> Vec3:
    """A 2- or 3-vector as a 3-vector: a 2-D case lies in the plane z = 0."""
    return (float(v[0]), float(v[1]), float(v[2]) if len(v) > 2 else 0.0)


def z_half(*halves: Sequence[float]) -> float:
    """The z half-width that embeds 2-D boxes in 3-D: 2 x their largest half-width (1 if all 0).

    Both boxes get it, centred at z = 0, so they overlap in z exactly when they
    do in the plane, and the z faces are never the nearest ones.
    """
    return 2.0 * max(abs(h) for half in halves for h in half) or 1.0


def approach_speed(pa: Sequence[float], pb: Sequence[float], va: Sequence[float],
                   vb: Sequence[float]) -> float:
    """Speed at which A and B approach along their line of centres (negative: separating).

    NaN when the centres coincide (no line of centres).
    """
    d = difference(pa, pb)
    length = norm(d)
    if not length > 0:
        return math.nan
    return dot(difference(vb, va), d) / length
