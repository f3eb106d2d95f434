"""What the time-of-impact paths of the engine adapters share (kind ``sphere_toi``).

A ``sphere_toi`` case (:class:`~crosscheck.core.schema.ToiCase`) is two spheres in linear
motion over ``[0, duration]``; an adapter answers ``hit`` (they touch in the interval),
``toi`` (the first contact time, seconds from the start) and ``normal`` (the unit vector
from A's centre to B's at that time).  Without a contact ``toi`` and ``normal`` are
``Undefined(NO_CONTACT)`` (:func:`no_contact`, the truth's own).  The engine parts are
:mod:`adapters.fcl_toi`, :mod:`adapters.box2d_toi` and :mod:`adapters.rapier_toi`.

>>> from crosscheck.core.schema import ToiCase
>>> case = ToiCase(id="x", kind="sphere_toi", description="d", dim=2, duration=2.0,
...     a={"center": [0.0, 0.0], "radius": 0.5, "velocity": [1.0, 0.0]},
...     b={"center": [4.0, 0.0], "radius": 0.5, "velocity": [-1.0, 0.0]})
>>> end_centres(case)
((2.0, 0.0), (2.0, 0.0))
>>> centre_normal(case, 1.5)
(1.0, 0.0)
>>> no_contact().hit
False
"""

from __future__ import annotations

import math

from crosscheck.core.geometry import Vec, norm
from crosscheck.core.model import Undefined
from crosscheck.core.schema import ToiCase
from crosscheck.truth.toi import NO_CONTACT, Motion, no_contact

__all__ = ["NO_CONTACT", "centre_normal", "end_centres", "no_contact", "refusal"]


def end_centres(case: ToiCase) -> tuple[Vec, Vec]:
    """A's and B's centres at the interval's end, ``center + velocity x duration`` (float64)."""
    return tuple(  # type: ignore[return-value]
        tuple(c + v * case.duration for c, v in zip(body.center, body.velocity, strict=True))
        for body in (case.a, case.b))


def centre_normal(case: ToiCase, t: float) -> Vec | Undefined:
    """The unit vector from A's centre to B's at time ``t`` (float64), from the case's motion:
    ``d = (cb - ca) + (vb - va) t``.  Undefined when the centres coincide then."""
    d = Motion.of(case).at(t)
    length = norm(d)
    if not length > 0:
        return Undefined("the centres coincide at the reported time")
    return tuple(x / length for x in d)


def refusal(case: ToiCase) -> str | None:
    """Why an engine should not be asked ``case``: a non-finite input or a negative radius
    (the engines take them unchecked), or a duration that is not positive and finite."""
    numbers = [*case.a.center, *case.b.center, *case.a.velocity, *case.b.velocity,
               case.a.radius, case.b.radius]
    if not all(math.isfinite(x) for x in numbers):
        return "non-finite input: the engine's time-of-impact query takes it unchecked"
    if case.a.radius < 0 or case.b.radius < 0:
        return "negative radius: no sphere has one"
    if not (math.isfinite(case.duration) and case.duration > 0):
        return f"duration {case.duration!r}: the interval [0, duration] needs 0 < duration < inf"
    return None
