"""Correctly rounded sphere distances and normals for N pairs at numpy speed.

The values equal :func:`reference_impl.exact.sphere_contact` bit for bit (signed zeros
included): ``distance = RN(|pb - pa| - (ra + rb))`` and ``normal_i = RN((pb - pa)_i /
|pb - pa|)``, where ``RN`` rounds the exact real to the nearest double, ties to even, and
a zero normal component is ``+0.0``.  Three stages, in the manner of Ziv's rounding test
(:func:`reference_impl.ddouble.ziv`); each pair goes only as far as it needs:

1. **double-double**, every pair in range, in blocks of :data:`CHUNK` pairs:
   ``d = pb - pa = dh + dl`` exactly (TwoSum); ``q = |d|**2`` within ``2**-73.9 q`` and
   ``S = sqrt(q)`` within ``2**-74 s`` (:func:`~reference_impl.ddouble.norm2`,
   :func:`~reference_impl.ddouble.sqrt_dd`); ``D = S - (ra + rb)`` within
   ``2**-73.9 (s + |r|)`` (TwoSum of ``s - rh``, the small parts added in float).  Each
   normal component starts from ``m``, ``fl(dh_i fl(1 / s))`` cut to 26 bits, so that
   ``m * sh`` and ``m * sl`` are exact (``sh + sl = s`` split) and ``dh_i - m sh`` is
   exact by Sterbenz's lemma; the remainder ``d_i - m S`` is then found within
   ``2**-74 |d_i|`` with four roundings of quantities below ``2**-23 |d_i|``, and
   ``n_i = m + remainder fl(1 / s)`` within ``2**-72.5 |n_i|`` (adding ``2**-74`` from
   ``S``, ``2**-76`` for the two roundings of a correction below ``2**-24.9 |n_i|``, and
   ``2**-75`` for dividing by ``s``, not ``S``).  The
   rounding test (:func:`~reference_impl.ddouble.ziv`) is run with ``2**-72 (s + |r|)``
   and ``2**-71 |m|``, more than twice the bounds.  It fails where ``D`` cancels (near
   touching), and at random with probability about ``2**-18`` per value.
2. **numerator**, pairs whose distance failed and ``r > 0``: ``D = (q - r**2) / (S + r)``
   as in :func:`reference_impl.rounding.sqrt_minus`, free of cancellation.  ``q - r**2``
   is an exact expansion of TwoProducts (factors in the range of
   :func:`~reference_impl.expansion.products_exact`), distilled by two error-free VecSum
   passes; the float sum of all but the last term errs by at most
   ``B = 2k u sum|rest|`` (``k`` terms, an a-posteriori bound).  ``S + r`` is within
   ``2**-73.9`` relative, the double-double quotient adds ``2**-74``, so ``D`` is within
   ``B / (S + r) + 2**-72.2 |D|``; the test runs with twice that.  A pair it cannot
   certify whose expansion sums to exactly zero (exact sign,
   :func:`~reference_impl.expansion.sum_sign`) is touching exactly: ``D = +0.0``.
3. **exact**: every pair still undetermined (ties to a midpoint, results that would be
   subnormal, non-finite inputs, inputs out of range) goes to the pure oracle.

Coincident centres (``d == 0`` exactly) are settled directly: ``distance = 0.0 - fl(ra +
rb)`` (``fl`` of an exact sum is its correct rounding, ``0.0 - x`` turns ``-0.0`` into the
oracle's ``+0.0``), the normal is undefined, and ``hit = fl(ra + rb) > 0``.  The hit
verdict of a settled pair follows from its distance: ``hit = RN(D) < 0 and r > 0``.

Range of stage 1: finite inputs, radii at most ``2**450`` in magnitude, every non-zero
component of ``fl(pb - pa)`` in ``[2**-450, 2**450]``.  Then no product overflows, every
normal component is at least ``2**-902`` (no subnormal result), and every underflow is
at most ``2**-1075`` absolute against quantities above ``2**-1000``, far inside the
bounds' slack; a certified distance is never subnormal either, as its bound
``2**-70 (s + |r|) >= 2**-520`` spans many subnormals.  Pairs outside go to stage 3.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from . import exact
from .ddouble import norm2, split, sqrt_dd, top, vec_sum, ziv
from .expansion import EPS, products_exact, sum_sign, two_product, two_sum
from .types import Contact

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]
IntArray = npt.NDArray[np.intp]

CHUNK = 16384
"""Pairs per block in stage 1: the temporaries of one block stay in cache."""
_LIMIT = 2.0**450
_DISTANCE_ERR = 2.0**-72
"""Stage 1's distance bound, relative to ``s + |r|`` (3.7 times the proven one)."""
_NORMAL_ERR = 2.0**-71
"""Stage 1's normal bound, relative to ``|m|`` (2.8 times the proven one)."""
_TINY_RESULT = 2.0**-1000


