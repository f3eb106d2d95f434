"""Vectorized exact verdicts for N pairs: float64 filter, exact rational fallback.

Inputs are float64 arrays of shape ``(N, dim)`` (``dim`` 2 or 3) for centres and
AABB half-widths, shape ``(N,)`` for radii.  Verdicts equal :mod:`reference_impl.exact`
pair for pair.  As in Shewchuk's adaptive predicates, each pair is decided in
float64 when a rigorous forward-error bound proves the sign; otherwise (and for
non-finite inputs) it is decided in :class:`fractions.Fraction`.

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
``r = ra+rb``).  Float path: ``Q = fl(sum fl(fl(pb_i-pa_i)**2))`` left to right,
``R = fl(ra+rb)``, ``RR = fl(R*R)``.  Each term of ``Q`` carries one rounding
from the difference (squared: two factors), one from the square and at most
``n-1 <= 2`` from the additions; all terms are >= 0, so
``|Q - q| <= g5*q + 2**-1072`` with ``g_k = k*u/(1-k*u)``; likewise
``|RR - r**2| <= g3*r**2 + 2**-1074``.  Hence
``|(Q - RR) - (q - r**2)| <= g5*(q + r**2) + 2**-1071``.  Instead of forming
``Q - RR`` (another rounding) the filter compares relatively, with
``L = 1 - 2**-49 = 1 - 16u`` and ``H = 1 + 16u`` (exact doubles):

* hit if ``R > 0`` and ``Q < fl(RR*L)``: then ``q <= (Q + 2**-1072)/(1-g5)`` and
  ``r**2 >= (RR - 2**-1074)/(1+g3)`` give ``q/r**2 <= L(1+u)(1+g3)/(1-g5) + 2**-170
  < 1 - 11u + 2**-170 < 1`` (``R > 0`` iff ``r > 0``: ``fl`` keeps signs and zero);
* not a hit if ``Q >= fl(RR*H)``: symmetrically ``q/r**2 >= H(1-u)(1-g3)/(1+g5)
  - 2**-170 > 1 + 7u > 1``;

both valid when ``2**-900 <= RR <= 2**1000`` (the absolute underflow terms are
then below ``2**-170 * RR``; ``RR*H`` cannot overflow, and ``Q = inf`` means
``q >= 2**1023 > r**2``).  Pairs outside that range, with ``R <= 0`` or NaN, or in
the band ``fl(RR*L) <= Q < fl(RR*H)`` (about 16 ulps of ``r**2`` wide) fall back.

Non-finite inputs make the float quantities NaN/inf, so they always fall back;
the exact path then reports ``hit=False`` and sets ``undefined`` (the oracle's
:class:`~reference_impl.types.Undefined`).  Distances need a square root
correctly rounded to the last bit, which no float64 bound of a few ulps can
certify, so :func:`aabb_distances` / :func:`sphere_distances` evaluate every pair
with the exact oracle (NaN for undefined); they are vectorized in interface only.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
import numpy.typing as npt

from . import exact
from .types import Contact

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

_L = 1.0 - 2.0**-49
_H = 1.0 + 2.0**-49
_TINY = 2.0**-900
_HUGE = 2.0**1000


@dataclass(frozen=True)
class BatchResult:
    """Verdicts, the pairs with non-finite inputs, and how many pairs fell back."""

    hit: BoolArray
    undefined: BoolArray
    fallbacks: int


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


def _resolve(hit: BoolArray, undecided: BoolArray,
             decide: Callable[[int], bool | None]) -> BatchResult:
    undefined = np.zeros(hit.shape, dtype=bool)
    idx = np.flatnonzero(undecided)
    for i in idx.tolist():
        verdict = decide(i)
        hit[i] = bool(verdict)
        undefined[i] = verdict is None
    return BatchResult(hit, undefined, len(idx))


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
    undecided = np.flatnonzero(undecided_mask)
    hit[undecided], rest = _aabb_two_sum(a[undecided], h[undecided], b[undecided], k[undecided])
    todo = np.zeros(hit.shape, dtype=bool)
    todo[undecided[rest]] = True
    return _resolve(hit, todo, lambda i: _exact_aabb(a[i], h[i], b[i], k[i]))


def _two_sum(x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Knuth's TwoSum: ``x + y == s + e`` exactly (no overflow)."""
    s = x + y
    bv = s - x
    return s, (x - (s - bv)) + (y - bv)


