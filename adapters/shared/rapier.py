"""What Rapier's pair calls and its scene runner share: the variants' body and collider builders
and a world; plain, so a repro script holds this source (until the scenes are calls of
:mod:`adapters.rapier.calls`, which then holds it).  rapier3d is imported inside each function
(importing this module imports no engine).

- tuned bodies: no sleeping, soft CCD (``soft_ccd_prediction`` :data:`SOFT_CCD`), rotations
  locked, no damping; default bodies: only a centre and a velocity;
- a 2-D body keeps to the plane z = 0 (z translation locked);
- tuned balls: friction 0, a restitution combined by a named rule; default balls: a mass
  and a restitution;
- a ``PhysicsWorld`` with gravity 0 and ``IntegrationParameters`` overrides.
"""

from typing import Any

SOFT_CCD = 1e30
"""Tuned bodies' ``soft_ccd_prediction``: no bound on the predictive reach of a step."""


def tuned_body(centre: Any, velocity: Any) -> Any:
    """The tuned variant's body: no sleeping, soft CCD, rotations locked, no damping."""
    import rapier3d as rp

    return (rp.RigidBody.dynamic().translation(centre).linvel(velocity).can_sleep(False)
            .soft_ccd_prediction(SOFT_CCD).locked_axes(rp.LockedAxes.ROTATION_LOCKED)
            .linear_damping(0.0).angular_damping(0.0))


def default_body(centre: Any, velocity: Any) -> Any:
    """The default variant's body: only its centre and velocity."""
    import rapier3d as rp

    return rp.RigidBody.dynamic().translation(centre).linvel(velocity)


def in_plane(builder: Any, dim: int) -> Any:
    """A 2-D body keeps to the plane z = 0 (z translation locked); a 3-D one is unchanged."""
    return builder.enabled_translations((True, True, False)) if dim == 2 else builder


def tuned_collider(radius: float, mass: float, restitution: float,
                   rule: str = "MULTIPLY") -> Any:
    """The tuned variant's ball: friction 0, ``restitution`` combined by ``rule`` (the name
    of a ``CoefficientCombineRule``)."""
    import rapier3d as rp

    return (rp.Collider.ball(radius).mass(mass).friction(0.0).restitution(restitution)
            .restitution_combine_rule(getattr(rp.CoefficientCombineRule, rule)))


def default_collider(radius: float, mass: float, restitution: float) -> Any:
    """The default variant's ball: its mass and restitution, the rest rapier's defaults."""
    import rapier3d as rp

    return rp.Collider.ball(radius).mass(mass).restitution(restitution)


def new_world(parameters: tuple[tuple[str, float], ...]) -> Any:
    """A ``PhysicsWorld`` with gravity 0 and these ``IntegrationParameters`` overrides."""
    import rapier3d as rp

    world = rp.PhysicsWorld(gravity=(0.0, 0.0, 0.0))
    params = world.integration_parameters
    for key, value in parameters:
        setattr(params, key, value)
    return world