@dataclass
class SphereValues:
    """Per pair: ``hit``, ``distance``, ``normal`` (NaN rows where undefined), and the stages.

    ``coincident`` rows have an undefined normal; ``undefined`` rows (non-finite input)
    have no values at all; ``exact_rows`` lists the pairs the pure oracle settled.
    ``stages`` counts pairs settled by each stage (``coincident``, ``double_double``,
    ``numerator``, ``exact``).
    """

    hit: BoolArray
    distance: FloatArray
    normal: FloatArray
    coincident: BoolArray
    undefined: BoolArray
    exact_rows: IntArray
    stages: dict[str, int] = field(default_factory=dict)


def sphere_values(pa: npt.ArrayLike, ra: npt.ArrayLike, pb: npt.ArrayLike,
                  rb: npt.ArrayLike) -> SphereValues:
    """Correctly rounded hit, distance and normal for N sphere pairs (see the module).

    >>> v = sphere_values([[0.0, 0.0]], [1.0], [[3.0, 4.0]], [1.5])
    >>> v.distance.tolist(), v.normal.tolist(), v.hit.tolist()
    ([2.5], [[0.6, 0.8]], [False])
    """
    a, b = _f(pa), _f(pb)
    r1, r2 = _f(ra), _f(rb)
    n, dim = a.shape
    out = SphereValues(np.empty(n, bool), np.empty(n), np.empty((n, dim)),
                       np.zeros(n, bool), np.zeros(n, bool), np.zeros(0, np.intp))
    dist_ok, norm_ok = np.empty(n, bool), np.empty(n, bool)
    for start in range(0, n, CHUNK):
        rows = slice(start, min(start + CHUNK, n))
        _stage_one(a[rows], r1[rows], b[rows], r2[rows], out, rows, dist_ok, norm_ok)
    coincident = int(out.coincident.sum())
    retry = np.flatnonzero(norm_ok & ~dist_ok)  # coincident pairs have neither
    dist, sure = _stage_two(a[retry], r1[retry], b[retry], r2[retry])
    settled = retry[sure]
    out.distance[settled] = dist[sure]
    out.hit[settled] = (dist[sure] < 0) & (r1[settled] + r2[settled] > 0)
    dist_ok[settled] = True
    dist_ok &= norm_ok
    dist_ok |= out.coincident
    out.exact_rows = np.flatnonzero(~dist_ok)
    _stage_three(a, r1, b, r2, out)
    out.stages = {"coincident": coincident,
                  "double_double": n - coincident - len(settled) - len(out.exact_rows),
                  "numerator": len(settled), "exact": len(out.exact_rows)}
    return out


def _f(x: npt.ArrayLike) -> FloatArray:
    return np.ascontiguousarray(x, dtype=np.float64)


