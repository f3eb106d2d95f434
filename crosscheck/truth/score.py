"""Scoring: compare an Observation with the oracle's truth, quantity by quantity.

Errors: ``hit`` 0 or 1; ``distance`` absolute difference; ``normal`` the
angle in radians between the unit vectors; ``v1``/``v2`` the Euclidean norm
of the difference.  A quantity agrees when its error is within the case's
tolerance (default: ``DEFAULT_RTOL`` x the case's size for lengths and
velocities, ``DEFAULT_NORMAL_TOL`` radians for normals; a case may set its
own).  A disagreement gets a category from the adapter's declared conventions.

>>> error_of("normal", (1.0, 0.0), (0.0, 1.0))  # doctest: +ELLIPSIS
1.5707963...
>>> error_of("hit", True, False)
1.0
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import cast

from crosscheck.core import geometry
from crosscheck.core.contract import TEXTBOOK_TOUCHING, Conventions
from crosscheck.core.geometry import Vec, norm
from crosscheck.core.model import Category, Observation, Status, Undefined, Value
from crosscheck.core.schema import AabbCase, AnyCase, PairCase, ResponseCase, SceneCase
from crosscheck.truth import scenes

DEFAULT_RTOL = 1e-9
"""Relative tolerance for distances and velocities, scaled by the case's size."""
DEFAULT_NORMAL_TOL = 1e-9
"""Tolerance on the normal's direction, in radians."""


@dataclass(frozen=True, slots=True)
class Verdict:
    """The judgement of one quantity."""

    status: Status
    error: float = math.nan
    tolerance: float = math.nan
    category: str = ""
    reason: str = ""


def encode(value: Value | None) -> str:
    """JSON text of a value (floats round-trip exactly); '' when absent.

    >>> encode((0.1, -0.0, float("nan"))), encode(True), encode(1e300)
    ('[0.1, -0.0, NaN]', 'true', '1e+300')
    """
    if value is None:
        return ""
    if isinstance(value, Undefined):
        return "undefined"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return _number(value)
    if isinstance(value, tuple) and all(isinstance(x, float) for x in value):
        return "[" + ", ".join(_number(x) for x in value) + "]"  # type: ignore[arg-type]
    return json.dumps(list(value) if isinstance(value, tuple) else value)


def _number(x: float) -> str:
    """``json.dumps(x)`` for a float, without its per-call overhead (runs per record)."""
    return float.__repr__(x) if math.isfinite(x) else json.dumps(x)


def _finite(xs: Iterator[float]) -> list[float]:
    return [abs(x) for x in xs if math.isfinite(x)]


_LAST_SCALE: list[tuple[AnyCase, float]] = []


def length_scale(case: PairCase) -> float:
    """The size of the case's numbers: largest |coordinate|, radius or half-width.

    Scoring asks this several times per case in a row, so the last answer is kept.
    """
    if _LAST_SCALE and _LAST_SCALE[0][0] is case:
        return _LAST_SCALE[0][1]
    scale = _length_scale(case)
    _LAST_SCALE[:] = [(case, scale)]
    return scale


def _length_scale(case: PairCase) -> float:
    nums = [*case.a.center, *case.b.center]
    if isinstance(case, AabbCase):
        nums += [*case.a.half, *case.b.half]
    else:
        nums += [case.a.radius, case.b.radius]
    return max(_finite(iter(nums)), default=0.0)


def velocity_scale(case: PairCase) -> float:
    """Largest |velocity component| of a response case (0 for detection cases)."""
    if not isinstance(case, ResponseCase):
        return 0.0
    return max(_finite(iter([*case.a.velocity, *case.b.velocity])), default=0.0)


def tolerance_for(case: PairCase, quantity: str) -> float:
    """The absolute tolerance for ``quantity`` in ``case``."""
    own = case.tolerance
    if quantity == "hit":
        return 0.0
    if quantity == "normal":
        return own.normal if own and own.normal is not None else DEFAULT_NORMAL_TOL
    if quantity == "distance":
        return own.distance if own and own.distance is not None else (
            DEFAULT_RTOL * length_scale(case))
    return own.velocity if own and own.velocity is not None else (
        DEFAULT_RTOL * velocity_scale(case))


def _is_unit(v: Sequence[float]) -> bool:
    return abs(norm(v) - 1.0) <= 1e-6


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


