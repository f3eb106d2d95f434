"""The textbook's AABB and sphere formulas, faithfully, in floating point.

These are the formulas as the blog post writes them (Freya.no, "Simple AABB vs
AABB collision detection" and "Simple Sphere-Sphere Collision Detection and
Collision Response"), evaluated operation by operation in IEEE arithmetic:
``precision="f64"`` in float64, ``precision="f32"`` with every input rounded to
float32 and every operation done in float32 (the textbook declares ``float``).
They show what a correct implementation of the textbook *computes*, rounding
included; :mod:`reference_impl.exact` says what the mathematics *means*.

Non-finite inputs are not special: the result is whatever IEEE gives (NaN is
the honest answer of the float formula).  Only the explicit undefined cases
(coincident centres, zero total mass, AABB ties) return :class:`Undefined`.

Two examples where float64 rounding flips the textbook verdict:

>>> aabb_contact((0.0, 0.0, 0.0), (0.8, 1, 1), (1.2000000000000002, 0, 0), (0.4, 1, 1)).hit
True
>>> sphere_contact((0.75, 0.0), 0.6, (2.05, 0.0), 0.7).hit
False
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Literal

import numpy as np

from .exact import dimension, overlap_normal
from .types import Contact, Response, Undefined, Vec

Precision = Literal["f64", "f32"]
Scalar = Any  # a numpy float32 / float64 scalar
_DTYPES: dict[str, Callable[[float], Scalar]] = {"f64": np.float64, "f32": np.float32}


def _caster(precision: Precision) -> Callable[[float], Scalar]:
    try:
        return _DTYPES[precision]
    except KeyError:
        raise ValueError(f"precision must be 'f64' or 'f32', not {precision!r}") from None


def _total(terms: Sequence[Scalar]) -> Scalar:
    """Left-to-right sum, as the textbook's ``a.x + a.y + a.z`` (no leading 0)."""
    acc = terms[0]
    for t in terms[1:]:
        acc = acc + t
    return acc


def _dot(a: Sequence[Scalar], b: Sequence[Scalar]) -> Scalar:
    return _total([x * y for x, y in zip(a, b, strict=True)])


def _floats(v: Sequence[Scalar]) -> Vec:
    return tuple(float(x) for x in v)


def aabb_contact(
    ca: Sequence[float],
    ha: Sequence[float],
    cb: Sequence[float],
    hb: Sequence[float],
    *,
    precision: Precision = "f64",
) -> Contact:
    """Textbook AABB test (``|a.c - b.c| > a.r + b.r`` on an axis: apart).

    Touching counts as a hit.  Overlapping: ``distance`` is minus the smallest
    per-axis overlap, ``normal`` that axis signed by ``cb - ca`` (Undefined on a
    tie or when the centres coincide on it).  Apart: ``distance`` is the
    Euclidean gap ``sqrt(sum g_i**2)``, ``g_i = max(0, |dc_i| - (ha_i + hb_i))``,
    and ``normal`` the vector ``g_i * sign(dc_i)`` normalised.

    >>> aabb_contact((0, 0), (1, 1), (2, 0.5), (1, 1))
    Contact(hit=True, distance=0.0, normal=(1.0, 0.0))
    >>> aabb_contact((0, 0), (1, 1), (1 + 1e-10, 0), (0.5, 0.5), precision="f32").hit
    True
    """
    f = _caster(precision)
    n = dimension(ca, ha, cb, hb)
    with np.errstate(all="ignore"):
        dc = [f(cb[i]) - f(ca[i]) for i in range(n)]
        s = [f(ha[i]) + f(hb[i]) for i in range(n)]
        if not any(abs(dc[i]) > s[i] for i in range(n)):
            return _aabb_overlapping(dc, s)
        return _aabb_apart(dc, s, f(0))


def _aabb_overlapping(dc: list[Scalar], s: list[Scalar]) -> Contact:
    overlaps = [float(si - abs(d)) for d, si in zip(dc, s, strict=True)]
    if any(np.isnan(overlaps)):
        return Contact(True, float("nan"), tuple(float("nan") for _ in dc))
    distance = 0.0 - min(overlaps)  # 0.0 - x, not -x: touching gives +0.0
    return Contact(True, distance, overlap_normal(overlaps, _floats(dc)))


def _aabb_apart(dc: list[Scalar], s: list[Scalar], zero: Scalar) -> Contact:
    gaps = [np.maximum(zero, abs(d) - si) for d, si in zip(dc, s, strict=True)]
    signed = [g * np.sign(d) for g, d in zip(gaps, dc, strict=True)]
    length = np.sqrt(_dot(signed, signed))
    normal: Vec | Undefined = _floats([g / length for g in signed])
    if not any(signed):
        normal = Undefined("coincident centres")
    return Contact(False, float(np.sqrt(_dot(gaps, gaps))), normal)


