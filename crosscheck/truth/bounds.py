"""What ``agree`` allows: a forward-error bound of the float64 textbook computation, per case.

An answer agrees when it is as right as float64 arithmetic allows for that
case: within a few units in the last place (``u = 2**-53``) of the magnitudes
the textbook formula actually combines, never of the largest coordinate of the
scene.  A case may set its own tolerance instead.

- **distance** ``K_LENGTH * u * M``, where ``M`` is ``|cb - ca| + ra + rb`` for
  spheres and, for boxes, ``max_i (|cb_i - ca_i| + ha_i + hb_i)`` over the axes
  that decide the distance (the separated ones; overlapping, the axis of least
  overlap and any within rounding of it): the float64
  formula rounds the centre differences (relative error ``u`` each), a dot
  product, a square root and one subtraction of the summed sizes, each adding
  at most ``u`` of ``M``.  Coordinates of 1e15 whose difference is 1 do not
  widen it: that difference is computed exactly (Sterbenz).
- **normal** ``K_ANGLE * u`` radians, plus, for separated boxes, the tilt
  ``K_LENGTH * u * M / |gap|`` that the rounding of the gaps gives a normal
  taken across the gap; for overlapping boxes whose least overlap float64
  cannot single out, any direction (pi), and an answer of "no direction"
  (a tie) agrees too.  Its length must be 1 to the engine's declared precision
  (:func:`unit_allowance`, ``K_ANGLE max(u, rtol)``), or the normal is an ``error``
  whatever its direction; within that but not to float64, its category is that of its
  direction (:func:`direction`), while its error stays that of the vector as given (a
  length off 1 counts in it: agree is float64's unit vector).
- **v1, v2** ``K_VELOCITY * u * (|va| + |vb|)``: the line of centres (a
  normalised difference), two dot products and coefficients with factors up to
  ``1 + e <= 2``.
- **hit** 0: a verdict is right or wrong.

The constants are upper bounds with room to spare over these operation counts;
``tests/truth/test_bounds.py`` checks that the float64 textbook formula stays within
them on the whole case suite, every sweep and random cases, except the hit
verdicts that flip at touching.  A tiny absolute floor (``K * 2**-1074``)
covers subnormal results.

>>> from crosscheck.testing.samples import sphere_pair
>>> bound(sphere_pair(0.0, 2.0), "distance") == K_LENGTH * U * 3.0
True
>>> bound(sphere_pair(1e15, 1e15 + 2.0), "distance") == bound(sphere_pair(0.0, 2.0), "distance")
True
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from fractions import Fraction
from typing import cast

from crosscheck.core.geometry import difference, norm
from crosscheck.core.model import Undefined, Value
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase

U = 2.0**-53
"""The unit roundoff of float64."""
TINY = 2.0**-1074
"""The smallest positive (subnormal) float64."""
UNIT_LENGTH = 1e-6
"""How far from 1 the conformance kit lets the length of a normal be on its clear samples (a
unit vector to float32 and then some).  Scoring asks more of each engine:
:func:`unit_allowance`."""
K_LENGTH = 8
K_ANGLE = 16
K_VELOCITY = 32


def _finite(x: float) -> float:
    return x if math.isfinite(x) else math.nan


def _box_axes(case: AabbCase) -> list[tuple[Fraction, float]]:
    """Per axis: the exact gap ``|cb_i - ca_i| - (ha_i + hb_i)`` and the magnitude it combines."""
    return [(abs(Fraction(b) - Fraction(a)) - Fraction(ha) - Fraction(hb), abs(b - a) + ha + hb)
            for a, b, ha, hb in zip(case.a.center, case.b.center, case.a.half, case.b.half,
                                    strict=True)]


def _deciding(axes: list[tuple[Fraction, float]]) -> list[tuple[Fraction, float]]:
    """The axes that decide a box distance, or could under rounding: the separated ones (or
    any whose gap rounding could make positive); overlapping, those within rounding of the
    smallest overlap."""
    slack = [Fraction(K_LENGTH * U * m) for _, m in axes]
    if any(g > 0 for g, _ in axes):
        return [axis for axis, s in zip(axes, slack, strict=True) if axis[0] > -s]
    least = max(axes, key=lambda axis: axis[0])  # the smallest overlap is the largest gap
    reach = least[0] - Fraction(K_LENGTH * U * least[1])
    return [axis for axis, s in zip(axes, slack, strict=True) if axis[0] + s >= reach]


def length_magnitude(case: PairCase) -> float:
    """``M``: the magnitudes the distance formula combines (see the module docstring).

    For boxes only the axes that decide the distance count: two boxes that
    overlap by 1e-9 on y are not judged by the 2e9 of their x extents.
    """
    if isinstance(case, AabbCase):
        axes = _box_axes(case)
        return max(m for _, m in _deciding(axes)) if axes else 0.0
    return norm(difference(case.a.center, case.b.center)) + case.a.radius + case.b.radius


def velocity_magnitude(case: ResponseCase) -> float:
    """``|va| + |vb|``: the magnitudes the response formula combines."""
    return norm(case.a.velocity) + norm(case.b.velocity)


def _boxes_ambiguous(case: AabbCase) -> bool:
    """Overlapping boxes whose axis of smallest overlap float64 cannot decide."""
    return len(_deciding(_box_axes(case))) > 1


def _normal_bound(case: PairCase, length: float, gap: float) -> float:
    angle = K_ANGLE * U
    if not isinstance(case, AabbCase):
        return angle
    if gap > 0:
        return angle + min(math.pi, length / gap)
    if _boxes_ambiguous(case):
        return math.pi
    return angle


def bound(case: PairCase, quantity: str, gap: float = math.nan) -> float:
    """The agree tolerance of ``quantity``: the case's own, or the float64 bound.

    ``gap`` is the true signed distance, needed for box normals.
    """
    own = case.tolerance
    if quantity == "hit":
        return 0.0
    if quantity in ("v1", "v2"):
        if own and own.velocity is not None:
            return own.velocity
        assert isinstance(case, ResponseCase)
        return _finite(K_VELOCITY * (U * velocity_magnitude(case) + TINY))
    length = _finite(K_LENGTH * (U * length_magnitude(case) + TINY))
    if quantity == "distance":
        return own.distance if own and own.distance is not None else length
    if own and own.normal is not None:
        return own.normal
    return _normal_bound(case, length, gap)


SENTINEL = sys.float_info.max
"""The largest double: an engine's 'no answer', never a distance of any case."""


