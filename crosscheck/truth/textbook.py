"""The textbook formula as an engine would answer: a Case evaluated in float64 or float32.

:func:`textbook` runs the faithful float formula (:mod:`reference_impl.formulas`); a time of
impact is its discrete test at the interval's two ends (:func:`sampled_impact`).  Both answer
with the harness's :class:`Observation`, like the exact oracle (:mod:`crosscheck.truth.oracle`,
which names them too), so a declared rule on the textbook's own answer
(:mod:`crosscheck.truth.no_value`) reads them without the oracle and its times of impact.
"""

from __future__ import annotations

from fractions import Fraction

from crosscheck.core.model import Kind, Observation, Undefined, quantities_of
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase, ToiCase
from reference_impl import formulas
from reference_impl.types import Contact, Response

__all__ = ["Precision", "contact_observation", "response_observation", "sampled_impact",
           "textbook"]

Precision = formulas.Precision


def textbook(case: PairCase | ToiCase, precision: Precision = "f64") -> Observation:
    """The textbook formula evaluated in ``precision`` floating point.

    A time of impact is the textbook's discrete test sampled at the interval's two ends
    (:func:`sampled_impact`), as a simulation that steps over the interval sees it.
    """
    if isinstance(case, ToiCase):
        return sampled_impact(case, precision)
    if isinstance(case, AabbCase):
        return contact_observation(formulas.aabb_contact(
            case.a.center, case.a.half, case.b.center, case.b.half, precision=precision),
            case.kind_enum)
    if isinstance(case, ResponseCase):
        a, b = case.a, case.b
        return response_observation(formulas.sphere_response(
            a.center, a.mass, a.velocity, b.center, b.mass, b.velocity, case.restitution,
            precision=precision))
    return contact_observation(formulas.sphere_contact(
        case.a.center, case.a.radius, case.b.center, case.b.radius, precision=precision),
        case.kind_enum)


def sampled_impact(case: ToiCase, precision: Precision = "f64") -> Observation:
    """The textbook's discrete sphere test (strict ``<``) at ``t = 0`` and at the interval's
    end ``T`` (centres ``c + v T`` in float64): a contact at the first sample that has one,
    with the textbook's normal there; no contact if neither has.

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> crossing = CASE_ADAPTER.validate_python({"id": "t", "description": "d",
    ...     "kind": "sphere_toi", "dim": 2, "duration": 1.0,
    ...     "a": {"center": [-1, 0], "radius": 0.1, "velocity": [2, 0]},
    ...     "b": {"center": [1, 0], "radius": 0.1, "velocity": [-2, 0]}})
    >>> sampled_impact(crossing).hit  # at t = 1 they have passed through each other
    False
    """
    a, b = case.a, case.b
    for t in (0.0, case.duration):
        ca = tuple(c + v * t for c, v in zip(a.center, a.velocity, strict=True))
        cb = tuple(c + v * t for c, v in zip(b.center, b.velocity, strict=True))
        c = formulas.sphere_contact(ca, a.radius, cb, b.radius, precision=precision)
        if isinstance(c, Undefined):
            return Observation.undefined(quantities_of(Kind.SPHERE_TOI), c.reason)
        if c.hit:
            return Observation(hit=True, toi=t, normal=c.normal)
    none = Undefined("no contact at either sample")
    return Observation(hit=False, toi=none, normal=none)


def contact_observation(c: Contact | Undefined, kind: Kind) -> Observation:
    """A contact (of the exact oracle or the formula) as an observation of ``kind``."""
    if isinstance(c, Undefined):
        return Observation.undefined(quantities_of(kind), c.reason)
    return Observation(hit=c.hit, distance=c.distance, normal=c.normal)


def response_observation(r: Response[float] | Response[Fraction] | Undefined) -> Observation:
    """A response (of the exact oracle or the formula) as an observation."""
    if isinstance(r, Undefined):
        return Observation.undefined(quantities_of(Kind.SPHERE_RESPONSE), r.reason)
    return Observation(v1=tuple(float(x) for x in r.v1), v2=tuple(float(x) for x in r.v2))
