"""Vectorized exact verdicts for N pairs: float64 filter, exact rational fallback.

Inputs are float64 arrays of shape ``(N, dim)`` (``dim`` 2 or 3) for centres and
AABB half-widths, shape ``(N,)`` for radii.  Verdicts equal :mod:`reference_impl.exact`
pair for pair.  As in Shewchuk's adaptive predicates, each pair is decided in
float64 when a rigorous forward-error bound proves the sign; otherwise (and for
non-finite inputs) it is decided by an exact second stage.

Notation: ``fl`` is round-to-nearest-even, ``u = 2**-53``.  ``fl`` is *monotone*
(``x <= y`` implies ``fl(x) <= fl(y)``, overflow to ``inf`` included), odd
(``fl(-x) = -fl(x)``), and with gradual underflow a sum of two floats is exact
whenever it is subnormal; a product obeys ``fl(xy) = xy(1+d) + e``, ``|d| <= u``,
``|e| <= 2**-1075``.

AABB (touching overlaps; on each axis ``|cb-ca| <= ha+hb``).  The float path
compares ``D = fl(|fl(cb-ca)|) = fl(|cb-ca|)`` with ``S = fl(ha+hb)``, each one
rounding of the exact operand, so ``|D - |cb-ca|| <= ulp(D)/2`` and
``|S - (ha+hb)| <= ulp(S)/2``: the computed ``D - S`` is within one ulp of the
operands' magnitude of the true value.  Sharper, by monotonicity:
``D < S`` implies ``|cb-ca| < ha+hb`` and ``D > S`` implies ``|cb-ca| > ha+hb``
(if the exact order were the other way, rounding both sides would keep it).  So
the sign is wrong only when ``D == S`` (the band of width <= 1 ulp around 0), or
NaN.  A pair is a hit if ``D < S`` on every axis, apart if ``D > S`` on some axis,
else it falls back.  No range guard is needed (overflow is monotone).

Spheres (strict: hit iff ``ra+rb > 0`` and ``q < r**2``, ``q = sum (pb-pa)_i**2``,
``r = ra+rb``).  Float path: ``Q = fl(sum fl(fl(pb_i-pa_i)**2))`` (numpy's ``einsum``;
any order, fused multiply-adds or not: each term meets at most five roundings),
``R = fl(ra+rb)``, ``RR = fl(R*R)``.  All terms are >= 0, so
``|Q - q| <= g5*q + 2**-1072`` with ``g_k = k*u/(1-k*u)``, and
``|RR - r**2| <= g3*r**2 + 2**-1074``.  The filter counts the doubles between
``Q`` and ``RR``: for non-negative doubles the int64 bit patterns are ordered like
the values and consecutive doubles differ by one, so ``k = bits(Q) - bits(RR)``
is that count.  Near ``RR`` consecutive doubles are at least ``RR*u`` apart above
it and ``RR*u/2`` below it, so:

* hit if ``R > 0`` and ``k <= -32``: then ``Q <= RR(1 - 16u)`` and
  ``q/r**2 <= (1 - 16u)(1+g3)/(1-g5) + 2**-170 < 1 - 7u < 1`` (``R > 0`` iff
  ``r > 0``: ``fl`` keeps signs and zero);
* not a hit if ``k >= 32``: then ``Q >= RR(1 + 32u)`` and
  ``q/r**2 >= (1 + 32u)(1-g3)/(1+g5) - 2**-170 > 1``;

both valid when ``2**-900 <= RR <= 2**1000`` (the absolute underflow terms are
then below ``2**-170 * RR``).  Pairs outside that range, with NaN, or in the band
``|k| < 32`` go to a second stage that is still exact and vectorized
(:func:`_sphere_expansion`: TwoSum, TwoProduct and an exact sign of the sum);
only pairs whose factors leave its range (non-finite, or below ``2**-480``) fall
back to Fractions.

Non-finite inputs make the float quantities NaN/inf, so they always fall back;
the exact path then reports ``hit=False`` and sets ``undefined`` (the oracle's
:class:`~reference_impl.types.Undefined`).  Distances need a square root
correctly rounded to the last bit, which no float64 bound of a few ulps can
certify, so :func:`aabb_distances` / :func:`sphere_distances` evaluate every pair
with the exact oracle (NaN for undefined); they are vectorized in interface only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
import numpy.typing as npt

from . import exact
from .expansion import products_exact, sum_sign, two_product, two_sum
from .types import Contact

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

_BAND = 32
"""Sphere filter half-width in ulps of ``RR`` (see the module docstring)."""
_TINY = 2.0**-900
_HUGE = 2.0**1000


@dataclass(frozen=True)
class BatchResult:
    """Verdicts, the pairs with non-finite inputs, and how each stage was used.

    ``refined`` pairs were left undecided by the float filter and settled by the
    exact vectorized second stage; ``fallbacks`` of them (non-finite or out of
    range) went on to Fractions.
    """

    hit: BoolArray
    undefined: BoolArray
    fallbacks: int
    refined: int = 0


def _f(x: npt.ArrayLike) -> FloatArray:
    return np.ascontiguousarray(x, dtype=np.float64)


def _exact_aabb(ca: FloatArray, ha: FloatArray, cb: FloatArray, hb: FloatArray) -> bool | None:
    if not all(math.isfinite(x) for v in (ca, ha, cb, hb) for x in v.tolist()):
        return None
    return all(
        abs(Fraction(b) - Fraction(a)) <= Fraction(h) + Fraction(k)
        for a, h, b, k in zip(ca.tolist(), ha.tolist(), cb.tolist(), hb.tolist(), strict=True)
    )


def _exact_sphere(pa: FloatArray, ra: float, pb: FloatArray, rb: float) -> bool | None:
    if not all(math.isfinite(x) for x in [*pa.tolist(), ra, *pb.tolist(), rb]):
        return None
    q = sum((Fraction(b) - Fraction(a)) ** 2 for a, b in zip(pa.tolist(), pb.tolist(), strict=True))
    r = Fraction(ra) + Fraction(rb)
    return r > 0 and q < r * r


def _settle(hit: BoolArray, undecided: BoolArray,
            refine: Callable[[npt.NDArray[np.intp]], tuple[BoolArray, BoolArray]],
            decide: Callable[[int], bool | None]) -> BatchResult:
    """Give the filter's undecided pairs to ``refine`` (the exact vectorized stage),
    and the pairs it leaves to ``decide`` (Fractions, one by one)."""
    idx = np.flatnonzero(undecided)
    hit[idx], rest = refine(idx)
    undefined = np.zeros(hit.shape, dtype=bool)
    left = idx[rest]
    for i in left.tolist():
        verdict = decide(i)
        hit[i] = bool(verdict)
        undefined[i] = verdict is None
    return BatchResult(hit, undefined, len(left), len(idx))


def aabb_batch(
    ca: npt.ArrayLike, ha: npt.ArrayLike, cb: npt.ArrayLike, hb: npt.ArrayLike
) -> BatchResult:
    """Exact AABB verdicts (touching overlaps) for N pairs, with fallback details.

    >>> r = aabb_batch([[0.0, 0.0]], [[0.8, 1.0]], [[1.2000000000000002, 0.0]], [[0.4, 1.0]])
    >>> r.hit.tolist(), r.fallbacks
    ([False], 0)
    """
    a, h, b, k = _f(ca), _f(ha), _f(cb), _f(hb)
    with np.errstate(all="ignore"):
        d = np.subtract(b, a)
        np.abs(d, out=d)
        s = np.add(h, k)
        lt, gt = d < s, d > s
        hit = lt[:, 0] & lt[:, 1]
        apart = gt[:, 0] | gt[:, 1]
        for j in range(2, d.shape[1]):
            hit &= lt[:, j]
            apart |= gt[:, j]
        undecided_mask = ~(hit | apart)
        if not math.isfinite(float(d.sum()) + float(s.sum())):  # inputs may be non-finite
            undecided_mask |= ~(np.isfinite(d).all(axis=1) & np.isfinite(s).all(axis=1))
    return _settle(hit, undecided_mask,
                   lambda idx: _aabb_two_sum(a[idx], h[idx], b[idx], k[idx]),
                   lambda i: _exact_aabb(a[i], h[i], b[i], k[i]))


def _aabb_two_sum(a: FloatArray, h: FloatArray, b: FloatArray,
                  k: FloatArray) -> tuple[BoolArray, BoolArray]:
    """Second, still exact, stage for the pairs with ``D == S`` on some axis.

    TwoSum gives ``cb - ca = dh + dl`` and ``ha + hb = sh + sl`` exactly; where
    ``|dh| == sh``, ``|cb-ca| - (ha+hb) = sign(dh)*dl - sl`` exactly, and comparing
    the two floats ``sign(dh)*dl`` and ``sl`` is exact.  Returns the verdicts and
    the pairs left for Fractions (non-finite or near-overflow values).
    """
    with np.errstate(all="ignore"):
        dh, dl = two_sum(b, -a)
        sh, sl = two_sum(h, k)
        big = np.abs(dh)
        tail = np.sign(dh) * dl
        ok = (big < sh) | ((big == sh) & (tail <= sl))
        safe = (big <= 2.0**1020) & (np.abs(sh) <= 2.0**1020)
    return np.asarray(ok.all(axis=1)), np.asarray(~safe.all(axis=1))


def sphere_batch(
    pa: npt.ArrayLike, ra: npt.ArrayLike, pb: npt.ArrayLike, rb: npt.ArrayLike
) -> BatchResult:
    """Exact sphere verdicts (strict ``<``) for N pairs, with fallback details.

    >>> sphere_batch([[0.75, 0.0]], [0.6], [[2.05, 0.0]], [0.7]).hit.tolist()
    [True]
    """
    a, b, r1, r2 = _f(pa), _f(pb), _f(ra), _f(rb)
    with np.errstate(all="ignore"):
        d = b - a
        q = np.einsum("ij,ij->i", d, d)
        rr = r1 + r2
        not_positive = None if rr.min(initial=1.0) > 0 else ~(rr > 0)
        np.multiply(rr, rr, out=rr)  # in place: fewer fresh pages to fault in
        out_of_range = None
        if not (math.isfinite(float(q.sum())) and rr.min(initial=1.0) >= _TINY
                and rr.max(initial=1.0) <= _HUGE):
            out_of_range = ~(np.isfinite(q) & (rr >= _TINY) & (rr <= _HUGE))
        step = q.view(np.int64)
        step -= rr.view(np.int64)  # doubles from RR to Q (both are >= 0)
        hit = step <= -_BAND
        step += _BAND - 1
        undecided = step.view(np.uint64) < 2 * _BAND - 1
        if not_positive is not None:
            hit &= ~not_positive
        if out_of_range is not None:
            undecided |= out_of_range
    return _settle(hit, undecided,
                   lambda idx: _sphere_expansion(a[idx], r1[idx], b[idx], r2[idx]),
                   lambda i: _exact_sphere(a[i], r1[i], b[i], r2[i]))


def _sphere_expansion(a: FloatArray, r1: FloatArray, b: FloatArray,
                      r2: FloatArray) -> tuple[BoolArray, BoolArray]:
    """Second, still exact, stage: the sign of ``q - r**2`` as a sum of exact terms.

    TwoSum splits ``pb_i - pa_i = dh + dl`` and ``ra + rb = rh + rl`` exactly; then
    ``(dh + dl)**2 = dh*dh + 2dh*dl + dl*dl`` and likewise for ``r``, each product
    split exactly by TwoProduct, so ``q - r**2`` is a sum of floats whose sign
    :func:`~reference_impl.expansion.sum_sign` finds exactly.  The terms of a zero
    ``dl`` or ``rl`` vanish, so pairs are grouped by which tails are zero and each
    group sums only the terms it has (most differences and many radius sums are
    exact).  Returns the verdicts and the pairs left for Fractions (non-finite
    inputs, factors outside :func:`~reference_impl.expansion.products_exact`'s range).
    """
    hit = np.zeros(len(a), dtype=bool)
    with np.errstate(all="ignore"):
        dh, dl = two_sum(b, -a)
        rh, rl = two_sum(r1, r2)
        ok = products_exact(dh, dl, rh, rl)
        d_tail, r_tail = (dl != 0).any(axis=1), rl != 0
        for has_d in (False, True):
            for has_r in (False, True):
                rows = np.flatnonzero(ok & (d_tail == has_d) & (r_tail == has_r))
                if rows.size:
                    terms = np.concatenate(
                        [*_square(dh[rows].T, dl[rows].T, has_d),
                         *(-t for t in _square(rh[None, rows], rl[None, rows], has_r))])
                    hit[rows] = (rh[rows] > 0) & (sum_sign(terms) < 0)
    return hit, ~ok


def _square(h: FloatArray, lo: FloatArray, tail: bool) -> tuple[FloatArray, ...]:
    """Arrays (k, N) whose sum down axis 0 is exactly ``sum_i (h_i + lo_i)**2``.

    Without ``tail`` the caller guarantees ``lo == 0``, and only ``h*h`` is split.
    """
    if not tail:
        return two_product(h, h)
    return (*two_product(h, h), *two_product(2.0 * h, lo), *two_product(lo, lo))


def aabb_verdicts(ca: npt.ArrayLike, ha: npt.ArrayLike, cb: npt.ArrayLike,
                  hb: npt.ArrayLike) -> BoolArray:
    """Exact AABB verdicts (False where an input is non-finite; see :func:`aabb_batch`)."""
    return aabb_batch(ca, ha, cb, hb).hit


def sphere_verdicts(pa: npt.ArrayLike, ra: npt.ArrayLike, pb: npt.ArrayLike,
                    rb: npt.ArrayLike) -> BoolArray:
    """Exact sphere verdicts (False where an input is non-finite; see :func:`sphere_batch`)."""
    return sphere_batch(pa, ra, pb, rb).hit


def naive_aabb_verdicts(ca: FloatArray, ha: FloatArray, cb: FloatArray,
                        hb: FloatArray) -> BoolArray:
    """The textbook AABB test in plain numpy float64 (rounding included)."""
    return np.asarray(np.all(np.abs(cb - ca) <= ha + hb, axis=1))


def naive_sphere_verdicts(pa: FloatArray, ra: FloatArray, pb: FloatArray,
                          rb: FloatArray) -> BoolArray:
    """The textbook sphere test in plain numpy float64: ``|pb - pa| < ra + rb``."""
    d = pa - pb
    return np.asarray(np.sqrt(np.einsum("ij,ij->i", d, d)) < ra + rb)


def _distance(c: Any) -> float:
    return c.distance if isinstance(c, Contact) else math.nan


def aabb_distances(ca: npt.ArrayLike, ha: npt.ArrayLike, cb: npt.ArrayLike,
                   hb: npt.ArrayLike) -> FloatArray:
    """Correctly rounded signed AABB distances (exact oracle per pair; NaN if undefined)."""
    a, h, b, k = _f(ca), _f(ha), _f(cb), _f(hb)
    return np.array([_distance(exact.aabb_contact(*(v[i].tolist() for v in (a, h, b, k))))
                     for i in range(len(a))], dtype=np.float64)


def sphere_distances(pa: npt.ArrayLike, ra: npt.ArrayLike, pb: npt.ArrayLike,
                     rb: npt.ArrayLike) -> FloatArray:
    """Correctly rounded signed sphere distances (exact oracle per pair; NaN if undefined)."""
    a, b, r1, r2 = _f(pa), _f(pb), _f(ra), _f(rb)
    return np.array([_distance(exact.sphere_contact(a[i].tolist(), float(r1[i]),
                                                    b[i].tolist(), float(r2[i])))
                     for i in range(len(a))], dtype=np.float64)


def near_pairs(kind: str, n: int, dim: int, rng: np.random.Generator, scale: float = 1.0,
               offset: float = 0.0, max_ulps: int = 3) -> tuple[FloatArray, ...]:
    """``n`` pairs within ``max_ulps`` ulps of touching along one axis: the hard cases the
    batch paths are checked on (their tests, and the bench's figures in
    ``crosscheck/studies/bench/oracle.py``).

    B's centre on that axis is ``fl(A + fl(ha + hb))`` (or ``fl(ra + rb)``), nudged
    by ``k`` ulps (``-max_ulps <= k <= max_ulps``) with :func:`numpy.nextafter`.
    Returns ``(ca, ha, cb, hb)`` or ``(pa, ra, pb, rb)``.
    """
    a = offset + scale * rng.uniform(-10, 10, (n, dim))
    size = (n, dim) if kind == "aabb" else (n,)
    h, k = scale * rng.uniform(0.1, 5, size), scale * rng.uniform(0.1, 5, size)
    b = a + (scale * rng.uniform(-0.05, 0.05, (n, dim)) if kind == "aabb" else 0.0)
    axis = rng.integers(0, dim, n)
    rows = np.arange(n)
    touch = (h + k)[rows, axis] if kind == "aabb" else h + k
    sign = rng.choice([-1.0, 1.0], n)
    b[rows, axis] = a[rows, axis] + sign * touch
    steps = rng.integers(-max_ulps, max_ulps + 1, n)
    for _ in range(max_ulps):
        col = b[rows, axis]
        col = np.where(steps > 0, np.nextafter(col, np.inf), col)
        col = np.where(steps < 0, np.nextafter(col, -np.inf), col)
        b[rows, axis] = col
        steps -= np.sign(steps)
    return a, h, b, k


def oracle(kind: str, x: tuple[FloatArray, ...], i: int) -> bool:
    """The pure exact oracle's verdict for pair ``i`` (Undefined counts as False)."""
    a, h, b, k = (v[i].tolist() for v in x)
    c = exact.aabb_contact(a, h, b, k) if kind == "aabb" else exact.sphere_contact(a, h, b, k)
    return isinstance(c, Contact) and c.hit
