"""The exact oracle: the textbook's AABB and sphere formulas in exact arithmetic.

Every input float is converted with :class:`fractions.Fraction`, i.e. to the
exact binary value it stores, and every verdict is decided in rationals, so
the answer is the one the textbook's real-number mathematics gives for those
inputs, free of rounding.  Distances and normals, which need a square root,
are returned as float64 values that are *correctly rounded* (see
:mod:`reference_impl.rounding`); the sphere response needs no square root and
is returned as exact fractions.

Conventions (shared with :mod:`reference_impl.formulas`):

* ``distance`` is signed: a gap is positive, penetration negative.
* ``normal`` is a unit vector from A to B, or :class:`Undefined`.
* A non-finite input gives ``Undefined("non-finite input: <field>")``.

Negative sizes are not rejected; the formulas are read as real mathematics.
An AABB verdict is exactly the textbook test, so a negative half-width sum on
an axis means "never overlapping".  Spheres collide iff ``|d| < ra + rb``; if
``ra + rb < 0`` that is false for every ``d``, so there is no collision (and the
signed distance ``|d| - (ra + rb)`` is positive, consistent with the verdict).

Two examples where the float64 textbook code and the exact answer disagree:

>>> aabb_contact((0.0, 0.0, 0.0), (0.8, 1, 1), (1.2000000000000002, 0, 0), (0.4, 1, 1))
Contact(hit=False, distance=1.1102230246251565e-16, normal=(1.0, 0.0, 0.0))
>>> sphere_contact((0.75, 0.0), 0.6, (2.05, 0.0), 0.7).hit
True
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from fractions import Fraction
from typing import TypeVar

from .rounding import quotient, sqrt_minus, sqrt_rounded, to_float
from .types import Contact, Response, Undefined, Vec

AXES = "xyz"

T = TypeVar("T", float, Fraction)
FVec = tuple[Fraction, ...]


def dimension(*vectors: Sequence[float]) -> int:
    """Common length (2 or 3) of the vectors, else :class:`ValueError`."""
    sizes = {len(v) for v in vectors}
    if len(sizes) != 1 or not sizes <= {2, 3}:
        raise ValueError(f"vectors must all be 2-D or all be 3-D, got lengths {sorted(sizes)}")
    return sizes.pop()


def overlap_normal(overlaps: Sequence[T], dc: Sequence[T]) -> Vec | Undefined:
    """Unit normal along the axis of smallest overlap, signed by ``dc = cb - ca``.

    >>> overlap_normal([0.5, 0.25], [1.0, -2.0])
    (0.0, -1.0)
    >>> overlap_normal([0.5, 0.5, 0.75], [1.0, 1.0, 1.0])
    Undefined(reason='tie between axes x and y')
    """
    smallest = min(overlaps)
    axes = [i for i, o in enumerate(overlaps) if o == smallest]
    if len(axes) > 1:
        names = [AXES[i] for i in axes]
        return Undefined(f"tie between axes {', '.join(names[:-1])} and {names[-1]}")
    (axis,) = axes
    if dc[axis] == 0:
        return Undefined(f"coincident centres on axis {AXES[axis]}")
    sign = 1.0 if dc[axis] > 0 else -1.0
    return tuple(sign if i == axis else 0.0 for i in range(len(dc)))


def _non_finite(**fields: float | Sequence[float]) -> Undefined | None:
    """The first non-finite input, as an :class:`Undefined`, or ``None``."""
    for name, value in fields.items():
        items = list(enumerate(value)) if isinstance(value, Iterable) else [(None, value)]
        for i, x in items:
            if not math.isfinite(x):
                label = name if i is None else f"{name}[{i}]"
                return Undefined(f"non-finite input: {label}")
    return None


def _q(x: float) -> Fraction:
    return Fraction(x) if isinstance(x, (int, float)) else Fraction(float(x))


def _vec(v: Sequence[float]) -> FVec:
    return tuple(_q(x) for x in v)


def _dot(a: FVec, b: FVec) -> Fraction:
    return sum((x * y for x, y in zip(a, b, strict=True)), Fraction(0))


def _sign(x: Fraction) -> int:
    return (x > 0) - (x < 0)


def _sub(a: FVec, b: FVec) -> FVec:
    return tuple(x - y for x, y in zip(a, b, strict=True))


def aabb_contact(
    ca: Sequence[float], ha: Sequence[float], cb: Sequence[float], hb: Sequence[float]
) -> Contact | Undefined:
    """Exact contact of AABB A (centre ``ca``, half-widths ``ha``) and AABB B.

    ``hit`` is the textbook test in rationals (touching overlaps).  Apart:
    ``distance`` is the Euclidean gap and ``normal`` the normalised vector of
    signed per-axis gaps.  Overlapping or touching: ``distance`` is minus the
    smallest per-axis overlap and ``normal`` that axis, signed from A to B.

    >>> aabb_contact((0, 0), (1, 1), (3, 4), (0.5, 1.5))
    Contact(hit=False, distance=2.1213203435596424, normal=(0.7071067811865476, 0.7071067811865476))
    >>> aabb_contact((0, 0), (1, 1), (1.5, 1), (1, 1))
    Contact(hit=True, distance=-0.5, normal=(1.0, 0.0))
    >>> aabb_contact((0, 0), (1, 1), (0, 1), (1, 3))
    Contact(hit=True, distance=-2.0, normal=Undefined(reason='coincident centres on axis x'))
    """
    n = dimension(ca, ha, cb, hb)
    bad = _non_finite(ca=ca, ha=ha, cb=cb, hb=hb)
    if bad is not None:
        return bad
    dc = _sub(_vec(cb), _vec(ca))
    s = tuple(x + y for x, y in zip(_vec(ha), _vec(hb), strict=True))
    if all(abs(dc[i]) <= s[i] for i in range(n)):
        overlaps = [s[i] - abs(dc[i]) for i in range(n)]
        return Contact(True, to_float(-min(overlaps)), overlap_normal(overlaps, dc))
    gaps = tuple(max(Fraction(0), abs(dc[i]) - s[i]) for i in range(n))
    signed = tuple(g * _sign(x) for g, x in zip(gaps, dc, strict=True))
    q = _dot(signed, signed)
    normal = tuple(quotient(g, q) for g in signed) if q else Undefined("coincident centres")
    return Contact(False, sqrt_rounded(_dot(gaps, gaps)), normal)


def sphere_contact(
    pa: Sequence[float], ra: float, pb: Sequence[float], rb: float
) -> Contact | Undefined:
    """Exact contact of sphere A (centre ``pa``, radius ``ra``) and sphere B.

    ``hit`` iff ``|pb - pa| < ra + rb`` exactly (touching is not a hit; a
    negative radius sum never collides).  ``distance = |pb - pa| - (ra + rb)``
    and ``normal = (pb - pa) / |pb - pa|``, both correctly rounded.

    >>> sphere_contact((0, 0), 1, (3, 4), 1.5)
    Contact(hit=False, distance=2.5, normal=(0.6, 0.8))
    >>> sphere_contact((0, 0, 0), 1, (0, 0, 0), 1)
    Contact(hit=True, distance=-2.0, normal=Undefined(reason='coincident centres'))
    """
    dimension(pa, pb)
    bad = _non_finite(pa=pa, ra=ra, pb=pb, rb=rb)
    if bad is not None:
        return bad
    d = _sub(_vec(pb), _vec(pa))
    q = _dot(d, d)
    r = _q(ra) + _q(rb)
    hit = r > 0 and q < r * r  # sqrt(q) < r, exactly
    if q == 0:
        return Contact(hit, to_float(-r), Undefined("coincident centres"))
    return Contact(hit, sqrt_minus(q, r), tuple(quotient(x, q) for x in d))


def sphere_response(
    pa: Sequence[float],
    ma: float,
    va: Sequence[float],
    pb: Sequence[float],
    mb: float,
    vb: Sequence[float],
    e: float = 1.0,
) -> Response[Fraction] | Undefined:
    """Exact velocities after the textbook response, with restitution ``e``.

    With ``d = pa - pb`` and ``proj(v) = d (d.v) / (d.d)`` (no square root):
    ``v1' = v1 + (1+e) m2/(m1+m2) proj(v2 - v1)`` and
    ``v2' = v2 + (1+e) m1/(m1+m2) proj(v1 - v2)``, which is the textbook's
    ``v1x (m1 - e m2)/(m1+m2) + v2x (1+e) m2/(m1+m2) + v1y`` rearranged
    (``v1x = proj(v1)``, ``v1y = v1 - proj(v1)``).  Like the textbook it is
    applied whether or not the spheres touch or approach.

    >>> r = sphere_response((0, 0), 1, (1, 0), (1, 0), 1, (0, 0))
    >>> [tuple(map(float, v)) for v in (r.v1, r.v2)]
    [(0.0, 0.0), (1.0, 0.0)]
    >>> sphere_response((0, 0), 1, (1, 0), (1, 0), -1, (0, 0))
    Undefined(reason='zero total mass')
    """
    dimension(pa, va, pb, vb)
    bad = _non_finite(pa=pa, ma=ma, va=va, pb=pb, mb=mb, vb=vb, e=e)
    if bad is not None:
        return bad
    d = _sub(_vec(pa), _vec(pb))
    dd = _dot(d, d)
    if dd == 0:
        return Undefined("coincident centres")
    m1, m2, ee = _q(ma), _q(mb), _q(e)
    if m1 + m2 == 0:
        return Undefined("zero total mass")
    v1, v2 = _vec(va), _vec(vb)

    def proj(v: FVec) -> FVec:
        c = _dot(d, v) / dd
        return tuple(c * x for x in d)

    c1, c2 = (1 + ee) * m2 / (m1 + m2), (1 + ee) * m1 / (m1 + m2)
    new1 = tuple(v + c1 * p for v, p in zip(v1, proj(_sub(v2, v1)), strict=True))
    new2 = tuple(v + c2 * p for v, p in zip(v2, proj(_sub(v1, v2)), strict=True))
    return Response(new1, new2)
