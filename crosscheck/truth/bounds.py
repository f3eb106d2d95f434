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
  (a tie) agrees too.
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
"""How far from 1 the length of a reported normal may be (a unit vector to float32 and
then some); a longer or shorter one is an ``error`` whatever its direction."""
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


def is_unit(v: Sequence[float]) -> bool:
    """Whether ``v`` is a unit vector, to :data:`UNIT_LENGTH`.

    >>> is_unit((0.6, 0.8)), is_unit((1.0000109, 0.0))
    (True, False)
    """
    return abs(norm(v) - 1.0) <= UNIT_LENGTH


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
