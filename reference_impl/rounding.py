"""Correctly rounded float64 values of expressions involving one square root.

The exact oracle works in rationals (:class:`fractions.Fraction`), but a
distance or a unit normal involves ``sqrt(q)``, which is usually irrational.
These helpers enclose ``sqrt(q)`` between two rationals using
:func:`math.isqrt`, push the enclosure through a monotone expression, and
convert both ends to float (``Fraction.__float__`` is correctly rounded, ties
to even).  When both ends round to the same float, that float is the correctly
rounded value of the true expression; otherwise the precision is doubled and
the step repeated.  The loop ends: an irrational value is never exactly a
rounding boundary, and a rational ``sqrt(q)`` is found exactly.

>>> sqrt_rounded(Fraction(2)) == 2 ** 0.5
True
>>> sqrt_minus(Fraction(25), Fraction(3))  # sqrt(25) - 3
2.0
>>> quotient(Fraction(3), Fraction(25))  # 3 / sqrt(25)
0.6
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction

Bounds = tuple[Fraction, Fraction]

_START_BITS = 80


def sqrt_bounds(q: Fraction, bits: int) -> Bounds:
    """Return ``lo <= sqrt(q) <= hi`` with ``hi - lo <= 2**-bits * sqrt(q)``.

    ``lo == hi`` exactly when ``sqrt(q)`` is rational.

    >>> sqrt_bounds(Fraction(9, 4), 10)
    (Fraction(3, 2), Fraction(3, 2))
    """
    if q < 0:
        raise ValueError("square root of a negative number")
    if q == 0:
        return Fraction(0), Fraction(0)
    # sqrt(n/d) = sqrt(n*d) / d, scaled by 2**k so the integer root has > bits bits.
    nd = q.numerator * q.denominator
    k = max(0, bits + 1 - nd.bit_length() // 2)
    scaled = nd << (2 * k)
    root = math.isqrt(scaled)
    lo = Fraction(root, q.denominator << k)
    hi = lo if root * root == scaled else Fraction(root + 1, q.denominator << k)
    return lo, hi


def to_float(x: Fraction) -> float:
    """Correctly rounded float of ``x``; values beyond the float range give +-inf.

    >>> to_float(Fraction(2) ** 1024)
    inf
    """
    try:
        return float(x)
    except OverflowError:
        return math.inf if x > 0 else -math.inf


def _same_float(a: float, b: float) -> bool:
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


def round_with_sqrt(q: Fraction, enclose: Callable[[Fraction, Fraction], Bounds]) -> float:
    """Correctly round ``g(sqrt(q))`` where ``enclose(lo, hi)`` bounds ``g`` on ``[lo, hi]``."""
    bits = _START_BITS
    while True:
        lo, hi = enclose(*sqrt_bounds(q, bits))
        flo, fhi = to_float(lo), to_float(hi)
        if _same_float(flo, fhi):
            return flo
        bits *= 2


def sqrt_rounded(q: Fraction) -> float:
    """Correctly rounded ``sqrt(q)`` for ``q >= 0``."""
    return round_with_sqrt(q, lambda lo, hi: (lo, hi))


def quotient(num: Fraction, q: Fraction) -> float:
    """Correctly rounded ``num / sqrt(q)`` for ``q > 0``."""
    if q <= 0:
        raise ZeroDivisionError("quotient needs q > 0")

    def enclose(lo: Fraction, hi: Fraction) -> Bounds:
        a, b = num / hi, num / lo
        return min(a, b), max(a, b)

    return round_with_sqrt(q, enclose)


def sqrt_minus(q: Fraction, r: Fraction) -> float:
    """Correctly rounded ``sqrt(q) - r`` for ``q >= 0``, without cancellation.

    For ``r > 0`` it evaluates ``(q - r*r) / (sqrt(q) + r)``: the numerator is
    exact and the denominator is a sum of non-negative terms, so the
    enclosure stays relatively tight however close ``sqrt(q)`` is to ``r``.
    """
    if r <= 0:  # sqrt(q) + |r|: no cancellation possible
        return round_with_sqrt(q, lambda lo, hi: (lo - r, hi - r))
    num = q - r * r
    if num == 0:
        return 0.0

    def enclose(lo: Fraction, hi: Fraction) -> Bounds:
        a, b = num / (hi + r), num / (lo + r)
        return min(a, b), max(a, b)

    return round_with_sqrt(q, enclose)
