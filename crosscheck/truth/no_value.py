"""Answers that carry no value, and the declared configurations in which an engine gives none.

An engine may answer a quantity with no finite value: Undefined (it says it gives
none), a number that is not finite, or the largest double, which engines return as a
failure sentinel (coal's EPA answers ``-DBL_MAX`` when it fails).  Such an answer is
never ``agree`` and never ``tolerance``: no precision makes "no number" near the truth.
It is an ``error``, unless a rule the engine declares (``Conventions.no_value``, by the
names of :data:`RULES`) says that the engine gives no value for this configuration:
then it is a ``convention``, with the rule in the reason.

One failed query gets one reason: :func:`failure` describes every quantity of the
observation that has no finite value, so a distance of ``-1.8e308`` and the NaN normal
that came with it read alike.

>>> failed(float("nan")), failed(-1.7976931348623157e308), failed(0.5), failed((0.0, 1.0))
(True, True, False, False)
"""

from __future__ import annotations

from collections.abc import Callable

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Observation, Undefined, Value
from crosscheck.core.schema import PairCase
from crosscheck.truth import oracle
from crosscheck.truth.bounds import SENTINEL, failed

__all__ = ["RULES", "SENTINEL", "declared", "failed", "failure"]

ANSWERED = ("distance", "normal", "v1", "v2")
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


def _textbook(precision: oracle.Precision) -> Callable[[PairCase, str], str]:
    """The textbook formula's own rule, in ``precision``: no normal where its centres
    coincide or its box axes tie, no response where its centres coincide, as its float
    numbers give them (``reference_impl.formulas``)."""
    name = {"f32": "float32", "f64": "float64"}[precision]

    def rule(case: PairCase, quantity: str) -> str:
        there = oracle.textbook(case, precision).get(quantity)
        if not isinstance(there, Undefined):
            return ""
        return (f"the textbook formula in {name} defines no {quantity} for this case "
                f"({there.reason})")
    return rule


RULES: dict[str, Callable[[PairCase, str], str]] = {
    "float32-textbook": _textbook("f32"),
    "float64-textbook": _textbook("f64"),
}
"""The configurations an engine may declare it gives no value in (``Conventions.no_value``)."""


def declared(case: PairCase, conv: Conventions, quantity: str) -> str:
    """The declared rule under which the engine gives no ``quantity`` here ('' if none).

    >>> from crosscheck.testing.samples import sphere_pair
    >>> far = sphere_pair(1e9, 1e9 + 1.5)  # float32 cannot tell these centres apart
    >>> declared(far, Conventions(no_value=("float32-textbook",)), "normal")[-52:]
    'defines no normal for this case (coincident centres)'
    >>> declared(far, Conventions(), "normal")
    ''
    """
    for name in conv.no_value:
        why = RULES[name](case, quantity)
        if why:
            return f"{name!r}: {why}"
    return ""
