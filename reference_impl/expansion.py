"""Error-free transformations in numpy float64, and the exact sign of a sum of floats.

These make the second stage of :mod:`reference_impl.batch`: exact, vectorized over
pairs, for the few pairs the float filter cannot decide.  Facts used (binary64,
round to nearest even, no overflow):

- TwoSum (Knuth): ``s = fl(x + y)`` and ``e`` with ``x + y == s + e`` exactly.
- TwoProduct (Dekker, with Veltkamp's split by ``2**27 + 1``): ``p = fl(x * y)`` and
  ``e`` with ``x * y == p + e`` exactly, provided ``|x|, |y| <= 2**995`` and the error
  ``e`` is not below the subnormal range; :func:`products_exact` states a sufficient
  range for the inputs.
- Exact sign of ``sum(P[i, :])`` per row (:func:`sum_sign`): Rump, Ogita and Oishi's
  *ExtractVector* ("Accurate floating-point summation, part I", SIAM J. Sci. Comput.
  31(1), 2008, Lemma 3.3).  With ``sigma = 2**k >= 2**M * max|p|`` and ``2**M >= n + 2``
  for ``n`` terms, ``q = fl(fl(sigma + p) - sigma)`` and ``r = fl(p - q)`` give
  ``p == q + r`` exactly, every ``q`` a multiple of ``eps * sigma`` (``eps = 2**-53``),
  ``|r| <= eps * sigma``, and ``tau = sum(q)`` exact in any order.  So ``sum(p) ==
  tau + sum(r)`` with ``|sum(r)| <= n * eps * sigma``: the sign is ``sign(tau)`` when
  ``|tau|`` exceeds that bound, or when every ``r`` is zero.  Otherwise ``tau`` joins
  the remainders (its own column) and the extraction repeats with a ``sigma`` at least
  ``2**(53 - 2M - 1)`` times smaller, so a handful of rounds reach zero remainders even
  for an exact tie.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

_SPLITTER = 134217729.0  # 2**27 + 1
EPS = 2.0**-53
PRODUCT_MIN = 2.0**-480
"""Non-zero factors at least this large give exact product errors (>= 2**-1066)."""
PRODUCT_MAX = 2.0**480
"""Factors at most this large neither overflow the split nor a sum of a few products."""


def two_sum(x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(s, e)`` with ``s = fl(x + y)`` and ``x + y == s + e`` exactly.

    >>> s, e = two_sum(np.array([1.0]), np.array([2.0**-60]))
    >>> float(s[0]), float(e[0]) == 2.0**-60
    (1.0, True)
    """
    s = x + y
    bv = s - x
    return s, (x - (s - bv)) + (y - bv)


def _split(x: FloatArray) -> tuple[FloatArray, FloatArray]:
    c = _SPLITTER * x
    hi = c - (c - x)
    return hi, x - hi


def two_product(x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(p, e)`` with ``p = fl(x * y)`` and ``x * y == p + e`` (see :func:`products_exact`).

    >>> p, e = two_product(np.array([1.0 + 2.0**-30]), np.array([1.0 - 2.0**-30]))
    >>> float(p[0]) == 1.0, float(e[0]) == -(2.0**-60)
    (True, True)
    """
    p = x * y
    xh, xl = _split(x)
    yh, yl = _split(y)
    return p, ((xh * yh - p) + xh * yl + xl * yh) + xl * yl


def products_exact(*factors: FloatArray) -> npt.NDArray[np.bool_]:
    """Rows whose every factor is zero or in ``[PRODUCT_MIN, PRODUCT_MAX]`` in magnitude."""
    ok = np.ones(factors[0].shape[0], dtype=bool)
    for f in factors:
        m = np.abs(f)
        good = (m == 0) | ((m >= PRODUCT_MIN) & (m <= PRODUCT_MAX))
        ok &= good if good.ndim == 1 else good.all(axis=1)
    return ok


def _sigma(p: FloatArray, m: int) -> FloatArray:
    """Per column, a power of two ``>= 2**m * max|p|`` (``2**m`` for an all-zero column)."""
    _, e = np.frexp(np.maximum(p.max(axis=0), -p.min(axis=0)))  # max|p| < 2**e
    sigma: FloatArray = np.ldexp(1.0, e + m)
    return sigma


def sum_sign(terms: FloatArray, max_rounds: int = 64) -> IntArray:
    """The exact sign (-1, 0, 1) of each column sum of ``terms`` (shape ``(n, N)``).

    Terms run down axis 0 so every step is elementwise across the N sums.  They
    must be finite with ``max|p| <= 2**1000`` (true for the products
    :func:`two_product` is exact on).  Each round extracts, decides the sums it
    can, and carries ``tau`` as one more term for the rest.

    >>> big, tiny = 2.0**60, 2.0**-60
    >>> sum_sign(np.array([[big, tiny, -big], [1.0, -1.0, 0.0], [tiny, -big, big]]).T).tolist()
    [1, 0, 1]
    """
    sign = np.zeros(terms.shape[1], dtype=np.int64)
    live, p = np.arange(terms.shape[1]), terms
    for _ in range(max_rounds):
        n = p.shape[0]
        sigma = _sigma(p, int(np.ceil(np.log2(n + 2))))
        q = (sigma + p) - sigma
        p = p - q
        tau = q.sum(axis=0)  # exact, in any order
        done = (np.abs(tau) > n * EPS * sigma) | ~p.any(axis=0)
        sign[live[done]] = np.sign(tau[done]).astype(np.int64)
        keep = ~done
        if not keep.any():
            return sign
        p = p[:, keep]
        p = np.concatenate([p[p.any(axis=1)], tau[None, keep]], axis=0)
        live = live[keep]
    raise ArithmeticError("sum_sign did not converge; inputs outside the documented range")
