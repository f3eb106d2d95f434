"""Double-double kernels in numpy float64, each with a stated error, and Ziv's rounding test.

These are the building blocks of :mod:`reference_impl.batch_values`: a value is carried
as an unevaluated sum ``hi + lo`` of two doubles, computed with error-free transformations
(exact) or with cheap variants whose error is small and bounded.  That is enough: the
rounding test needs an error far below half an ulp, not a full 106-bit result.

Notation: ``u = 2**-53``; ``fl`` is round-to-nearest-even and monotone.  All statements
assume no overflow, and count an underflow as at most ``2**-1075`` absolute per
operation; callers keep their inputs in a range where that is negligible (see
:mod:`reference_impl.batch_values`).

* :func:`split` cuts ``x`` into ``hi``, its top 26 significant bits (the low 27 bits of the
  bit pattern masked off), and ``lo = x - hi`` (exact, ``|lo| < 2**-25 |x|``).  A product
  of ``hi`` with a double of at most 27 significant bits is exact (at most 53 bits).
* :func:`square` gives ``x*x = big + small``: ``big = hi*hi`` exact, and
  ``small = fl(lo * fl(hi + x))`` approximates ``2 hi lo + lo**2 = lo (hi + x)`` within
  ``2**-76 x*x`` (two roundings, of ``hi + x`` (``<= 2u |x|``, times ``|lo|``) and of a
  product at most ``2**-23 x*x``).
* :func:`ziv` is the rounding test for an absolute bound: given ``hi + lo`` and ``err``,
  at least twice a proven bound on its distance to the true real ``v``, it returns
  ``fl(hi + fl(lo - err))`` and whether that equals ``fl(hi + fl(lo + err))``.  The
  roundings of ``lo +- err`` (at most ``u (|lo| + err)``) stay below ``err / 2`` when
  ``|lo| <= 2**50 err``, so ``v`` lies between the two ends; ``fl`` is monotone, so if
  both ends round to the same double, so does ``v``.  A zero's sign is not compared:
  callers either exclude zero results or fix the sign themselves.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from .expansion import two_sum

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

_LOW27 = np.int64(-(1 << 27))


def split(x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(hi, lo)``: ``hi`` keeps the top 26 significant bits of ``x``, ``lo = x - hi`` exactly.

    >>> hi, lo = split(np.array([1.0 + 2.0**-40]))
    >>> float(hi[0]), float(lo[0]) == 2.0**-40
    (1.0, True)
    """
    hi = top(x)
    return hi, x - hi


def top(x: FloatArray) -> FloatArray:
    """The top 26 significant bits of ``x`` (truncated towards zero), as in :func:`split`."""
    hi: FloatArray = (x.view(np.int64) & _LOW27).view(np.float64)
    return hi


