"""Bridge from a Case to the reference package: the exact truth and the textbook formula.

:func:`truth` asks the exact oracle (:mod:`reference_impl.exact`; scenes:
:mod:`crosscheck.truth.scenes`, the event-driven simulator);
:func:`textbook` runs the faithful float formula (:mod:`reference_impl.formulas`)
in float64 or float32.  Both answer with the harness's :class:`Observation`,
so the oracle's answer and an engine's answer are compared like for like.
:func:`truth_batch` gives the same observations as :func:`truth` for many cases at
once, settling sphere and response pairs with the vectorised, still exact, batch
oracle (:mod:`reference_impl.batch_values`, :mod:`reference_impl.batch_response`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from fractions import Fraction

import numpy as np

from crosscheck.core.model import Kind, Observation, Undefined, quantities_of
from crosscheck.core.schema import (
    AabbCase,
    AnyCase,
    PairCase,
    ResponseCase,
    SceneCase,
    SphereCase,
    ToiCase,
)
from crosscheck.truth import scenes, toi
from reference_impl import exact, formulas
from reference_impl.batch_response import response_values
from reference_impl.batch_values import sphere_values
from reference_impl.types import Contact, Response

Precision = formulas.Precision


def truth(case: AnyCase) -> Observation:
    """The exact answer for ``case``; quantities are Undefined where they have no value."""
    if isinstance(case, SceneCase):
        return scenes.truth(case)
    if isinstance(case, ToiCase):
        return toi.truth(case)
    if isinstance(case, AabbCase):
        return _contact(exact.aabb_contact(case.a.center, case.a.half,
                                           case.b.center, case.b.half), case.kind_enum)
    if isinstance(case, ResponseCase):
        a, b = case.a, case.b
        return _response(exact.sphere_response(a.center, a.mass, a.velocity, b.center, b.mass,
                                               b.velocity, case.restitution))
    return _contact(exact.sphere_contact(case.a.center, case.a.radius,
                                         case.b.center, case.b.radius), case.kind_enum)


def textbook(case: PairCase | ToiCase, precision: Precision = "f64") -> Observation:
    """The textbook formula evaluated in ``precision`` floating point.

    A time of impact is the textbook's discrete test sampled at the interval's two ends
    (:func:`sampled_impact`), as a simulation that steps over the interval sees it.
    """
    if isinstance(case, ToiCase):
        return sampled_impact(case, precision)
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


def _contact(c: Contact | Undefined, kind: Kind) -> Observation:
    if isinstance(c, Undefined):
        return Observation.undefined(quantities_of(kind), c.reason)
    return Observation(hit=c.hit, distance=c.distance, normal=c.normal)


def _response(r: Response[float] | Response[Fraction] | Undefined) -> Observation:
    if isinstance(r, Undefined):
        return Observation.undefined(quantities_of(Kind.SPHERE_RESPONSE), r.reason)
    return Observation(v1=tuple(float(x) for x in r.v1), v2=tuple(float(x) for x in r.v2))


def truth_batch(cases: Sequence[AnyCase]) -> list[Observation]:
    """``[truth(c) for c in cases]``, equal value for value, with sphere and response
    pairs settled together by the batch oracle (pairs it cannot settle, and every other
    kind, go through :func:`truth`)."""
    out: list[Observation | None] = [None] * len(cases)
    for dim in (2, 3):
        spheres = [i for i, c in enumerate(cases) if isinstance(c, SphereCase)
                   and len(c.a.center) == len(c.b.center) == dim]
        responses = [i for i, c in enumerate(cases) if isinstance(c, ResponseCase)
                     and {len(v) for v in (c.a.center, c.a.velocity, c.b.center,
                                            c.b.velocity)} == {dim}]
        _fill(out, cases, spheres, _sphere_batch)
        _fill(out, cases, responses, _response_batch)
    return [truth(c) if o is None else o for c, o in zip(cases, out, strict=True)]


Batch = Callable[[list[AnyCase]], list[Observation | None]]


def _fill(out: list[Observation | None], cases: Sequence[AnyCase], rows: list[int],
          batch: Batch) -> None:
    if rows:
        for i, o in zip(rows, batch([cases[i] for i in rows]), strict=True):
            out[i] = o


def _sphere_batch(cases: list[AnyCase]) -> list[Observation | None]:
    """Observations of sphere cases; None where the pure path must answer."""
    sc = [c for c in cases if isinstance(c, SphereCase)]
    v = sphere_values([c.a.center for c in sc], [c.a.radius for c in sc],
                      [c.b.center for c in sc], [c.b.radius for c in sc])
    pure = np.zeros(len(sc), dtype=bool)
    pure[v.exact_rows] = True
    coincident = Undefined("coincident centres")
    return [None if pure[k] else
            Observation(hit=bool(v.hit[k]), distance=float(v.distance[k]),
                        normal=coincident if v.coincident[k]
                        else tuple(float(x) for x in v.normal[k]))
            for k in range(len(sc))]


def _response_batch(cases: list[AnyCase]) -> list[Observation | None]:
    """Observations of response cases; None where the pure path must answer."""
    rc = [c for c in cases if isinstance(c, ResponseCase)]
    v = response_values([c.a.center for c in rc], [c.a.mass for c in rc],
                        [c.a.velocity for c in rc], [c.b.center for c in rc],
                        [c.b.mass for c in rc], [c.b.velocity for c in rc],
                        [c.restitution for c in rc])
    pure = np.zeros(len(rc), dtype=bool)
    pure[v.exact_rows] = True
    return [None if pure[k] else Observation(v1=tuple(float(x) for x in v.v1[k]),
                                             v2=tuple(float(x) for x in v.v2[k]))
            for k in range(len(rc))]