def _aabb_two_sum(a: FloatArray, h: FloatArray, b: FloatArray,
                  k: FloatArray) -> tuple[BoolArray, BoolArray]:
    """Second, still exact, stage for the pairs with ``D == S`` on some axis.

    TwoSum gives ``cb - ca = dh + dl`` and ``ha + hb = sh + sl`` exactly; where
    ``|dh| == sh``, ``|cb-ca| - (ha+hb) = sign(dh)*dl - sl`` exactly, and comparing
    the two floats ``sign(dh)*dl`` and ``sl`` is exact.  Returns the verdicts and
    the pairs left for Fractions (non-finite or near-overflow values).
    """
    with np.errstate(all="ignore"):
        dh, dl = _two_sum(b, -a)
        sh, sl = _two_sum(h, k)
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
        d = np.subtract(b, a)
        np.multiply(d, d, out=d)
        q = d[:, 0] + d[:, 1]
        for j in range(2, d.shape[1]):
            q += d[:, j]
        r = r1 + r2
        rr = r * r
        hit = q < rr * _L
        undecided = q < rr * _H
        undecided &= ~hit
        if not math.isfinite(float(q.sum())):  # non-finite inputs (or overflow) fall back
            undecided |= ~np.isfinite(q)
        if not (r.min(initial=1.0) > 0 and rr.min(initial=1.0) >= _TINY
                and rr.max(initial=1.0) <= _HUGE):
            undecided |= ~((r > 0) & (rr >= _TINY) & (rr <= _HUGE))
    return _resolve(hit, undecided, lambda i: _exact_sphere(a[i], r1[i], b[i], r2[i]))


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
    """``n`` pairs within ``max_ulps`` ulps of touching along one axis.

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


def _best(f: Callable[[], object]) -> float:
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def bench_batch(n: int = 1_000_000, near_fraction: float = 0.01, seed: int = 0,
                kind: str = "aabb", dim: int = 3) -> dict[str, float]:
    """Time the batch path against the naive formula and check it against the oracle."""
    rng = np.random.default_rng(seed)
    m = int(n * near_fraction)
    near = near_pairs(kind, m, dim, rng)
    far = near_pairs(kind, n - m, dim, rng, max_ulps=0)
    far[2][:] = far[0] + rng.uniform(-15, 15, far[0].shape)
    x = tuple(np.ascontiguousarray(np.concatenate([p, q])) for p, q in zip(near, far, strict=True))
    batch = aabb_batch if kind == "aabb" else sphere_batch
    naive = naive_aabb_verdicts if kind == "aabb" else naive_sphere_verdicts
    t_batch = _best(lambda: batch(*x))
    t_naive = _best(lambda: naive(*x))
    result = batch(*x)
    sample = np.concatenate([np.arange(m), rng.choice(np.arange(m, n), min(10_000, n - m),
                                                      replace=False)])
    agree = sum(bool(result.hit[i]) == oracle(kind, x, i) for i in sample.tolist())
    naive_hit = naive(*x)
    return {"batch_pairs_per_s": n / t_batch, "naive_pairs_per_s": n / t_naive,
            "ratio": t_naive / t_batch, "fallbacks": result.fallbacks,
            "checked": len(sample), "agreement": agree / len(sample),
            "naive_wrong_near": float(sum(bool(naive_hit[i]) != oracle(kind, x, i)
                                          for i in range(m)))}