def square(x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(big, small, hi)``: ``x*x = big + small`` within ``2**-76 x*x``; ``hi`` from :func:`split`.

    >>> big, small, _ = square(np.array([1.0 + 2.0**-30]))
    >>> float(big[0]) == 1.0, float(small[0]) == 2.0**-29 + 2.0**-60
    (True, True)
    """
    hi, lo = split(x)
    small = hi + x
    small *= lo
    return hi * hi, small, hi


def vec_sum(terms: FloatArray) -> FloatArray:
    """One error-free pass of cascaded TwoSum down axis 0 (Ogita, Rump and Oishi's VecSum).

    The column sums are unchanged exactly; the last row becomes the float sum and the
    others its rounding errors, so the mass moves into the last row.
    """
    p = terms.copy()
    for i in range(1, p.shape[0]):
        p[i], p[i - 1] = two_sum(p[i], p[i - 1])
    return p


def ziv(hi: FloatArray, lo: FloatArray, err: FloatArray) -> tuple[FloatArray, BoolArray]:
    """The candidate double for ``hi + lo`` (within ``err / 2``) and whether it is certain.

    >>> x, ok = ziv(np.array([1.0, 1.0]), np.array([2.0**-60, 2.0**-53]),
    ...             np.array([2.0**-70, 2.0**-70]))
    >>> x.tolist(), ok.tolist()
    ([1.0, 1.0], [True, False])
    """
    below = lo - err
    below += hi
    above = lo + err
    above += hi
    return below, below == above



def fast_two_sum(hi: FloatArray, lo: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Renormalise: ``(s, e)``, ``s + e == hi + lo`` exactly, given ``|hi| >= |lo|`` (Fast2Sum)."""
    s = hi + lo
    return s, lo - (s - hi)


def mul(ah: FloatArray, al: FloatArray, bh: FloatArray,
        bl: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(ah + al)(bh + bl)`` renormalised, within ``2**-75 |ab|``; inputs with ``|lo| <= u |hi|``.

    ``ah*bh = p + e`` as in :func:`split` (``ahh*bhh - p`` exact by Sterbenz, ``ahh*bhl``
    exact, ``ahl*bh`` one rounding of at most ``2**-25 |ab|``); ``ah*bl + al*bh`` is
    rounded on at most ``2u |ab|`` and ``al*bl <= u**2 |ab|`` is dropped.
    """
    p = ah * bh
    ahh, ahl = split(ah)
    bhh, bhl = split(bh)
    e = ahh * bhh - p
    e += ahh * bhl
    e += ahl * bh
    e += ah * bl + al * bh
    return fast_two_sum(p, e)


def div(ah: FloatArray, al: FloatArray, bh: FloatArray,
        bl: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(ah + al) / (bh + bl)`` renormalised, within ``2**-74 |a/b|``; inputs as for :func:`mul`.

    ``q = fl(ah/bh)``; the remainder ``a - q b`` is ``(ah - qbh) - e + al - q bl`` with
    ``q bh = P + e`` split as in :func:`mul` (``ah - P`` exact by Sterbenz), and one
    correction ``remainder / bh`` is added.
    """
    q = ah / bh
    p = q * bh
    qh, ql = split(q)
    bhh, bhl = split(bh)
    e = qh * bhh - p
    e += qh * bhl
    e += ql * bh
    r = ah - p
    r -= e
    r += al
    r -= q * bl
    r /= bh
    return fast_two_sum(q, r)


def norm2(dh: FloatArray, dl: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``q = sum_i (dh_i + dl_i)**2`` as ``qh + ql`` (``|ql| <= u qh``), within ``2**-73.9 q``.

    Rows of ``dh``, ``dl`` are axes; ``|dl| <= u |dh|`` (a TwoSum).  The squares ``hi**2``
    of :func:`square` are summed by TwoSum (exact); the float sum ``ql`` of their small
    parts (each at most ``2**-24 dh**2``, within ``2**-76``), the TwoSum errors and
    ``2 sum dh dl`` errs by at most ``6u 2**-24 q``; ``dl**2 <= u**2 dh**2`` is dropped.
    """
    qh, ql, _ = square(dh[0])
    cross = dh[0] * dl[0]
    for j in range(1, dh.shape[0]):
        big, small, _ = square(dh[j])
        qh, t = two_sum(qh, big)
        ql += small
        ql += t
        cross += dh[j] * dl[j]
    ql += cross + cross
    total = qh + ql  # Fast2Sum: |qh| >= |ql|
    ql -= total - qh
    return total, ql


def sqrt_dd(qh: FloatArray, ql: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``sqrt(qh + ql)`` as ``s + c`` within ``2**-75.3 s``, for ``|ql| <= u qh``.

    ``s = fl(sqrt(qh))``, ``c = (qh - s**2 + ql) / 2s`` with ``s**2`` from :func:`square`
    (``qh - hi**2`` exact by Sterbenz); the residual is at most ``3u q``, so the dropped
    second-order Newton term is below ``2**-104 s``.
    """
    s = np.sqrt(qh)
    big, small, _ = square(s)
    res = qh - big  # exact: Sterbenz
    res -= small
    res += ql
    res /= s + s
    return s, res
