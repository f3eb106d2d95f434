"""Why an answer disagrees: the category and the reason, from declared conventions only.

Every disagreement gets exactly one category, tried in this order:

0. an answer with no finite value (Undefined, NaN, infinite, the largest double) is an
   ``error``, unless a declared rule says the engine gives no value for this
   configuration (``convention``); one failed query gets one reason for all its
   quantities (:mod:`crosscheck.truth.no_value`);
1. ``convention``: a rule the engine documents differs from the textbook's, and
   it fires on this case: its touching rule at an exact touch, its reading of a
   negative size, and for responses the rules of
   :mod:`crosscheck.truth.response_rules` (a zero mass, separating bodies, a
   restitution threshold, a speed cap) or a declared soft contact or friction that
   the engine's impulse fits (:mod:`crosscheck.truth.contact_model`);
2. ``timestep``: (responses) the engine resolved the contact after a step into
   penetration, and its answer is right for the centres where it first reported
   the contact (the error there is recorded beside the error against the case); or
   the engine samples contacts at step starts and the contact fell between two;
3. ``tolerance``: within the engine's declared allowance for the quantity
   (:mod:`crosscheck.truth.allowance`: its precision on the case's numbers plus the
   margin that acts on that quantity); for a verdict or a normal, when the gap itself
   is within that allowance; a normal taken across the gap tilts by the allowance
   over the gap;
4. ``error``: explained by none of these.

Every reason is built from the rule that fired, with its numbers, and cites only the
allowances that act on its quantity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from crosscheck.core.contract import TEXTBOOK_TOUCHING, Conventions
from crosscheck.core.geometry import difference, norm
from crosscheck.core.model import Category, Observation, Undefined, Value
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase
from crosscheck.truth import contact_model, no_value, oracle, response_rules
from crosscheck.truth.allowance import (
    Allowance,
    allowance,
    approach_speed,
    length_scale,
    nearest_feature,
    touch_feature,
    velocity_scale,
)
from crosscheck.truth.bounds import bound, error_of

DETECTION_CONVENTIONS = ("no_value", "touching", "negative_extents")
"""The declared conventions whose rules make a detection pair's disagreement a
``convention``: an answer with no value under a declared rule, the touching rule, the reading
of a negative size."""
RESPONSE_CONVENTIONS = ("no_value", *response_rules.CASE_RULES, "max_speed",
                        *contact_model.CONVENTIONS)
"""The same for a response, in the order they are tried."""

__all__ = ["DETECTION_CONVENTIONS", "RESPONSE_CONVENTIONS", "Allowance", "Explained",
           "allowance", "approach_speed", "categorize",
           "length_scale", "nearest_feature", "touch_feature", "velocity_scale"]


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


def _convention(case: PairCase, conv: Conventions, quantity: str, value: Value,
                truth: Observation, observation: Observation) -> str:
    if not isinstance(case, ResponseCase):
        return (_touch_rule(case, conv, quantity, truth)
                or _negative_rule(case, conv, quantity, value))
    tolerance = allowance(case, conv, quantity).total
    return (response_rules.convention(case, conv, quantity, value, observation, tolerance)
            or contact_model.explain(case, conv, observation, tolerance))


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


def _tolerance(quantity: str, err: float, truth: Observation, allowed: Allowance) -> str:
    gap = _gap(truth)
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


def _no_value(case: PairCase, conv: Conventions, quantity: str, failed: str) -> Explained:
    """A failed answer: ``convention`` under a declared no-value rule, else ``error``."""
    rule = no_value.declared(case, conv, quantity)
    if rule:
        return Explained(Category.CONVENTION, f"no value by a declared rule: {failed}, and "
                         f"its rule {rule}")
    return Explained(Category.ERROR, f"no finite answer: {failed}; no declared convention "
                     "says the engine gives none for this case")


def _stepped(case: ResponseCase, conv: Conventions, quantity: str, value: Value, err: float,
             observation: Observation) -> Explained | None:
    """The time-step rules: a contact resolved a step late, or one that fell between steps."""
    late = _timestep(case, conv, quantity, value, err, observation)
    if late is not None and late.category is Category.TIMESTEP:
        return late
    between = response_rules.missed(case, conv, quantity, value, observation,
                                    allowance(case, conv, quantity).total, err)
    if between:
        return Explained(Category.TIMESTEP, between)
    return late


def categorize(case: PairCase, conv: Conventions, quantity: str, value: Value, err: float,
               truth: Observation, observation: Observation, agree: float) -> Explained:
    """The category and reason of a disagreement of ``value`` (error ``err``, agree bound
    ``agree``) with the truth of ``case`` as declared."""
    failed = no_value.failure(observation, quantity, value)
    if failed:
        return _no_value(case, conv, quantity, failed)
    rule = _convention(case, conv, quantity, value, truth, observation)
    if rule:
        return Explained(Category.CONVENTION, rule)
    at_contact = math.nan
    if isinstance(case, ResponseCase):
        stepped = _stepped(case, conv, quantity, value, err, observation)
        if stepped is not None and stepped.category is Category.TIMESTEP:
            return stepped
        at_contact = stepped.error_at_contact if stepped is not None else math.nan
    allowed = allowance(case, conv, quantity)
    why = _tolerance(quantity, err, truth, allowed)
    if why:
        return Explained(Category.TOLERANCE, why, at_contact)
    return Explained(Category.ERROR, f"error {err:.3g} beyond the agree bound {agree:.3g} and "
                     f"{_declared(quantity, truth, allowed)}; no declared convention applies",
                     at_contact)


def _declared(quantity: str, truth: Observation, allowed: Allowance) -> str:
    """The engine's declared tolerance as it acts on ``quantity``: a normal's is the tilt its
    length tolerance gives across the gap (radians), not the length itself; a verdict's acts
    on the gap, not on the verdict's error of 1."""
    gap = abs(_gap(truth))
    if quantity == "normal" and gap > 0:
        tilt = min(math.pi, allowed.total / gap)
        return (f"the tilt {tilt:.3g} rad that the engine's {allowed} gives a normal across "
                f"a gap of {gap:.3g}")
    if quantity == "hit" and math.isfinite(gap):
        return f"the |gap| {gap:.3g} beyond the engine's {allowed}"
    return f"the engine's {allowed}"
