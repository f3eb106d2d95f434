"""Bridge from a Case to the reference package: the exact truth and the textbook formula.

:func:`truth` asks the exact oracle (:mod:`reference_impl.exact`; scenes:
:mod:`crosscheck.truth.scenes`, the event-driven simulator; times of impact:
:mod:`crosscheck.truth.toi`), through the truth its kind's spec names (:data:`TRUTHS`);
:func:`textbook` runs the faithful float formula (:mod:`reference_impl.formulas`)
in float64 or float32 (:mod:`crosscheck.truth.textbook`, named here too).  Both answer with
the harness's :class:`Observation`, so the oracle's answer and an engine's answer are
compared like for like.
:func:`truth_batch` gives the same observations as :func:`truth` for many cases at
once, settling sphere and response pairs with the vectorised, still exact, batch
oracle (:mod:`reference_impl.batch_values`, :mod:`reference_impl.batch_response`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from crosscheck.core.kinds import spec
from crosscheck.core.model import Observation, Undefined
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SphereCase
from crosscheck.truth import scenes, toi
from crosscheck.truth.textbook import (
    Precision,
    contact_observation,
    response_observation,
    sampled_impact,
    textbook,
)
from reference_impl import exact
from reference_impl.batch_response import response_values
from reference_impl.batch_values import sphere_values

__all__ = ["TRUTHS", "Precision", "sampled_impact", "textbook", "truth", "truth_batch"]


def _box_contact(case: AabbCase) -> Observation:
    return contact_observation(exact.aabb_contact(case.a.center, case.a.half,
                                                  case.b.center, case.b.half), case.kind_enum)


def _sphere_contact(case: SphereCase) -> Observation:
    return contact_observation(exact.sphere_contact(case.a.center, case.a.radius,
                                                    case.b.center, case.b.radius), case.kind_enum)


def _response(case: ResponseCase) -> Observation:
    a, b = case.a, case.b
    return response_observation(exact.sphere_response(a.center, a.mass, a.velocity, b.center,
                                                      b.mass, b.velocity, case.restitution))


TRUTHS: dict[str, Callable[[Any], Observation]] = {
    "box contact": _box_contact, "sphere contact": _sphere_contact, "response": _response,
    "time of impact": toi.truth, "scene": scenes.truth}
"""Each kind's exact truth, by the name its spec gives it (:attr:`KindSpec.truth
<crosscheck.core.kinds.KindSpec.truth>`); each takes a case of that kind."""


def truth(case: AnyCase) -> Observation:
    """The exact answer for ``case``; quantities are Undefined where they have no value."""
    return TRUTHS[spec(case.kind_enum).truth](case)


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