def _columns(a: FloatArray, b: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``b`` and ``-a`` transposed to contiguous rows, one per axis."""
    return np.ascontiguousarray(b.T), np.negative(a.T, order="C")


def _screen(r1: FloatArray, r2: FloatArray, dh: FloatArray,
            rh: FloatArray) -> tuple[BoolArray, BoolArray, bool]:
    """Pairs inside stage 1's range, the coincident pairs, and whether zeros occur in ``dh``.

    One reduction per array decides a whole block in the common case (no zero, NaN
    fails every comparison).
    """
    m = np.abs(dh)
    top = max(float(m.max()), float(np.abs(r1).max()), float(np.abs(r2).max()))
    if float(m.min()) >= 1 / _LIMIT and top <= _LIMIT:
        return np.ones(len(rh), dtype=bool), np.zeros(len(rh), dtype=bool), False
    finite = np.isfinite(m).all(axis=0) & np.isfinite(r1) & np.isfinite(r2)
    zero = ~dh.any(axis=0)
    good = (finite & ~zero & ((m == 0) | ((m >= 1 / _LIMIT) & (m <= _LIMIT))).all(axis=0)
            & (np.abs(r1) <= _LIMIT) & (np.abs(r2) <= _LIMIT))
    return good, zero & finite & np.isfinite(rh), True


def _stage_one(a: FloatArray, r1: FloatArray, b: FloatArray, r2: FloatArray,
               out: SphereValues, rows: slice, dist_ok: BoolArray, norm_ok: BoolArray) -> None:
    """Stage 1 on one block of pairs, and the coincident centres (module docstring)."""
    with np.errstate(all="ignore"):
        dh, dl = two_sum(*_columns(a, b))  # shape (dim, m): one contiguous row per axis
        rh, rl = two_sum(r1, r2)
        good, coincident, zeros = _screen(r1, r2, dh, rh)
        s, c = sqrt_dd(*norm2(dh, dl))
        big, t = two_sum(s, -rh)
        t += c
        t -= rl
        dist, ok = ziv(big, t, _DISTANCE_ERR * (s + np.abs(rh)))
        dist_ok[rows] = good & ok
        ok, out.normal[rows] = _normal(dh, dl, s, c, zeros)
        norm_ok[rows] = good & ok
        out.hit[rows] = (dist < 0) & (rh > 0)  # a certified distance decides the verdict
        if zeros:
            dist[coincident] = 0.0 - rh[coincident]
            out.coincident[rows] = coincident
            out.hit[rows] |= coincident & (rh > 0)
            out.normal[rows][coincident] = np.nan
        out.distance[rows] = dist


def _normal(dh: FloatArray, dl: FloatArray, s: FloatArray, c: FloatArray,
            zeros: bool) -> tuple[BoolArray, FloatArray]:
    """Whether all axes are certain, and ``d / (s + c)`` rounded (``+0.0`` for 0), ``(m, dim)``.

    One axis at a time: rows of length ``m`` stay in cache, unlike ``(dim, m)`` blocks.
    """
    sh, sl = split(s)
    inverse = 1.0 / s
    normal = np.empty((dh.shape[1], dh.shape[0]))
    ok = np.ones(dh.shape[1], dtype=bool)
    for j in range(dh.shape[0]):
        m = top(dh[j] * inverse)  # 26 bits: m * sh and m * sl are exact
        rho = dh[j] - m * sh  # exact: Sterbenz
        rho -= m * sl
        rho += dl[j]
        rho -= m * c
        rho *= inverse
        value, sure = ziv(m, rho, _NORMAL_ERR * np.abs(m))
        if zeros:
            value += 0.0
            sure |= dh[j] == 0
        normal[:, j] = value
        ok &= sure
    return ok, normal


def _stage_two(a: FloatArray, r1: FloatArray, b: FloatArray,
               r2: FloatArray) -> tuple[FloatArray, BoolArray]:
    """Stage 2: ``(q - r**2) / (S + r)`` for the pairs given; values and which are certain."""
    with np.errstate(all="ignore"):
        dh, dl = two_sum(*_columns(a, b))
        rh, rl = two_sum(r1, r2)
        usable = (rh > 0) & products_exact(dh.T, dl.T, rh, rl)
        num = vec_sum(vec_sum(_numerator_terms(dh, dl, rh, rl)))
        rest = num[:-1].sum(axis=0)
        bound = (2 * num.shape[0] * EPS) * np.abs(num[:-1]).sum(axis=0)
        nh, nl = two_sum(num[-1], rest)
        s, c = sqrt_dd(*norm2(dh, dl))
        gh, g = two_sum(s, rh)
        gl = (g + c) + rl
        quot = nh / gh
        p, pe = two_product(quot, gh)
        rho = ((nh - p) - pe + nl) - quot * gl
        dist, ok = ziv(quot, rho / gh, 2 * bound / gh + 2.0**-69 * np.abs(quot))
        ok &= (np.abs(nh) >= 2.0**-900) & (np.abs(dist) >= _TINY_RESULT)
        zero = np.zeros_like(ok)
        rows = np.flatnonzero(usable & ~ok)
        zero[rows] = sum_sign(num[:, rows]) == 0  # touching exactly: q == r**2
        dist[zero] = 0.0
    return dist, usable & (ok | zero)


def _numerator_terms(dh: FloatArray, dl: FloatArray, rh: FloatArray,
                     rl: FloatArray) -> FloatArray:
    """Floats (k, m) whose column sums are exactly ``|dh + dl|**2 - (rh + rl)**2``."""
    terms: list[FloatArray] = []
    for h, lo, sign in [*((dh[j], dl[j], 1.0) for j in range(dh.shape[0])), (rh, rl, -1.0)]:
        for x, y in ((h, h), (h + h, lo), (lo, lo)):
            terms.extend(sign * t for t in two_product(x, y))
    return np.array(terms)


def _stage_three(a: FloatArray, r1: FloatArray, b: FloatArray, r2: FloatArray,
                 out: SphereValues) -> None:
    """The pure oracle for every pair left: its values overwrite the batch's."""
    for i in out.exact_rows.tolist():
        c = exact.sphere_contact(a[i].tolist(), float(r1[i]), b[i].tolist(), float(r2[i]))
        out.normal[i] = np.nan
        if not isinstance(c, Contact):
            out.undefined[i], out.distance[i], out.hit[i] = True, np.nan, False
            continue
        out.hit[i], out.distance[i] = c.hit, c.distance
        out.coincident[i] = not isinstance(c.normal, tuple)
        if isinstance(c.normal, tuple):
            out.normal[i] = c.normal


def naive_values(pa: FloatArray, ra: FloatArray, pb: FloatArray,
                 rb: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The textbook float64 formula: ``|d| - (ra + rb)`` and ``d / |d|``, ``d = pb - pa``."""
    d = pb - pa
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    return length - (ra + rb), d / length[:, None]


def same_as_oracle(v: SphereValues, x: tuple[FloatArray, ...], i: int) -> bool:
    """Whether pair ``i`` of ``v`` equals the pure oracle bit for bit (signed zeros too)."""
    a, r1, b, r2 = x
    c = exact.sphere_contact(a[i].tolist(), float(r1[i]), b[i].tolist(), float(r2[i]))
    if not isinstance(c, Contact):
        return bool(v.undefined[i])
    got = [v.distance[i], *(v.normal[i] if isinstance(c.normal, tuple) else [])]
    want = [c.distance, *(c.normal if isinstance(c.normal, tuple) else [])]
    return (bool(v.hit[i]) == c.hit and bool(v.coincident[i]) != isinstance(c.normal, tuple)
            and np.array_equal(np.asarray(got).view(np.int64), np.asarray(want).view(np.int64)))
