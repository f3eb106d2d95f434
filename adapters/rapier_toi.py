"""Rapier's shape cast for ``sphere_toi`` cases, for both Rapier variants (rapier3d 0.36.1).

The Python bindings expose no pairwise ``cast_shapes`` (parry's function of two shapes, two
poses and two velocities): the shape cast they have is ``QueryPipeline.cast_shape(pose,
velocity, shape, options)``, a shape moving with a constant velocity against the colliders
of a set, which stay where they are.  So the case is cast in B's frame of motion
(translation only, so this is exact): ``prepare`` puts B's ball as a standalone collider at
B's start centre in a new ``ColliderSet``, builds the ``QueryPipeline`` over it
(``BroadPhaseBvh``, ``NarrowPhase``, ``RigidBodySet``, then ``update``), A's
``SharedShape.ball`` at A's start centre, the relative velocity ``va - vb`` (float64, here)
and ``ShapeCastOptions(max_time_of_impact=duration, target_distance=0,
stop_at_penetration=True, compute_impact_geometry_on_penetration=True)`` (the defaults but
the time); ``query`` makes the one ``cast_shape`` call.  The cast's time is in the case's
units (the velocity is per second): ``toi`` = ``ShapeCastHit.time_of_impact``.  2-D cases
lie in the plane z = 0; answers come back without z.  f32 throughout (``Real``).

- no hit (``None``): ``hit`` False, ``toi`` and ``normal`` Undefined;
- a hit: ``hit`` True, ``toi`` its time, ``normal`` = ``-normal1``: ``normal1`` is the
  outward normal of the hit collider (B) at the impact, in world space, pointing to A
  (the engine's normal, used as the engine gives it: parry builds it as ``dpt / radius``
  without normalising, ``Unit::new_unchecked``, so its length may differ from 1 by f32
  rounding; measured 1.000011 on the head-on pair).  Already overlapping at the start: the
  cast reports time 0 (status ``PENETRATING_OR_WITHIN_TARGET_DIST``) and a normal of length
  ``|cb - ca| / (ra + rb)``, not 1 (measured: 0.5 for centres 0.05 apart, radii 0.05): the
  ray starts inside the summed ball and parry divides by the radius all the same; reported
  as the engine gives it (scored against the unit direction: a wrong normal).

Conventions (parry v0.25.3, the nearest tag we can read to the wheel's parry3d 0.31.1,
:data:`SOURCES`): two balls take ``cast_shapes_ball_ball`` (shape_cast_ball_ball.rs), which
is analytic, a ray cast against the ball of the summed radii plus ``target_distance``
(``ray_toi_with_ball``, solid): no iteration and no termination tolerance.  Declared
``toi_target`` 0 (``target_distance`` 0: "considered as impacting as soon as their
distance is smaller or equal to this target distance", shape_cast.rs) and ``toi_tolerance``
0; the error is f32 rounding, the adapter's ``rtol`` (2^-21).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from adapters.sphere_toi import no_contact, refusal
from crosscheck.core.geometry import to3
from crosscheck.core.model import Observation
from crosscheck.core.schema import ToiCase

if TYPE_CHECKING:
    import rapier3d

PARRY = "https://github.com/dimforge/parry/blob/v0.25.3/src/query/"
SOURCES = (
    "https://github.com/dimforge/rapier/blob/v0.35.2/python/rapier-py-3d/python/rapier3d/"
    "_rapier3d.pyi",  # QueryPipeline.cast_shape, ShapeCastOptions, ShapeCastHit
    PARRY + "shape_cast/shape_cast.rs",  # ShapeCastOptions, ShapeCastHit, statuses
    PARRY + "shape_cast/shape_cast_ball_ball.rs",  # analytic: ray against the summed ball
    PARRY + "ray/ray_ball.rs",  # ray_toi_with_ball
)
TOI_NOTES = (
    "Times of impact: QueryPipeline.cast_shape of A's ball with velocity va - vb against B's "
    "ball at rest (B's frame; exact for translations), ShapeCastOptions(max_time_of_impact="
    "duration, target_distance=0, stop_at_penetration=True); parry's ball-ball cast is "
    "analytic (toi_target 0, toi_tolerance 0, f32); normal = -normal1 as the engine gives it "
    "(not renormalised). ")


@dataclass(frozen=True, slots=True)
class PreparedToi:
    """B's collider in a query pipeline; A's ball, pose and relative velocity; the options."""

    pipeline: rapier3d.QueryPipeline
    colliders: rapier3d.ColliderSet
    shape: rapier3d.SharedShape
    pose: rapier3d.Isometry3
    velocity: tuple[float, float, float]
    options: rapier3d.ShapeCastOptions
    dim: int


def prepare(case: ToiCase) -> PreparedToi:
    """Everything the cast needs; raises ``ValueError`` for inputs rapier would take unchecked."""
    import rapier3d as rp

    why = refusal(case)
    if why:
        raise ValueError(why)
    colliders = rp.ColliderSet()
    colliders.insert(rp.Collider.new(rp.SharedShape.ball(case.b.radius))
                     .translation(to3(case.b.center)).build())
    bodies = rp.RigidBodySet()
    pipeline = rp.QueryPipeline(rp.BroadPhaseBvh(), rp.NarrowPhase(), bodies, colliders)
    pipeline.update(bodies, colliders)
    velocity = to3(tuple(a - b for a, b in zip(case.a.velocity, case.b.velocity, strict=True)))
    options = rp.ShapeCastOptions(max_time_of_impact=case.duration, target_distance=0.0,
                                  stop_at_penetration=True,
                                  compute_impact_geometry_on_penetration=True)
    return PreparedToi(pipeline, colliders, rp.SharedShape.ball(case.a.radius),
                       rp.Isometry3(to3(case.a.center)), velocity, options, case.dim)


def query(p: PreparedToi) -> Observation:
    """The one ``cast_shape`` call, mapped to the harness's conventions."""
    found: Any = p.pipeline.cast_shape(p.pose, p.velocity, p.shape, p.options)
    if found is None:
        return no_contact()
    _, hit = found
    n = hit.normal1.to_tuple()
    return Observation(hit=True, toi=float(hit.time_of_impact),
                       normal=tuple(-float(x) for x in n[:p.dim]))
