"""Answers that carry no value, and the declared configurations in which an engine gives none.

An engine may answer a quantity with no finite value: Undefined (it says it gives
none), a number that is not finite, or the largest double, which engines return as a
failure sentinel (coal's EPA answers ``-DBL_MAX`` when it fails).  Such an answer is
never ``agree`` and never ``tolerance``: no precision makes "no number" near the truth.
It is an ``error``, unless a rule the engine declares (``Conventions.no_value``, by the
names of :data:`RULES`) says that the engine gives no value for this configuration:
then it is a ``convention``, with the rule in the reason.  The same holds for a time of
impact's ``toi`` and ``normal`` (:mod:`crosscheck.truth.toi`), whose rules may read the
engine's answer: the centres coinciding at the time it reports (:data:`RULES`
``*-centre-line``), as well as the textbook's own rule on its discrete test.

One failed query gets one reason: :func:`failure` describes every quantity of the
observation that has no finite value, so a distance of ``-1.8e308`` and the NaN normal
that came with it read alike.

>>> failed(float("nan")), failed(-1.7976931348623157e308), failed(0.5), failed((0.0, 1.0))
(True, True, False, False)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Observation, Undefined, Value
from crosscheck.core.schema import PairCase, ToiCase
from crosscheck.truth.bounds import SENTINEL, failed
from crosscheck.truth.textbook import Precision, textbook

__all__ = ["RULES", "SENTINEL", "declared", "failed", "failure"]

ANSWERED = ("distance", "toi", "normal", "v1", "v2")
"""The quantities that carry a number (a verdict always has a value)."""


def _shown(quantity: str, value: Value) -> str:
    if isinstance(value, Undefined):
        return f"no {quantity} ({value.reason})"
    if isinstance(value, float):
        sentinel = " (the largest double: a failure sentinel)" if abs(value) == SENTINEL else ""
        return f"{quantity} {value:.3g}{sentinel}"
    numbers = value if isinstance(value, tuple) else (value,)
    shown = ", ".join(f"{x:.3g}" if isinstance(x, float) else str(x) for x in numbers)
    return f"{quantity} ({shown})"


def failure(observation: Observation, quantity: str, value: Value) -> str:
    """The failed answers of the query ``value`` belongs to, in words ('' if it has a value).

    >>> failure(Observation(distance=-1.7976931348623157e308, normal=Undefined("NaN")),
    ...         "normal", Undefined("NaN"))[:55]
    'the engine gave no normal (NaN) and distance -1.8e+308 '


    The row's own ``value`` comes first; the observation adds the other quantities of the
    same query that have no finite value either.
    """
    if not failed(value):
        return ""
    parts = [_shown(quantity, value)]
    for other in ANSWERED:
        seen = observation.get(other)
        if other != quantity and seen is not None and failed(seen):
            parts.append(_shown(other, seen))
    return "the engine gave " + " and ".join(parts)


# --- declared rules --------------------------------------------------------------------------

Rule = Callable[[PairCase | ToiCase, str, Observation], str]
"""A rule: why the engine gives no ``quantity`` for the case, given its answer ('' if the
rule does not say so)."""


def _textbook(precision: Precision) -> Rule:
    """The textbook formula's own rule, in ``precision``: no normal where its centres
    coincide or its box axes tie, no response where its centres coincide, as its float
    numbers give them (``reference_impl.formulas``); for a time of impact, its discrete test
    at the interval's two ends (:func:`crosscheck.truth.textbook.sampled_impact`): no normal
    where the centres coincide at the sample that finds the contact."""
    name = {"f32": "float32", "f64": "float64"}[precision]

    def rule(case: PairCase | ToiCase, quantity: str, observation: Observation) -> str:
        there = textbook(case, precision).get(quantity)
        if not isinstance(there, Undefined):
            return ""
        return (f"the textbook formula in {name} defines no {quantity} for this case "
                f"({there.reason})")
    return rule


def _centre_line(precision: Precision) -> Rule:
    """A time of impact's normal taken as the direction from A's centre to B's at the time
    the engine reports (the engine gives none, or the adapter computes it so: FCL's binding,
    Box2D's ``b2Distance`` witness points of two circles), with the centres at that time in
    ``precision``: none where they coincide there.  In float64 the difference of the centres
    is ``(cb - ca) + (vb - va) t`` (:func:`adapters.shared.centre_normal`); in float32
    each centre is interpolated between its float32 start and end, ``(1 - s) c0 + s c1`` at
    ``s = t / duration`` (Box2D's ``b2Sweep::GetTransform``)."""
    name = {"f32": "float32", "f64": "float64"}[precision]

    def rule(case: PairCase | ToiCase, quantity: str, observation: Observation) -> str:
        t = observation.toi
        if (not isinstance(case, ToiCase) or quantity != "normal" or observation.hit is not True
                or not isinstance(t, float) or not math.isfinite(t)):
            return ""
        a, b = _centres_at(case, t, precision)
        if a != b:
            return ""
        return (f"the normal is the direction between the centres at the engine's time "
                f"t = {t!r}, where in {name} they coincide (at {_shown_point(a)})")
    return rule


def _centres_at(case: ToiCase, t: float, precision: Precision
                ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """A's and B's centres at ``t`` as :func:`_centre_line` computes them (float64: A's at
    the origin, B's at the difference)."""
    if precision == "f64":
        d = tuple((y - x) + (w - v) * t for x, y, v, w in zip(
            case.a.center, case.b.center, case.a.velocity, case.b.velocity, strict=True))
        return tuple(0.0 for _ in d), d
    s = np.float32(t / case.duration)

    def at(center: Sequence[float], velocity: Sequence[float]) -> tuple[float, ...]:
        c0 = np.array(center, dtype=np.float32)
        c1 = np.array([c + v * case.duration for c, v in zip(center, velocity, strict=True)],
                      dtype=np.float32)
        return tuple(float(x) for x in (np.float32(1.0) - s) * c0 + s * c1)
    return at(case.a.center, case.a.velocity), at(case.b.center, case.b.velocity)


def _shown_point(p: Sequence[float]) -> str:
    return "(" + ", ".join(f"{x:.9g}" for x in p) + ")"


RULES: dict[str, Rule] = {
    "float32-textbook": _textbook("f32"),
    "float64-textbook": _textbook("f64"),
    "float32-centre-line": _centre_line("f32"),
    "float64-centre-line": _centre_line("f64"),
}
"""The configurations an engine may declare it gives no value in (``Conventions.no_value``)."""


def declared(case: PairCase | ToiCase, conv: Conventions, quantity: str,
             observation: Observation | None = None) -> str:
    """The declared rule under which the engine gives no ``quantity`` here ('' if none);
    ``observation`` is the engine's answer (a time of impact's rule reads its time).

    >>> from crosscheck.testing.samples import sphere_pair
    >>> far = sphere_pair(1e9, 1e9 + 1.5)  # float32 cannot tell these centres apart
    >>> declared(far, Conventions(no_value=("float32-textbook",)), "normal")[-52:]
    'defines no normal for this case (coincident centres)'
    >>> declared(far, Conventions(), "normal")
    ''
    """
    seen = observation or Observation()
    for name in conv.no_value:
        why = RULES[name](case, quantity, seen)
        if why:
            return f"{name!r}: {why}"
    return ""