def sphere_contact(
    pa: Sequence[float],
    ra: float,
    pb: Sequence[float],
    rb: float,
    *,
    precision: Precision = "f64",
) -> Contact:
    """Textbook sphere test: ``d = s1.pos - s2.pos``; hit iff ``|d| < r1 + r2``.

    Touching is not a hit.  ``distance = |d| - (r1 + r2)``; ``normal = -d/|d|``
    (from A to B), Undefined when the centres coincide.

    >>> sphere_contact((0, 0), 1, (3, 4), 1.5)
    Contact(hit=False, distance=2.5, normal=(0.6, 0.8))
    >>> sphere_contact((0, 0), 0.5, (1 - 1e-10, 0), 0.5).hit
    True
    >>> sphere_contact((0, 0), 0.5, (1 - 1e-10, 0), 0.5, precision="f32").hit
    False
    """
    f = _caster(precision)
    dimension(pa, pb)
    with np.errstate(all="ignore"):
        p1, p2 = [f(x) for x in pa], [f(x) for x in pb]
        d = [a - b for a, b in zip(p1, p2, strict=True)]
        length = np.sqrt(_dot(d, d))
        sumradius = f(ra) + f(rb)
        normal: Vec | Undefined = _floats([-x / length for x in d])
        if all(a == b for a, b in zip(p1, p2, strict=True)):
            normal = Undefined("coincident centres")
        return Contact(bool(length < sumradius), float(length - sumradius), normal)


def sphere_response(
    pa: Sequence[float],
    ma: float,
    va: Sequence[float],
    pb: Sequence[float],
    mb: float,
    vb: Sequence[float],
    e: float = 1.0,
    *,
    precision: Precision = "f64",
) -> Response[float] | Undefined:
    """Textbook elastic response, generalised with restitution ``e``.

    ``x = normalize(p1 - p2)``, ``v1x = x (x.v1)``, ``v1y = v1 - v1x``; same for
    sphere 2 with ``x`` negated; then
    ``v1' = v1x (m1 - e m2)/(m1+m2) + v2x ((1+e) m2)/(m1+m2) + v1y`` and
    ``v2' = v1x ((1+e) m1)/(m1+m2) + v2x (m2 - e m1)/(m1+m2) + v2y``.
    For ``e = 1`` this is bit for bit the textbook (``1+1 == 2``,
    ``m1 - 1*m2 == m1 - m2``).  Applied unconditionally, as in the textbook.

    >>> sphere_response((0, 0), 1, (1, 0), (1, 0), 1, (0, 0))
    Response(v1=(0.0, 0.0), v2=(1.0, 0.0))
    >>> sphere_response((0, 0), 1, (1, 0), (0, 0), 1, (0, 0))
    Undefined(reason='coincident centres')
    """
    f = _caster(precision)
    dimension(pa, va, pb, vb)
    p1, v1, p2, v2 = ([f(x) for x in vec] for vec in (pa, va, pb, vb))
    m1, m2, ee, one = f(ma), f(mb), f(e), f(1)
    if all(a == b for a, b in zip(p1, p2, strict=True)):
        return Undefined("coincident centres")
    with np.errstate(all="ignore"):
        if m1 + m2 == 0:
            return Undefined("zero total mass")
        x = [a - b for a, b in zip(p1, p2, strict=True)]
        length = np.sqrt(_dot(x, x))
        x = [c / length for c in x]  # x.normalize()
        x1 = _dot(x, v1)
        v1x = [c * x1 for c in x]
        v1y = [a - b for a, b in zip(v1, v1x, strict=True)]
        x = [-c for c in x]  # x = x * -1
        x2 = _dot(x, v2)
        v2x = [c * x2 for c in x]
        v2y = [a - b for a, b in zip(v2, v2x, strict=True)]
        c11, c12 = (m1 - ee * m2) / (m1 + m2), ((one + ee) * m2) / (m1 + m2)
        c21, c22 = ((one + ee) * m1) / (m1 + m2), (m2 - ee * m1) / (m1 + m2)
        new1 = [a * c11 + b * c12 + c for a, b, c in zip(v1x, v2x, v1y, strict=True)]
        new2 = [a * c21 + b * c22 + c for a, b, c in zip(v1x, v2x, v2y, strict=True)]
        return Response(_floats(new1), _floats(new2))