def judge(case: AnyCase, conventions: Conventions, quantity: str,
          value: Value | None, truth: Observation) -> Verdict:
    """Judge one quantity of an engine's observation against the truth."""
    want = truth.get(quantity)
    if value is None:
        return Verdict(Status.SKIP, reason=f"engine reported no {quantity}")
    if isinstance(want, Undefined) or want is None:
        why = want.reason if isinstance(want, Undefined) else "no truth"
        return Verdict(Status.UNDEFINED, reason=f"no defined value: {why}")
    if isinstance(case, SceneCase):
        status, err, tol, category, reason = scenes.judge(case, quantity, value, want,
                                                          DEFAULT_RTOL)
        return Verdict(status, err, tol, category, reason)
    tol = tolerance_for(case, quantity)
    if isinstance(value, Undefined):
        return Verdict(Status.DISAGREE, math.inf, tol, Category.ERROR,
                       f"engine gave undefined ({value.reason}) where truth is defined")
    if quantity == "normal" and isinstance(value, tuple) and not _is_unit(vec := cast(Vec, value)):
        return Verdict(Status.DISAGREE, math.inf, tol, Category.ERROR,
                       f"engine normal is not a unit vector (length {norm(vec):.3g})")
    err = error_of(quantity, value, want)
    if err <= tol:
        return Verdict(Status.AGREE, err, tol)
    category, reason = categorize(case, conventions, quantity, err, truth)
    return Verdict(Status.DISAGREE, err, tol, category, reason)


def approach_speed(case: ResponseCase) -> float:
    """Speed at which A and B approach along their line of centres (negative: separating)."""
    return geometry.approach_speed(case.a.center, case.b.center, case.a.velocity,
                                   case.b.velocity)


def _touch_convention(case: PairCase, conv: Conventions) -> str:
    feature = touch_feature(case)
    counts = conv.touching_is_contact(feature)
    if counts == TEXTBOOK_TOUCHING[feature]:
        return ""
    return f"exact {feature} touch; the engine counts it as {'contact' if counts else 'apart'}"


def _response_convention(case: ResponseCase, conv: Conventions) -> str:
    speed = approach_speed(case)
    if speed <= 0 and not conv.resolves_separating:
        return f"bodies already separating ({speed:.3g}); the engine leaves them alone"
    if 0 < speed < conv.restitution_threshold:
        return (f"approach speed {speed:.3g} below the engine's restitution threshold "
                f"{conv.restitution_threshold:g}: the bounce is inelastic")
    return ""


def touch_feature(case: PairCase) -> str:
    """Where two exactly touching bodies meet: ``sphere``, or a box ``face``/``edge``/``corner``.

    >>> from tests.conftest import aabb
    >>> touch_feature(aabb([0.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.5, 0.5]))
    'corner'
    """
    if not isinstance(case, AabbCase):
        return "sphere"
    touching = sum(
        abs(Fraction(cb) - Fraction(ca)) == Fraction(ha) + Fraction(hb)
        for ca, cb, ha, hb in zip(case.a.center, case.b.center, case.a.half, case.b.half,
                                  strict=True))
    if touching <= 1:
        return "face"
    return "edge" if touching == 2 and case.dim == 3 else "corner"


def nearest_feature(case: PairCase) -> str:
    """Where the bodies are nearest: ``sphere``, or the box ``face``, ``edge`` or ``corner``.

    A box pair separated (or touching) along one axis meets at a face, along two
    at an edge (a corner in 2-D), along three at a corner; overlapping boxes
    meet across a face.

    >>> from tests.conftest import aabb
    >>> nearest_feature(aabb([0.0, 0.0], [0.5, 0.5], [2.0, 3.0], [0.5, 0.5]))
    'corner'
    >>> nearest_feature(aabb([0.0, 0.0], [0.5, 0.5], [0.5, 0.2], [0.5, 0.5]))
    'face'
    """
    if not isinstance(case, AabbCase):
        return "sphere"
    apart = sum(abs(Fraction(cb) - Fraction(ca)) >= Fraction(ha) + Fraction(hb)
                for ca, cb, ha, hb in zip(case.a.center, case.b.center, case.a.half,
                                          case.b.half, strict=True))
    if apart <= 1:
        return "face"
    return "edge" if apart == 2 and case.dim == 3 else "corner"


def categorize(case: PairCase, conv: Conventions, quantity: str, err: float,
               truth: Observation) -> tuple[Category, str]:
    """Category and reason of a disagreement, from the adapter's declared conventions."""
    velocity = quantity in ("v1", "v2")
    # margin is a distance: it bounds lengths, never velocities
    allowed = (conv.rtol * velocity_scale(case) if velocity
               else conv.margin_for(nearest_feature(case)) + conv.rtol * length_scale(case))
    gap = truth.distance if isinstance(truth.distance, float) else math.nan
    rule = _touch_convention(case, conv) if quantity == "hit" and gap == 0.0 else ""
    if velocity and isinstance(case, ResponseCase):
        rule = _response_convention(case, conv)
    if rule:
        return Category.CONVENTION, rule
    if quantity in ("hit", "normal") and abs(gap) < allowed:
        return Category.TOLERANCE, f"|gap| {abs(gap):.3g} within declared tolerance {allowed:.3g}"
    if quantity == "normal":
        separation = norm([y - x for x, y in zip(case.a.center, case.b.center, strict=False)])
        allowed = allowed / separation if separation > 0 else 0.0
    if quantity != "hit" and err <= allowed:
        return Category.TOLERANCE, f"error {err:.3g} within declared tolerance {allowed:.3g}"
    return Category.ERROR, f"error {err:.3g} beyond tolerance and declared conventions"
