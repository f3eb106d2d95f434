"""Why an answer disagrees: the category and the reason, from declared conventions only.

Every disagreement gets exactly one category, tried in this order:

1. ``convention``: a rule the engine documents differs from the textbook's, and
   it fires on this case: its touching rule at an exact touch, its reading of a
   negative size or of a zero mass, leaving separating bodies alone, a
   restitution threshold above the approach speed, or (responses) a declared
   soft contact or friction that the engine's impulse fits
   (:mod:`crosscheck.truth.contact_model`);
2. ``timestep``: (responses) the engine resolved the contact after a step into
   penetration, and its answer is right for the centres where it first reported
   the contact; the error there is recorded beside the error against the case;
3. ``tolerance``: within the engine's declared precision (``rtol`` x the case's
   size) plus its declared margin at the feature where the bodies meet; for a
   verdict or a normal, when the gap itself is within that allowance; a normal
   taken across the gap tilts by the allowance over the gap;
4. ``error``: explained by none of these.

Every reason is built from the rule that fired, with its numbers, and cites a
margin only for a feature that has one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from crosscheck.core.contract import TEXTBOOK_TOUCHING, Conventions
from crosscheck.core.geometry import approach_speed as approach
from crosscheck.core.geometry import difference, norm
from crosscheck.core.model import Category, Observation, Undefined, Value
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase
from crosscheck.truth import contact_model, oracle
from crosscheck.truth.bounds import bound, error_of


def _finite_abs(xs: list[float]) -> list[float]:
    return [abs(x) for x in xs if math.isfinite(x)]


def length_scale(case: PairCase) -> float:
    """The size of the case's numbers: largest |coordinate|, radius or half-width."""
    nums = [*case.a.center, *case.b.center]
    nums += [*case.a.half, *case.b.half] if isinstance(case, AabbCase) else [
        case.a.radius, case.b.radius]
    return max(_finite_abs(nums), default=0.0)


def velocity_scale(case: PairCase) -> float:
    """Largest |velocity component| of a response case (0 for detection cases)."""
    if not isinstance(case, ResponseCase):
        return 0.0
    return max(_finite_abs([*case.a.velocity, *case.b.velocity]), default=0.0)


def approach_speed(case: ResponseCase) -> float:
    """Speed at which A and B approach along their line of centres (negative: separating)."""
    return approach(case.a.center, case.b.center, case.a.velocity, case.b.velocity)


def _features_apart(case: AabbCase, exact_touch: bool) -> int:
    def apart(ca: float, cb: float, ha: float, hb: float) -> bool:
        d, s = abs(Fraction(cb) - Fraction(ca)), Fraction(ha) + Fraction(hb)
        return d == s if exact_touch else d >= s
    return sum(apart(*x) for x in zip(case.a.center, case.b.center, case.a.half, case.b.half,
                                       strict=True))


def _feature(case: PairCase, axes: int) -> str:
    if not isinstance(case, AabbCase):
        return "sphere"
    if axes <= 1:
        return "face"
    return "edge" if axes == 2 and case.dim == 3 else "corner"


def touch_feature(case: PairCase) -> str:
    """Where two exactly touching bodies meet: ``sphere``, or a box ``face``/``edge``/``corner``.

    >>> from crosscheck.testing.samples import box_pair
    >>> touch_feature(box_pair([0.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.5, 0.5]))
    'corner'
    """
    return _feature(case, _features_apart(case, True) if isinstance(case, AabbCase) else 0)


def nearest_feature(case: PairCase) -> str:
    """Where the bodies are nearest: ``sphere``, or the box ``face``, ``edge`` or ``corner``.

    A box pair separated (or touching) along one axis meets at a face, along two
    at an edge (a corner in 2-D), along three at a corner; overlapping boxes
    meet across a face.

    >>> from crosscheck.testing.samples import box_pair
    >>> nearest_feature(box_pair([0.0, 0.0], [0.5, 0.5], [2.0, 3.0], [0.5, 0.5]))
    'corner'
    >>> nearest_feature(box_pair([0.0, 0.0], [0.5, 0.5], [0.5, 0.2], [0.5, 0.5]))
    'face'
    """
    return _feature(case, _features_apart(case, False) if isinstance(case, AabbCase) else 0)


@dataclass(frozen=True, slots=True)
class Allowance:
    """An engine's declared tolerance for one quantity of one case, and where it comes from."""

    margin: float
    feature: str
    rtol: float
    size: float

    @property
    def total(self) -> float:
        return self.margin + self.rtol * self.size

    def __str__(self) -> str:
        margin = f"margin {self.margin:.3g} at a {self.feature} + " if self.margin else ""
        return (f"declared tolerance {self.total:.3g} ({margin}precision "
                f"{self.rtol:.3g} x size {self.size:.3g})")