def failed(value: Value | None) -> bool:
    """Whether ``value`` is an answer without a finite value (None is no answer at all):
    Undefined, a number that is not finite, or :data:`SENTINEL`.  No such answer is ever
    within a bound (:mod:`crosscheck.truth.no_value` says which engines give none by rule).

    >>> failed(float("nan")), failed(-1.7976931348623157e308), failed((0.0, 1.0))
    (True, True, False)
    """
    if isinstance(value, Undefined):
        return True
    if isinstance(value, bool) or value is None:
        return False
    numbers = value if isinstance(value, tuple) else (value,)
    return any(isinstance(x, float) and (not math.isfinite(x) or abs(x) == SENTINEL)
               for x in numbers)


def unit_allowance(precision: float) -> float:
    """How far from 1 the length of a pair's normal may be from an engine whose arithmetic
    has relative precision ``precision`` (its declared ``rtol``, at least ``u``): the
    ``K_ANGLE`` roundings of a normalisation (a sum of squares, a square root, a division)
    with room.  A longer or shorter one is an ``error`` whatever its direction; one within
    it is judged by its direction (:func:`direction`).

    >>> unit_allowance(2.0**-21) > 5e-6 > unit_allowance(2.0**-50)
    True
    """
    return K_ANGLE * max(U, precision)


def length_off(v: Sequence[float]) -> float:
    """How far the length of ``v`` is from 1 (infinite for a zero vector, which has no
    direction whatever the allowance).

    >>> length_off((0.6, 0.8)), length_off((2.0, 0.0)), length_off((0.0, 0.0))
    (0.0, 1.0, inf)
    """
    length = norm(v)
    return abs(length - 1.0) if length > 0 else math.inf


def direction(v: Sequence[float]) -> tuple[float, ...]:
    """``v`` scaled to length 1 (``v`` itself when its length is 1 to float64's ``K_ANGLE u``);
    ``v`` is not zero.

    >>> direction((0.0, 1.0000098))
    (0.0, 1.0)
    """
    length = norm(v)
    if abs(length - 1.0) <= K_ANGLE * U:
        return tuple(v)
    return tuple(x / length for x in v)


def _precision(rtol: float) -> str:
    return f"rtol {rtol:.3g}" if rtol >= U else f"rtol {rtol:.3g}, so float64's u"


def not_unit(vec: Sequence[float], allowed: float, rtol: float) -> str:
    """The reason of a normal whose length is not 1 to the engine's precision."""
    if not norm(vec) > 0:
        return "engine normal is the zero vector: no direction, not a unit vector"
    return (f"engine normal is not a unit vector: length {norm(vec):.9g}, off 1 by "
            f"{length_off(vec):.3g}, beyond the {allowed:.3g} its declared precision "
            f"({_precision(rtol)}) allows")


def by_direction(vec: Sequence[float], allowed: float, rtol: float) -> str:
    """The start of the reason of a normal judged by its direction (its length within the
    engine's precision of 1, not float64's)."""
    return (f"engine normal of length {norm(vec):.9g} (off 1 by {length_off(vec):.3g}: within "
            f"the {allowed:.3g} its declared precision ({_precision(rtol)}) allows, beyond "
            "float64's), judged by its direction: ")


def error_of(quantity: str, value: Value, truth: Value) -> float:
    """The error of ``value`` against ``truth`` (both defined) for ``quantity``."""
    if quantity == "hit":
        return 0.0 if value == truth else 1.0
    if isinstance(value, tuple) and isinstance(truth, tuple):
        if len(value) != len(truth):
            return math.inf
        a, b = cast(Sequence[float], value), cast(Sequence[float], truth)
        diff = norm([x - y for x, y in zip(a, b, strict=True)])
        return 2.0 * math.asin(min(1.0, diff / 2.0)) if quantity == "normal" else diff
    assert isinstance(value, float | int) and isinstance(truth, float | int)
    return abs(float(value) - float(truth))
