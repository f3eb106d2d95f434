"""Gravity and static walls of a Rapier scene (:mod:`adapters.rapier_scene`), and what they
declare.

Walls: one fixed rigid body (``RigidBody.fixed()``, infinite mass, at the origin) carries
one ``Collider.halfspace(normal)`` per wall, translated to ``normal x offset``: parry's
``HalfSpace`` is the solid ``normal . x <= 0`` of its frame with ``normal`` the outward
normal (_rapier3d.pyi ``halfspace(outward_normal)``; parry ``shape/half_space.rs``), exactly
the scene's :class:`adapters.scene.Wall`.  A half-space is solid all the way down and has no
edge, so a sphere cannot tunnel through it or slip past its side (a sphere that sinks in
during a step is pushed back out), and no huge box costs float32 precision; the offset
itself is rounded to float32 (``Real``), as every centre is.  Colliders of one body never
pair, and fixed-fixed pairs are off by default (``ActiveCollisionTypes``,
collider_components.rs): walls never collide with each other.  A 2-D scene's walls are the
same half-spaces with a normal in the plane z = 0.  Gravity is ``PhysicsWorld.gravity`` (the
scene's, z 0 in 2-D); open space keeps gravity 0 and no body is added, so its worlds are the
ones built before walls existed.

The wall's material is the variant's, with the scene's e: tuned friction 0 and restitution e
under the variant's rule (Max: max(e, e) = e), default friction 0.5 (the ColliderBuilder
default) and restitution e under rapier's default Average ((e + e) / 2 = e): the stronger
rule of the two colliders applies (coefficient_combine_rule.rs), and a sphere gets the
same rule, so a sphere-wall contact bounces with e exactly as a sphere-sphere one.

Conventions (declared in ``adapters.rapier.TUNED`` / ``DEFAULT``, with :data:`TUNED_NOTES` /
:data:`DEFAULT_NOTES`; sources :data:`SOURCES`, Rapier files at v0.35.2):

- rest gap: no slop band.  "No slop deadzone on the position-correction bias"
  (``ContactWithCoulombFrictionBuilder::update``, contact_with_coulomb_friction.rs): a
  penetration is pushed out towards 0, and ``normalized_allowed_linear_error`` (0.005) is
  "geometric slop ... e.g. the standoff kept by the CCD clamp. NOT a deadzone"
  (integration_parameters.rs).  Predictive contacts (prediction distance 0.02 default, 0
  tuned plus soft CCD) push only what would overlap, so a body does not rest above the
  wall either: ``rest_gap`` (0, 0).
- sink: the contact is a spring (``SpringCoefficients``: ``erp``/``cfm`` from a natural
  frequency and damping ratio), and a contact with a fixed body uses
  ``static_contact_softness``, 60 Hz (``contact_static_defaults``; 30 Hz between two dynamic
  bodies, ``contact_defaults``), in both variants.  A spring of natural frequency f
  carrying its own body's weight deflects g / (2 pi f)^2: ``rest_sink_s2`` =
  1 / (2 pi 60)^2 = 7.036e-6 s^2 (6.9e-5 m at g 9.81), independent of dt: the soft step's
  fixed point (gravity g h, one warm-started PGS pass with ``erp_inv_dt`` E and
  ``cfm_factor`` 1 / (1 + c), positions moved only by the biased velocity) is a gap -g h c /
  E, and c / E = 1 / (h omega^2) for any substep h (``SpringCoefficients::cfm_coeff``,
  ``erp_inv_dt``); ``rest_sink_steps`` 0.  Measured below.
- sleeping: tuned ``can_sleep(False)``; default sleeps a body whose farthest point moved
  less than 2 x ``normalized_linear_threshold`` (0.05 m/s) x dt a step (``drift * 0.5 <
  linear_threshold * dt``: slower than 0.1 m/s) for
  ``time_until_sleep`` 0.5 s (``RigidBodyActivation::update_energy``,
  rigid_body_components.rs): a sphere resting on the ground falls asleep, its velocity 0.
- restitution with walls: as between spheres (above); no threshold in either variant
  (``is_bouncy``: e > 0, contact_pair.rs).  A bounce is resolved at a step's end: in the
  tuned variant (prediction distance 0, soft CCD) the predictive contact stops a falling
  sphere at the wall in the step it would cross it and the end-of-step restitution sends
  it back at e x its speed at that step's start, so the height it had then is lost (an
  elastic drop loses apex height at every bounce, the more the larger dt; measured).  In
  the default variant a sphere further than 0.02 from the wall at a step's start is not
  stopped: it sinks into the wall that step and leaves at e x its speed there.

Measured with a throwaway script outside the suite, ``.venv/bin/python script.py`` running
``rapier_scene.prepare_scene([((0, 0, 0.1), 0.1, 1.0, (0, 0, 0))], 3, 0.0, dt, iterations,
variant.scene_tuning, Surroundings((0, 0, -9.81), (Wall((0, 0, 1), 0.0),)))`` and
``run_scene(..., record_every=1)`` for each variant, 2-D alike (a sphere r = 0.1, m = 1
starting on a ground at 0, 3 and 10 s, dt 1/60 to 1e-4, 1 to 8 iterations; and a column of
three such spheres):

- the steady gap is -g / (2 pi 60)^2 = -6.90e-5 m to within 0.3% at dt 1/60 to 1/240 and
  1.8% at 1/1000 with 4 iterations (both variants, 2-D and 3-D alike, rapier-ccd as tuned):
  float32 stops
  the approach short: a centre no longer moves once a substep's displacement is below half
  an ulp of its coordinate, and the slow mode of the overdamped spring (damping ratio 10)
  moves it by about ``h / (2 zeta / omega)`` of the distance left per substep ``h = dt /
  iterations``, so the gap freezes within about ``ulp / 2 x 2 zeta / (omega h)`` of the
  spring's rest (4.8e-8 m at h = 1/240, 4.7e-7 at 1/1920), and far from it at tiny substeps
  (dt 1e-4 with 4 iterations: -1.9e-5 m; with 8: -6.6e-8).
- in a column the penetration of each contact is the weight it carries over ``m_eff (2 pi
  f)^2`` (``m_eff`` the pair's projected mass, m1 m2 / (m1 + m2) between spheres; f 60 Hz
  at the wall, 30 Hz between spheres): 3 g / omega_60^2, then 4 and 2 g / omega_30^2 from
  the ground up, within
  0.2% in the tuned variant; the default variant's spheres fall asleep while still sinking
  (up to 13% short).
- the tuned sphere's velocity at rest is exactly 0 (the rigid relax pass), so no jitter;
  starting on the ground it first dips about 0.6 |g| dt^2 (prediction distance 0: no
  contact at distance 0 until it moves) and is back at the spring's rest within 0.5 s.  The default
  sphere sleeps after 0.5 s.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from adapters.scene import Surroundings
from crosscheck.core.geometry import to3

if TYPE_CHECKING:
    import rapier3d

RAPIER = "https://github.com/dimforge/rapier/blob/v0.35.2/"
SOURCES = (
    RAPIER + "src/dynamics/integration_parameters.rs",  # static_contact_softness, 60 Hz
    RAPIER + "src/dynamics/solver/contact_constraint/contact_with_coulomb_friction.rs",
    RAPIER + "src/dynamics/rigid_body_components.rs",  # RigidBodyActivation
    RAPIER + "src/dynamics/coefficient_combine_rule.rs",
    "https://github.com/dimforge/parry/blob/v0.25.3/src/shape/half_space.rs",
)
STATIC_CONTACT_HZ = 60.0
"""``SpringCoefficients::contact_static_defaults().natural_frequency`` (Hz): the softness of
a contact with a fixed body (integration_parameters.rs)."""
REST_SINK_S2 = 1.0 / (2.0 * math.pi * STATIC_CONTACT_HZ) ** 2
"""A resting sphere's penetration over |g| (s^2): a spring's static deflection 1 / omega^2."""
SLEEP_SPEED = 0.05
"""``RigidBodyActivation::default_normalized_linear_threshold`` (m/s, length_unit 1)."""
SLEEP_AFTER = 0.5
"""``RigidBodyActivation::default_time_until_sleep`` (s)."""

_COMMON = ("Walls: one fixed body with a HalfSpace collider per wall (no thickness, no "
           "extent: nothing tunnels), friction and restitution rule the variant's, "
           "restitution e: a sphere-wall contact bounces with e as a sphere pair does.  Rest: "
           "no slop deadzone (contact_with_coulomb_friction.rs), so rest_gap (0, 0); a contact "
           "with a fixed body is a 60 Hz spring (static_contact_softness, "
           "integration_parameters.rs), deflecting |g| / (2 pi 60)^2 under a sphere's weight "
           "(rest_sink_s2; between two spheres 30 Hz, contact_softness).  ")
TUNED_NOTES = _COMMON + "Tuned: no sleeping (can_sleep False), wall friction 0.  "
DEFAULT_NOTES = _COMMON + (
    f"Default: a body moving less than {SLEEP_SPEED} m/s for {SLEEP_AFTER} s sleeps, its "
    "velocity 0 (RigidBodyActivation, rigid_body_components.rs); wall friction 0.5.  ")


def check_f32(surroundings: Surroundings, largest: float) -> None:
    """Raise ``OverflowError`` for gravity or a wall offset beyond ``largest`` (float32's)."""
    named = [("gravity", g) for g in surroundings.gravity]
    named += [(f"wall {k} offset", w.offset) for k, w in enumerate(surroundings.walls)]
    for name, x in named:
        if abs(x) > largest:
            raise OverflowError(f"{name} {x!r} is beyond float32's largest finite value")


def wall_collider(normal: tuple[float, ...], offset: float, restitution: float,
                  tuned: bool, rule: str) -> rapier3d.ColliderBuilder:
    """A wall's half-space collider, placed on its fixed body, with the variant's material."""
    import rapier3d as rp

    n = to3(normal)
    builder = rp.Collider.halfspace(n).translation((offset * n[0], offset * n[1], offset * n[2]))
    builder = builder.restitution(restitution)
    if tuned:
        builder = (builder.friction(0.0)
                   .restitution_combine_rule(getattr(rp.CoefficientCombineRule, rule)))
    return builder


def add_surroundings(world: rapier3d.PhysicsWorld, surroundings: Surroundings,
                     restitution: float, tuned: bool, rule: str) -> None:
    """Set the world's gravity and add the walls (one fixed body) if there are any."""
    import rapier3d as rp

    if any(surroundings.gravity):
        world.gravity = rp.Vec3(*to3(surroundings.gravity))
    if surroundings.walls:
        colliders: list[rapier3d.Collider | rapier3d.ColliderBuilder] = [
            wall_collider(w.normal, w.offset, restitution, tuned, rule)
            for w in surroundings.walls]
        world.add_body(rp.RigidBody.fixed(), colliders)