def allowance(case: PairCase, conv: Conventions, quantity: str) -> Allowance:
    """The declared tolerance: margins bound lengths at their feature, never velocities."""
    if quantity in ("v1", "v2"):
        return Allowance(0.0, "", conv.rtol, velocity_scale(case))
    feature = nearest_feature(case)
    return Allowance(conv.margin_for(feature), feature, conv.rtol, length_scale(case))


@dataclass(frozen=True, slots=True)
class Explained:
    """A disagreement's category and reason (and, for responses, the error at the contact)."""

    category: Category
    reason: str
    error_at_contact: float = math.nan


# --- 1. conventions ------------------------------------------------------------------------------


def _touch_rule(case: PairCase, conv: Conventions, quantity: str, truth: Observation) -> str:
    if quantity != "hit" or truth.distance != 0.0:
        return ""
    feature = touch_feature(case)
    counts = conv.touching_is_contact(feature)
    if counts == TEXTBOOK_TOUCHING[feature]:
        return ""
    return (f"exact {feature} touch (distance 0): the engine counts it as "
            f"{'contact' if counts else 'apart'}, the textbook as "
            f"{'contact' if TEXTBOOK_TOUCHING[feature] else 'apart'}")


def _sizes(case: PairCase) -> list[tuple[str, float]]:
    if isinstance(case, AabbCase):
        return [(f"{side}.half[{i}]", h) for side, body in (("a", case.a), ("b", case.b))
                for i, h in enumerate(body.half)]
    return [("a.radius", case.a.radius), ("b.radius", case.b.radius)]


def _negative_rule(case: PairCase, conv: Conventions, quantity: str, value: Value) -> str:
    negative = [(name, x) for name, x in _sizes(case) if x < 0]
    if not negative or conv.negative_extents != "absolute" or isinstance(case, ResponseCase):
        return ""
    absolute = _with_absolute_sizes(case)
    want = oracle.truth(absolute).get(quantity)
    if want is None or isinstance(want, Undefined) or isinstance(value, Undefined):
        return ""
    if error_of(quantity, value, want) > bound(absolute, quantity, _gap(oracle.truth(absolute))):
        return ""
    name, x = negative[0]
    return (f"{name} = {x:g} < 0: the engine reads a negative size as its magnitude "
            f"({abs(x):g}), and answers right for that; the oracle reads it literally")


def _with_absolute_sizes(case: PairCase) -> PairCase:
    if isinstance(case, AabbCase):
        return case.model_copy(update={
            "a": case.a.model_copy(update={"half": tuple(abs(h) for h in case.a.half)}),
            "b": case.b.model_copy(update={"half": tuple(abs(h) for h in case.b.half)})})
    return case.model_copy(update={"a": case.a.model_copy(update={"radius": abs(case.a.radius)}),
                                   "b": case.b.model_copy(update={"radius": abs(case.b.radius)})})


def _response_rule(case: ResponseCase, conv: Conventions) -> str:
    zero = [side for side, body in (("A", case.a), ("B", case.b)) if body.mass == 0]
    if zero and conv.zero_mass == "static":
        return (f"body {zero[0]} has mass 0: the engine makes it static (immovable), the "
                "textbook gives it no inertia")
    speed = approach_speed(case)
    if speed <= 0 and not conv.resolves_separating:
        return (f"bodies already separating (approach speed {speed:.3g} <= 0): the engine "
                "leaves them alone, the textbook exchanges momentum regardless")
    if 0 < speed < conv.restitution_threshold:
        return (f"approach speed {speed:.9g} below the engine's restitution threshold "
                f"{conv.restitution_threshold:.9g}: the bounce is inelastic")
    return ""


def _convention(case: PairCase, conv: Conventions, quantity: str, value: Value,
                truth: Observation) -> str:
    if isinstance(case, ResponseCase):
        return _response_rule(case, conv)
    return _touch_rule(case, conv, quantity, truth) or _negative_rule(case, conv, quantity, value)


# --- 2. time step --------------------------------------------------------------------------------


def _moved(case: ResponseCase, observation: Observation) -> ResponseCase | None:
    if observation.resolved_at is None:
        return None
    pa, pb = observation.resolved_at
    if (tuple(pa), tuple(pb)) == (case.a.center, case.b.center):
        return None
    return case.model_copy(update={"a": case.a.model_copy(update={"center": tuple(pa)}),
                                   "b": case.b.model_copy(update={"center": tuple(pb)})})


