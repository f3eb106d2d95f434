"""Scoring: compare an Observation with the oracle's truth, quantity by quantity.

Errors: ``hit`` 0 or 1; ``distance`` absolute difference; ``normal`` the
angle in radians between the unit vectors; ``v1``/``v2`` the Euclidean norm
of the difference (:func:`crosscheck.truth.bounds.error_of`).  A quantity
agrees when its error is within the case's own tolerance or, by default, the
forward-error bound of the float64 textbook computation for that case
(:mod:`crosscheck.truth.bounds`): ``agree`` means as right as float64 allows.  An
answer with no finite value (:func:`crosscheck.truth.no_value.failed`) never agrees,
whatever the bound: a normal across a subnormal gap may point anywhere, but it must
point.
Every disagreement gets a category and a reason from the adapter's declared
conventions (:mod:`crosscheck.truth.categories`).  Responses are judged
against the case as declared; when the engine resolved the contact later, the
error at the centres where it first reported the contact is kept beside it.

>>> from crosscheck.truth.bounds import error_of
>>> error_of("normal", (1.0, 0.0), (0.0, 1.0))  # doctest: +ELLIPSIS
1.5707963...
>>> error_of("hit", True, False)
1.0
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec
from crosscheck.core.kinds import spec
from crosscheck.core.model import Category, Observation, Status, Undefined, Value
from crosscheck.core.schema import AnyCase, PairCase, SceneCase, ToiCase
from crosscheck.truth import scene_rules, toi
from crosscheck.truth.bounds import (
    bound,
    by_direction,
    direction,
    error_of,
    length_off,
    not_unit,
    unit_allowance,
)
from crosscheck.truth.categories import categorize
from crosscheck.truth.no_value import failed

DEFAULT_RTOL = 1e-9
"""Relative tolerance of scene quantities (dimensionless errors), unless a case sets its own."""


@dataclass(frozen=True, slots=True)
class Verdict:
    """The judgement of one quantity."""

    status: Status
    error: float = math.nan
    tolerance: float = math.nan
    category: str = ""
    reason: str = ""
    error_at_contact: float = math.nan
    """Responses: the error against the truth where the engine first reported the contact."""


def _gap(truth: Observation) -> float:
    return truth.distance if isinstance(truth.distance, float) else math.nan


def judge(case: AnyCase, conventions: Conventions, quantity: str, value: Value | None,
          truth: Observation, observation: Observation | None = None) -> Verdict:
    """Judge one quantity of an engine's ``observation`` against the truth of the case as declared.

    ``value`` is ``observation.get(quantity)``; a quantity with no defined truth
    for the case as declared is ``undefined``, whatever the engine did.  A defined one is
    judged by the judge its kind's spec names (:data:`JUDGES`).
    """
    want = truth.get(quantity)
    if value is None:
        return Verdict(Status.SKIP, reason=f"engine reported no {quantity}")
    if isinstance(want, Undefined) or want is None:
        why = want.reason if isinstance(want, Undefined) else "no truth"
        return Verdict(Status.UNDEFINED, reason=f"no defined value: {why}")
    return JUDGES[spec(case.kind_enum).judge](case, conventions, quantity, value, want, truth,
                                              observation or Observation())


def _scene(case: SceneCase, conventions: Conventions, quantity: str, value: Value, want: Value,
           truth: Observation, observation: Observation) -> Verdict:
    status, err, tol, category, reason = scene_rules.judge(
        case, conventions, quantity, value, want, truth, observation, DEFAULT_RTOL)
    return Verdict(status, err, tol, category, reason)


def _impact(case: ToiCase, conventions: Conventions, quantity: str, value: Value, want: Value,
            truth: Observation, observation: Observation) -> Verdict:
    status, err, tol, category, reason = toi.judge(case, conventions, quantity, value, truth,
                                                   observation)
    return Verdict(status, err, tol, category, reason)


def _pair(case: PairCase, conventions: Conventions, quantity: str, value: Value, want: Value,
          truth: Observation, observation: Observation) -> Verdict:
    """A two-body kind at one instant: within the float64 bound (or the case's tolerance),
    else categorised; a normal that is no unit vector is an error."""
    tol = bound(case, quantity, _gap(truth))
    if quantity == "normal" and isinstance(value, tuple) and not failed(value):
        vec = cast(Vec, value)
        allowed = unit_allowance(conventions.rtol)
        if not length_off(vec) <= allowed:
            return Verdict(Status.DISAGREE, math.inf, tol, Category.ERROR,
                           not_unit(vec, allowed, conventions.rtol))
    err = math.inf if isinstance(value, Undefined) else error_of(quantity, value, want)
    if err <= tol and not failed(value):  # no value is ever within a bound
        return Verdict(Status.AGREE, err, tol)
    seen, seen_err, judged = value, err, ""
    if quantity == "normal" and isinstance(value, tuple) and not failed(value):
        seen = direction(cast(Vec, value))
        if seen != value:  # judged by its direction (module docstring)
            seen_err = error_of(quantity, seen, want)
            judged = by_direction(cast(Vec, value), unit_allowance(conventions.rtol),
                                  conventions.rtol)
    explained = categorize(case, conventions, quantity, seen, seen_err, truth, observation, tol)
    return Verdict(Status.DISAGREE, err, tol, explained.category, judged + explained.reason,
                   explained.error_at_contact)


JUDGES: dict[str, Callable[..., Verdict]] = {"pair": _pair, "time of impact": _impact,
                                             "scene": _scene}
"""Each kind's judge, by the name its spec gives it (:attr:`KindSpec.judge
<crosscheck.core.kinds.KindSpec.judge>`): ``judge(case, conventions, quantity, value, want,
truth, observation)`` with a defined ``want``."""
