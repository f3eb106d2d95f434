"""Bridge from a Case to the reference package: the exact truth and the textbook formula.

:func:`truth` asks the exact oracle (:mod:`reference_impl.exact`; scenes:
:mod:`crosscheck.truth.scenes`, the event-driven simulator);
:func:`textbook` runs the faithful float formula (:mod:`reference_impl.formulas`)
in float64 or float32.  Both answer with the harness's :class:`Observation`,
so the oracle's answer and an engine's answer are compared like for like.
"""

from __future__ import annotations

from fractions import Fraction

from crosscheck.core.model import Kind, Observation, Undefined, quantities_of
from crosscheck.core.schema import AabbCase, AnyCase, PairCase, ResponseCase, SceneCase
from crosscheck.truth import scenes
from reference_impl import exact, formulas
from reference_impl.types import Contact, Response

Precision = formulas.Precision


def truth(case: AnyCase) -> Observation:
    """The exact answer for ``case``; quantities are Undefined where they have no value."""
    if isinstance(case, SceneCase):
        return scenes.truth(case)
    if isinstance(case, AabbCase):
        return _contact(exact.aabb_contact(case.a.center, case.a.half,
                                           case.b.center, case.b.half), case.kind_enum)
    if isinstance(case, ResponseCase):
        a, b = case.a, case.b
        return _response(exact.sphere_response(a.center, a.mass, a.velocity, b.center, b.mass,
                                               b.velocity, case.restitution))
    return _contact(exact.sphere_contact(case.a.center, case.a.radius,
                                         case.b.center, case.b.radius), case.kind_enum)


def textbook(case: PairCase, precision: Precision = "f64") -> Observation:
    """The textbook formula evaluated in ``precision`` floating point."""
    if isinstance(case, AabbCase):
        return _contact(formulas.aabb_contact(case.a.center, case.a.half, case.b.center,
                                              case.b.half, precision=precision), case.kind_enum)
    if isinstance(case, ResponseCase):
        a, b = case.a, case.b
        return _response(formulas.sphere_response(a.center, a.mass, a.velocity, b.center, b.mass,
                                                  b.velocity, case.restitution,
                                                  precision=precision))
    return _contact(formulas.sphere_contact(case.a.center, case.a.radius, case.b.center,
                                            case.b.radius, precision=precision), case.kind_enum)


def _contact(c: Contact | Undefined, kind: Kind) -> Observation:
    if isinstance(c, Undefined):
        return Observation.undefined(quantities_of(kind), c.reason)
    return Observation(hit=c.hit, distance=c.distance, normal=c.normal)


def _response(r: Response[float] | Response[Fraction] | Undefined) -> Observation:
    if isinstance(r, Undefined):
        return Observation.undefined(quantities_of(Kind.SPHERE_RESPONSE), r.reason)
    return Observation(v1=tuple(float(x) for x in r.v1), v2=tuple(float(x) for x in r.v2))