def _timestep(case: ResponseCase, conv: Conventions, quantity: str, value: Value,
              declared_err: float, observation: Observation) -> Explained | None:
    """The answer against the truth at the centres where the engine first reported contact."""
    moved = _moved(case, observation)
    if moved is None:
        return None
    there = oracle.truth(moved)
    want = there.get(quantity)
    if want is None or isinstance(want, Undefined) or isinstance(value, Undefined):
        return None
    err = error_of(quantity, value, want)
    explained = err <= max(bound(moved, quantity), allowance(moved, conv, quantity).total)
    if not explained:
        return Explained(Category.ERROR, "", err)
    depth = (moved.a.radius + moved.b.radius) - norm(difference(moved.a.center, moved.b.center))
    where = f"a penetration of {depth:.3g}" if depth >= 0 else f"a gap of {-depth:.3g}"
    step = f"steps of {conv.time_step:.3g} s" if conv.time_step else "its step"
    return Explained(Category.TIMESTEP, (
        f"right for the centres where the engine first reported the contact (error {err:.3g} "
        f"there), reached after {step} at {where}; against the case as "
        f"declared the error is {declared_err:.3g}"), err)


# --- 3. tolerance --------------------------------------------------------------------------------


def _gap(truth: Observation) -> float:
    return truth.distance if isinstance(truth.distance, float) else math.nan


def _undefined_explained(case: PairCase, allowed: Allowance) -> str:
    """Why an engine may rightly fail to define a value: its inputs blur within its precision."""
    separation = norm(difference(case.a.center, case.b.center))
    if separation < allowed.total:
        return f"centres {separation:.3g} apart, within its {allowed}"
    if isinstance(case, AabbCase):
        overlaps = sorted(abs(ha + hb - abs(b - a)) for a, b, ha, hb in zip(
            case.a.center, case.b.center, case.a.half, case.b.half, strict=True))
        if len(overlaps) > 1 and overlaps[1] - overlaps[0] < allowed.total:
            return (f"the two nearest axes differ by {overlaps[1] - overlaps[0]:.3g}, "
                    f"within its {allowed}")
    return ""


def _tolerance(case: PairCase, conv: Conventions, quantity: str, value: Value, err: float,
               truth: Observation, allowed: Allowance) -> str:
    gap = _gap(truth)
    if isinstance(value, Undefined):  # positions blur within the engine's length allowance
        why = _undefined_explained(case, allowance(case, conv, "distance"))
        return f"the engine gives no value ({value.reason}): {why}" if why else ""
    if quantity in ("hit", "normal") and abs(gap) < allowed.total:
        return f"|gap| {abs(gap):.3g} within the engine's {allowed}"
    if quantity == "normal":
        tilt = min(math.pi, allowed.total / abs(gap)) if gap else math.pi
        if err <= tilt:
            return (f"normal off by {err:.3g} rad, within the tilt {tilt:.3g} that the "
                    f"engine's {allowed} gives a normal across a gap of {abs(gap):.3g}")
        return ""
    if quantity != "hit" and err <= allowed.total:
        return f"error {err:.3g} within the engine's {allowed}"
    return ""


# --- the category --------------------------------------------------------------------------------


def categorize(case: PairCase, conv: Conventions, quantity: str, value: Value, err: float,
               truth: Observation, observation: Observation, agree: float) -> Explained:
    """The category and reason of a disagreement of ``value`` (error ``err``, agree bound
    ``agree``) with the truth of ``case`` as declared."""
    rule = _convention(case, conv, quantity, value, truth)
    if not rule and isinstance(case, ResponseCase) and quantity in ("v1", "v2"):
        rule = contact_model.explain(case, conv, observation,
                                     allowance(case, conv, quantity).total)
    if rule:
        return Explained(Category.CONVENTION, rule)
    at_contact = math.nan
    if isinstance(case, ResponseCase):
        stepped = _timestep(case, conv, quantity, value, err, observation)
        if stepped is not None and stepped.category is Category.TIMESTEP:
            return stepped
        at_contact = stepped.error_at_contact if stepped is not None else math.nan
    allowed = allowance(case, conv, quantity)
    why = _tolerance(case, conv, quantity, value, err, truth, allowed)
    if why:
        return Explained(Category.TOLERANCE, why, at_contact)
    shown = "undefined" if isinstance(value, Undefined) else f"error {err:.3g}"
    return Explained(Category.ERROR, f"{shown} beyond the agree bound {agree:.3g} and the "
                     f"engine's {allowed}; no declared convention applies", at_contact)
