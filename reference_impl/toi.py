"""Exact time of impact of two spheres in linear motion over ``[0, t_end]``.

The oracle a continuous collision detection (CCD) query is checked against:
sphere A (centre ``ca``, velocity ``va``, radius ``ra``) and sphere B move with
constant velocities from ``t = 0`` to ``t = t_end``.  Every input double is
read exactly as a :class:`~fractions.Fraction`; the verdict is decided in
rationals and the time and normal are correctly rounded to doubles.

* **Contact** at ``t`` means touching or overlapping: ``|d(t)| <= R`` with
  ``d(t) = dp + dv t``, ``dp = cb - ca``, ``dv = vb - va``, ``R = ra + rb``,
  i.e. ``f(t) = a t**2 + 2 b t + c <= 0`` with ``a = dv.dv``, ``b = dp.dv``,
  ``c = dp.dp - R**2``.  (Detection in :mod:`reference_impl.exact` uses the
  strict ``<``; a sweep counts the touching instant as the contact.)
* ``hit`` iff contact at some ``t`` in the closed interval ``[0, t_end]``:
  touching or overlapping at ``t = 0`` is a hit at ``toi = 0`` whatever the
  motion (also while moving apart: unlike :mod:`reference_impl.events`, which
  only lets approaching pairs collide); a graze at exact tangency (a double
  root) is a hit; contact exactly at ``t_end`` is a hit.  Without relative
  motion (``a = 0``) the distance is constant, so it is a hit iff ``c <= 0``.
  Points (``R = 0``) hit only if they pass exactly through each other.
* ``toi`` is the first contact time, the double nearest to the exact value
  (ties to even).  If ``c > 0`` it is the smaller root
  ``(-b - sqrt(disc)) / a = c / (-b + sqrt(disc))``, ``disc = b**2 - a c``
  (the second form has no cancellation).  It is a hit iff the root is
  ``<= t_end``, decided exactly: the vertex ``-b / a`` lies in ``[0, t_end]``
  or ``f(t_end) <= 0``.  Rounding is monotone and ``t_end`` is a double, so
  ``toi <= t_end`` always.
* ``normal`` is the unit vector from A's centre to B's at the exact contact
  time.  At ``t = 0`` it is ``dp / |dp|``; at a root ``|d(t)| = R`` exactly,
  so it is ``d(t) / R = (a dp - b dv - dv sqrt(disc)) / (a R)``.  It is
  ``None`` when the centres coincide at contact (``dp = 0`` at ``t = 0``, or
  ``R = 0``): the direction is undefined.

**Correct rounding.**  A rational value (``disc`` a perfect square, or the
contact at 0 along ``dp`` with rational ``|dp|``) is rounded once by
``Fraction.__float__`` (round-to-nearest, ties to even).  Otherwise
``sqrt(disc)`` is enclosed between rationals by exact integer square roots
(:func:`reference_impl.rounding.sqrt_bounds`); each value is monotone in
``sqrt(disc)``, so the enclosure's ends bound it, and
:func:`~reference_impl.rounding.round_with_sqrt` doubles the precision until
both ends round to the same double, which is then the correctly rounded value
(an irrational value is never a rounding boundary, so this ends).  No float
square root is ever used.

>>> hit = time_of_impact((0.0, 0.0), (1.0, 0.0), 0.5, (4.0, 0.0), (-1.0, 0.0), 0.5, 2.0)
>>> hit
Impact(hit=True, toi=1.5, normal=(1.0, 0.0))
>>> time_of_impact((0.0, 0.0), (1.0, 0.0), 0.5, (4.0, 0.0), (-1.0, 0.0), 0.5, 1.0).hit
False
>>> time_of_impact((0.0, 0.0), (0.0, 0.0), 0.5, (-2.0, 1.0), (1.0, 0.0), 0.5, 4.0)
Impact(hit=True, toi=2.0, normal=(0.0, 1.0))
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

from .exact import dimension
from .rounding import Bounds, quotient, round_with_sqrt, sqrt_bounds, to_float

FVec = tuple[Fraction, ...]


@dataclass(frozen=True, slots=True)
class Impact:
    """Result of :func:`time_of_impact`; ``toi`` and ``normal`` are ``None`` without a hit.

    >>> Impact(False, None, None)
    Impact(hit=False, toi=None, normal=None)
    """

    hit: bool
    toi: float | None
    normal: tuple[float, ...] | None


@dataclass(frozen=True, slots=True)
class Quadratic:
    """``f(t) = a t**2 + 2 b t + c = |dp + dv t|**2 - R**2``, exactly.

    >>> Quadratic.of((Fraction(3), Fraction(0)), (Fraction(-1), Fraction(0)), Fraction(1)).c
    Fraction(8, 1)
    """

    dp: FVec
    dv: FVec
    radius: Fraction
    a: Fraction
    b: Fraction
    c: Fraction

    @classmethod
    def of(cls, dp: FVec, dv: FVec, radius: Fraction) -> Quadratic:
        return cls(dp, dv, radius, _dot(dv, dv), _dot(dp, dv), _dot(dp, dp) - radius * radius)

    def __call__(self, t: Fraction) -> Fraction:
        return (self.a * t + 2 * self.b) * t + self.c

    @property
    def disc(self) -> Fraction:
        """The reduced discriminant ``b**2 - a c``."""
        return self.b * self.b - self.a * self.c


def _dot(u: FVec, w: FVec) -> Fraction:
    return sum((x * y for x, y in zip(u, w, strict=True)), Fraction())


def _check(values: Sequence[float], ra: float, rb: float, t_end: float) -> None:
    if not all(math.isfinite(x) for x in (*values, ra, rb, t_end)):
        raise ValueError("time_of_impact needs finite inputs")
    if ra < 0 or rb < 0:
        raise ValueError(f"radii must be >= 0, got {ra!r} and {rb!r}")
    if not t_end > 0:
        raise ValueError(f"t_end must be > 0, got {t_end!r}")


def _hits_by(f: Quadratic, t_end: Fraction) -> bool:
    """Whether ``f``, positive at 0, reaches ``<= 0`` in ``[0, t_end]`` (``a > 0``)."""
    if f.b >= 0 or f.disc < 0:  # not closing in, or the closest approach is a miss
        return False
    return -f.b <= f.a * t_end or f(t_end) <= 0  # vertex -b/a inside, or f(t_end) <= 0


def _first_root(f: Quadratic) -> float:
    """Correctly rounded ``c / (-b + sqrt(disc))`` (``b < 0 < c``, ``disc >= 0``)."""
    lo, hi = sqrt_bounds(f.disc, 0)
    if lo == hi:
        return to_float(f.c / (lo - f.b))

    def enclose(lo: Fraction, hi: Fraction) -> Bounds:
        return f.c / (hi - f.b), f.c / (lo - f.b)

    return round_with_sqrt(f.disc, enclose)


def _component(p: Fraction, q: Fraction, disc: Fraction) -> float:
    """Correctly rounded ``p - q sqrt(disc)``."""
    lo, hi = sqrt_bounds(disc, 0)
    if lo == hi or q == 0:
        return to_float(p - q * lo)

    def enclose(lo: Fraction, hi: Fraction) -> Bounds:
        ends = (p - q * lo, p - q * hi)
        return min(ends), max(ends)

    return round_with_sqrt(disc, enclose)


def _root_normal(f: Quadratic) -> tuple[float, ...] | None:
    """``d(t) / R`` at the exact first root, componentwise correctly rounded."""
    if f.radius == 0:
        return None  # points: the centres coincide at contact
    scale = f.a * f.radius
    return tuple(
        _component((f.a * p - f.b * v) / scale, v / scale, f.disc)
        for p, v in zip(f.dp, f.dv, strict=True)
    )


def _start_normal(dp: FVec) -> tuple[float, ...] | None:
    """``dp / |dp|``, componentwise correctly rounded; ``None`` if ``dp = 0``."""
    q = _dot(dp, dp)
    return tuple(quotient(x, q) for x in dp) if q else None


def time_of_impact(
    ca: Sequence[float],
    va: Sequence[float],
    ra: float,
    cb: Sequence[float],
    vb: Sequence[float],
    rb: float,
    t_end: float,
) -> Impact:
    """First contact of spheres A and B in ``[0, t_end]``; see the module docstring.

    Raises :class:`ValueError` for mixed or other than 2-D/3-D vectors,
    non-finite inputs, a negative radius or ``t_end <= 0``.

    >>> time_of_impact((0.0, 0.0), (0.0, 0.0), 1.0, (0.0, 0.0), (1.0, 0.0), 1.0, 1.0)
    Impact(hit=True, toi=0.0, normal=None)
    """
    dimension(ca, va, cb, vb)
    _check((*ca, *va, *cb, *vb), ra, rb, t_end)
    dp = tuple(Fraction(y) - Fraction(x) for x, y in zip(ca, cb, strict=True))
    dv = tuple(Fraction(y) - Fraction(x) for x, y in zip(va, vb, strict=True))
    f = Quadratic.of(dp, dv, Fraction(ra) + Fraction(rb))
    if f.c <= 0:
        return Impact(True, 0.0, _start_normal(dp))
    if f.a == 0 or not _hits_by(f, Fraction(t_end)):
        return Impact(False, None, None)
    return Impact(True, _first_root(f), _root_normal(f))
