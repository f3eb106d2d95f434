"""Stepping a ``sphere_response`` case in rapier3d (the response half of the rapier adapter).

The adapter's ``prepare`` makes the builders (two dynamic bodies at the case's centres with
its velocities, each carrying ``Collider.ball(r).mass(m)`` and the variant's settings) and
the ``IntegrationParameters`` overrides; :func:`respond` builds a new ``PhysicsWorld``
(gravity 0) from them on every query, so every query is the first (builders are copied on
insertion), and steps it up to the first step after which the pair carries a normal impulse
(``ContactPair.total_impulse_magnitude() > 0``), or until the bodies stop approaching
without one (``MAX_STEPS`` at most).  ``resolved_at`` is the centres at the start of that
step: ``PhysicsPipeline.step`` computes contacts before it solves, so they are the
configuration the solver resolved.  One step, not more: a contact that persists is no
longer "new" (it bounces only if e >= 1, contact_pair.rs), and an inelastic pair sliding
along each other would be pushed again around a turning normal, which the textbook's single
impulse is not.

Why the tuned variant keeps dt = 1/60: its bodies have ``soft_ccd_prediction``, so a
touching or closing pair gets a predictive contact and is resolved in the step in which it
meets, at the centres that step starts from.  The one step-size effect left is a predictive
contact that starts a float32 rounding apart (dist ~1e-7 > 0): it lets an inelastic pair
keep approaching at dist / substep.  Measured on 300 random touching or closing pairs
against the truth where each was resolved: worst velocity error 9.4e-6 x the speed at dt
1/60, 6e-5 at 1/240 and 4e-4 at 1e-3 (medians 1e-7 for all three); more substeps did not
help consistently.

A body whose state became non-finite is neutralised by rapier (``PhysicsWorld.quarantine``):
:func:`respond` raises then (measured for an infinite velocity or restitution).  A 2-D case
runs at z = 0 with z translation locked; a result with vz != 0 raises.  Conventions and
sources: :mod:`adapters.rapier_engine`.

The builders of the variants' bodies and colliders (:func:`tuned_body`, :func:`default_body`,
:func:`tuned_collider`, :func:`default_collider`, :func:`in_plane`) and :func:`new_world` are
shared with the scene runner :mod:`adapters.rapier_scene`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from crosscheck.core.geometry import Vec, Vec3, approach_speed
from crosscheck.core.model import Observation

if TYPE_CHECKING:
    import rapier3d

SOFT_CCD = 1e30
"""Tuned bodies' ``soft_ccd_prediction``: no bound on the predictive reach of a step."""
MAX_STEPS = 100_000
APPROACH_RTOL = 2.0**-20
"""A response stops once the approach speed is below this x the case's largest speed."""


@dataclass(frozen=True, slots=True)
class Response:
    """What a response query builds its world from (builders are copied on insertion)."""

    bodies: tuple[rapier3d.RigidBodyBuilder, rapier3d.RigidBodyBuilder]
    colliders: tuple[rapier3d.ColliderBuilder, rapier3d.ColliderBuilder]
    parameters: tuple[tuple[str, float], ...]
    dim: int
    tol: float


def tuned_body(centre: Vec3, velocity: Vec3) -> rapier3d.RigidBodyBuilder:
    """The tuned variant's body: no sleeping, soft CCD, rotations locked, no damping."""
    import rapier3d as rp

    return (rp.RigidBody.dynamic().translation(centre).linvel(velocity).can_sleep(False)
            .soft_ccd_prediction(SOFT_CCD).locked_axes(rp.LockedAxes.ROTATION_LOCKED)
            .linear_damping(0.0).angular_damping(0.0))


def default_body(centre: Vec3, velocity: Vec3) -> rapier3d.RigidBodyBuilder:
    """The default variant's body: only its centre and velocity."""
    import rapier3d as rp

    return rp.RigidBody.dynamic().translation(centre).linvel(velocity)


def in_plane(builder: rapier3d.RigidBodyBuilder, dim: int) -> rapier3d.RigidBodyBuilder:
    """A 2-D body keeps to the plane z = 0 (z translation locked); a 3-D one is unchanged."""
    return builder.enabled_translations((True, True, False)) if dim == 2 else builder


def tuned_collider(radius: float, mass: float, restitution: float,
                   rule: str = "MULTIPLY") -> rapier3d.ColliderBuilder:
    """The tuned variant's ball: friction 0, ``restitution`` combined by ``rule`` (the name
    of a ``CoefficientCombineRule``)."""
    import rapier3d as rp

    return (rp.Collider.ball(radius).mass(mass).friction(0.0).restitution(restitution)
            .restitution_combine_rule(getattr(rp.CoefficientCombineRule, rule)))


def default_collider(radius: float, mass: float, restitution: float) -> rapier3d.ColliderBuilder:
    """The default variant's ball: its mass and restitution, the rest rapier's defaults."""
    import rapier3d as rp

    return rp.Collider.ball(radius).mass(mass).restitution(restitution)


def new_world(parameters: tuple[tuple[str, float], ...]) -> rapier3d.PhysicsWorld:
    """A ``PhysicsWorld`` with gravity 0 and these ``IntegrationParameters`` overrides."""
    import rapier3d as rp

    world = rp.PhysicsWorld(gravity=(0.0, 0.0, 0.0))
    params = world.integration_parameters
    for key, value in parameters:
        setattr(params, key, value)
    return world


def pushed(world: rapier3d.PhysicsWorld) -> bool:
    """Whether the last step's solver put a normal impulse on the contact between A and B."""
    return any(pair.total_impulse_magnitude() > 0.0 for pair in world.narrow_phase.contact_pairs())


def respond(p: Response) -> Observation:
    """Step a new world up to the first step whose solver pushed A and B apart, or until they
    no longer approach without having touched (or ``MAX_STEPS``)."""
    world = new_world(p.parameters)
    handles = [world.add_body(body, [collider])
               for body, collider in zip(p.bodies, p.colliders, strict=True)]
    a, b = (world.rigid_bodies[h] for h in handles)
    resolved: tuple[Vec3, Vec3] | None = None
    for _ in range(MAX_STEPS):
        pa, pb = a.translation.to_tuple(), b.translation.to_tuple()
        world.step()
        va, vb = a.linvel.to_tuple(), b.linvel.to_tuple()
        if pushed(world):
            resolved = (pa, pb)  # the contact this step resolved was computed here
            break
        if not approach_speed(pa, pb, va, vb) > p.tol:  # NaN (coincident centres): stop
            break
    if not world.quarantine.is_empty():
        raise FloatingPointError(f"rapier quarantined a body whose state became non-finite "
                                 f"({world.quarantine})")
    return observed(p.dim, va, vb, resolved)


def observed(dim: int, va: Vec3, vb: Vec3, resolved: tuple[Vec3, Vec3] | None) -> Observation:
    """A response observation in ``dim`` dimensions; a 2-D result must stay in z = 0."""
    if dim == 3:
        return Observation(v1=va, v2=vb, resolved_at=resolved)
    if abs(va[2]) > 0.0 or abs(vb[2]) > 0.0:
        raise RuntimeError(f"2-D response left the plane z = 0: vz = {va[2]!r}, {vb[2]!r}")
    at: tuple[Vec, Vec] | None = None
    if resolved is not None:
        at = (resolved[0][:2], resolved[1][:2])
    return Observation(v1=va[:2], v2=vb[:2], resolved_at=at)
