"""Box2D's ``b2TimeOfImpact`` for ``sphere_toi`` cases (2-D), for both Box2D variants.

pybox2d 2.3.10 exposes the direct query: ``Box2D.b2TimeOfImpact(shapeA=, shapeB=, sweepA=,
sweepB=, tMax=)`` (Box2D_contact.i: it fills a ``b2TOIInput`` with the shapes' distance
proxies and returns ``(state, t)``), so no world or bullet body is involved.  ``prepare``
builds two ``b2CircleShape(radius=r)`` and two ``b2Sweep`` s (``c0`` = the case's start
centre, ``c`` = its end centre ``center + velocity x duration`` computed in float64, angles
0, ``localCenter`` 0, ``alpha0`` 0): Box2D's sweep interpolates ``(1 - t) c0 + t c`` over
its own ``t`` in [0, 1] (b2Math.h, ``b2Sweep::GetTransform``), so ``tMax`` is 1 and
``toi`` = ``t x duration``.  Everything enters as float32 (``float32`` is C ``float``).

``query`` makes the ``b2TimeOfImpact`` call, and for a contact, as Box2D's header says
("use b2Distance to compute the contact point and normal at the time of impact"), one
``b2Distance`` of the two circles at the sweeps' transforms at ``t`` (``useRadii=False``:
a circle's proxy is its centre) whose witness points ``pointA`` -> ``pointB`` give
``normal`` (normalised here in float64): the engine's own centres at its time.  States
(b2TimeOfImpact.cpp): ``e_touching`` -> hit at ``t``; ``e_separated`` -> no contact;
``e_overlapped`` (the cores, here the centres, coincide at the start) -> hit at 0, with
the normal Undefined when the witness points coincide; ``e_failed`` (the root finder ran
out of iterations or found an initial overlap) and ``e_unknown`` -> ``RuntimeError`` (an
``error`` row), with the state and the ``t`` Box2D left.

Conventions (b2TimeOfImpact.cpp and b2Settings.h at pybox2d 2.3.10, :data:`SOURCES`):
Box2D does not look for the touching time.  It advances until the distance of the cores
(for circles the centre distance, ``useRadii = false``) is within ``tolerance = 0.25
b2_linearSlop`` of ``target = max(b2_linearSlop, totalRadius - 3 b2_linearSlop)``
(``b2_linearSlop`` = 0.005 m, compiled in): the surfaces then overlap by ``3 b2_linearSlop``
= 0.015 m, the overlap its contact solver keeps.  Declared ``toi_target`` = -0.015 and
``toi_tolerance`` = 0.00125.  For a radius sum below ``4 b2_linearSlop`` = 0.02 the target
is the centre distance ``b2_linearSlop`` instead (surface separation ``0.005 - R``):
declared ``toi_min_centre_distance`` = ``b2_linearSlop``.  A pair that never overlaps by
that much reads as no contact.  Float32 throughout (the adapter's ``rtol``, 2^-21).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from adapters.box2d_world import engine
from adapters.sphere_toi import end_centres, no_contact, refusal
from crosscheck.core.model import Observation, Undefined
from crosscheck.core.schema import ToiCase

B2 = "https://github.com/pybox2d/pybox2d/blob/2.3.10/Box2D/"
SOURCES = (
    B2 + "Collision/b2TimeOfImpact.cpp",  # target, tolerance, states
    B2 + "Collision/b2TimeOfImpact.h",  # b2TOIInput: sweep interval [0, tMax]; use b2Distance
    B2 + "Box2D_contact.i",  # pybox2d's b2TimeOfImpact(shapeA=, ..., tMax=) -> (state, t)
    B2 + "Common/b2Math.h",  # b2Sweep::GetTransform: (1 - t) c0 + t c
)
LINEAR_SLOP = 0.005
"""``b2_linearSlop`` (b2Settings.h), m."""
TOI_TARGET = -3.0 * LINEAR_SLOP
"""The surface separation b2TimeOfImpact stops at: ``totalRadius - 3 b2_linearSlop`` between
the centres, an overlap of 0.015 m (for a radius sum of at least 4 b2_linearSlop)."""
TOI_TOLERANCE = 0.25 * LINEAR_SLOP
"""b2TimeOfImpact's ``tolerance``: 0.00125 m either side of the target."""
TOI_NOTES = (
    "Times of impact (2-D): b2TimeOfImpact on two circle proxies, sweeps over [0, 1] mapped to "
    "[0, duration] (toi = t x duration); normal from b2Distance's witness points at the "
    "sweeps' transforms at t. Box2D stops at an overlap of 3 b2_linearSlop = 0.015 "
    "(target = max(b2_linearSlop, totalRadius - 3 b2_linearSlop) between the centres, "
    "tolerance 0.25 b2_linearSlop): declared toi_target -0.015, toi_tolerance 0.00125; for a "
    "radius sum below 0.02 the centres stop at b2_linearSlop instead (declared "
    "toi_min_centre_distance 0.005). A pair that never "
    "overlaps by that much reads as no contact. e_failed and e_unknown raise (error rows). ")


@dataclass(frozen=True, slots=True)
class PreparedToi:
    """Two circle shapes and their sweeps over Box2D's [0, 1]; the case's duration."""

    a: Any
    b: Any
    sweep_a: Any
    sweep_b: Any
    duration: float


def _sweep(start: tuple[float, ...], end: tuple[float, ...]) -> Any:
    sweep = engine().b2Sweep()
    sweep.localCenter = (0.0, 0.0)
    sweep.c0 = (start[0], start[1])
    sweep.c = (end[0], end[1])
    sweep.a0 = 0.0
    sweep.a = 0.0
    sweep.alpha0 = 0.0
    return sweep


def prepare(case: ToiCase) -> PreparedToi:
    """Shapes and sweeps; raises ``ValueError`` for inputs Box2D would take unchecked."""
    why = refusal(case)
    if why:
        raise ValueError(why)
    b2 = engine()
    end_a, end_b = end_centres(case)
    return PreparedToi(b2.b2CircleShape(radius=case.a.radius),
                       b2.b2CircleShape(radius=case.b.radius),
                       _sweep(case.a.center, end_a), _sweep(case.b.center, end_b),
                       case.duration)


def query(p: PreparedToi) -> Observation:
    """``b2TimeOfImpact``, and ``b2Distance`` at its time for the normal."""
    b2 = engine()
    state, t = b2.b2TimeOfImpact(shapeA=p.a, shapeB=p.b, sweepA=p.sweep_a, sweepB=p.sweep_b,
                                 tMax=1.0)
    out = b2.b2TOIOutput
    if state == out.e_separated:
        return no_contact()
    if state not in (out.e_touching, out.e_overlapped):
        names = {out.e_failed: "e_failed", out.e_unknown: "e_unknown"}
        raise RuntimeError(f"b2TimeOfImpact ended in state {names.get(state, state)} "
                           f"(t = {float(t)!r} of [0, 1]): no time of impact")
    t = float(t)
    near = b2.b2Distance(shapeA=p.a, shapeB=p.b, transformA=p.sweep_a.GetTransform(t),
                         transformB=p.sweep_b.GetTransform(t), useRadii=False)
    dx, dy = near.pointB[0] - near.pointA[0], near.pointB[1] - near.pointA[1]
    length = math.hypot(dx, dy)
    normal = ((dx / length, dy / length) if length > 0
              else Undefined("b2Distance's witness points coincide at the reported time"))
    return Observation(hit=True, toi=t * p.duration, normal=normal)
