"""Rapier (rapier3d 0.36.1) stepping a scene of N spheres: variant settings, walls, measures.

What it is for: a scene (N spheres, one restitution, in open space or under gravity between
static walls) is stepped with a fixed ``dt`` by the scene calls of :mod:`adapters.rapier.calls`
(``scene``, ``step_scene``, ``release_scene``).  Here: what a variant sets (:class:`Tuning`),
its inputs to the scene calls (:func:`scene_settings`), what its walls declare, and what was
measured with those calls.  Checks and recording are shared (:mod:`adapters.shared.scene`).

Building (``scene``, untimed): a new ``PhysicsWorld`` per scene (gravity 0;
:func:`adapters.rapier.calls.new_world`) with the scene's ``dt`` and, if given,
``num_solver_iterations`` (else rapier's 4); one dynamic body per sphere at its centre with
its velocity (``in_plane``: a 2-D scene lies in z = 0 with z translation locked, as the
responses do: a 3-D build in the plane, 2-D walls are half-spaces with a normal in it)
carrying ``Collider.ball(r).mass(m)`` with restitution e; then the ``surroundings``' gravity
and walls (below: one fixed body with a ``HalfSpace`` collider per
wall, the variant's material with restitution e; open space adds nothing, so its worlds are
unchanged).  The builders are the response adapter's (:mod:`adapters.rapier.calls`).
Numbers float32 cannot hold raise ``OverflowError`` (rapier would read them as infinite).
``step_scene`` times only ``PhysicsWorld.step`` (``adapters.shared.scene.step_and_record``,
reading ``translation`` / ``linvel`` untimed between runs of steps) and raises if rapier
quarantined a non-finite body; ``release_scene`` empties the world.  Resting contact,
sleeping and bounces on walls, with what was measured: below.

Variants (``tuning``, passed in by the adapter: a :class:`Tuning` or None): tuned
(``rapier``) passes the pair adapter's ``IntegrationParameters`` (normalized prediction
distance 0, no speed cap: ``normalized_max_linear_velocity`` f32::MAX; its dt replaced by the
scene's) and gets its bodies (no sleeping, ``soft_ccd_prediction`` 1e30, rotations locked,
damping 0) and colliders (friction 0), restitution e on every collider combined by Max.
Default (``rapier-default``) passes None and sets only what the scene declares: dt,
iterations if given, masses, radii, velocities and restitution e on every collider (combined
by rapier's default Average); prediction distance 0.02, friction 0.5, free rotation,
sleeping and the speed cap 400 stay.

Conventions, measured with the scene calls on rapier3d 0.36.1 (sources as cited in
``adapters.rapier.SOURCES``; sleeping: ``RigidBodyActivation`` in _rapier3d.pyi and
rigid_body_components.rs):

- restitution: the stronger ``CoefficientCombineRule`` of two colliders wins
  [coefficient_combine_rule.rs]; every collider gets e, so Max (tuned) and Average (default)
  both give e, rounded to float32: a head-on pair at e = 0.25 and 0.5 leaves at exactly e,
  at 0.81 at 0.8100000023841858 (float32 of 0.81), in both variants.  No restitution
  threshold (a contact bounces when e > 0, ``is_bouncy`` in contact_pair.rs): a pair closing
  at 0.02 with e = 0.5 leaves at 0.01 in the tuned variant.
- speed cap: tuned none (a free body at 1000 keeps 1000); default 400 (a free body at 1000
  is at 400 after a step) [integration_parameters.rs].  In a scene it is a fixed speed, not a
  travel per step: a free body at 1000 leaves its first step at 400 having moved 400 dt, at
  dt 1e-3, 1/240 and 1/60 alike, so a scene starting above it moves as if it started at 400.
  A bounce can leave a step above it (it comes after the cap: A at 1000 onto a touching B at
  rest, e = 1, leaves the first step at -100 and 900, dt 1/60 and 1/240, as declared "before
  restitution" for responses); the next step caps it.
- fast bodies (two balls r = 0.05, e = 1, head-on at +-v from 0.6 apart, v 5 to 1000, dt
  1/240 and 1/60): tuned catches every impact (soft CCD: predictive contacts whatever the
  travel) and exchanges the velocities exactly; default passes through from step travel
  |vb - va| dt / 2(ra + rb) 2.08 at 1/240 (v = 50; v = 20 is caught by the 0.02 prediction
  distance) and 0.83 at 1/60 (v = 20), its speeds capped at 400.  ``ccd_enabled`` changes
  none of these, tuned or default, nor with soft CCD off (then tuned passes through from v
  = 20 at 1/240): Rapier's CCD sweeps a fast body against fixed colliders, and a
  ``ccd_enabled`` body ("bullet") also against moving bodies but "never sweeps another
  bullet, so two bullets can still tunnel through each other" (``RigidBody::enable_ccd``,
  rigid_body.rs; ccd_solver.rs, v0.35.2).  ``rapier-ccd`` (:mod:`adapters.rapier`)
  enables it on every body of the tuned variant.
- sleeping: tuned none.  Default: a body slower than about 0.1 m/s (bisected: 0.1000017 at dt
  1e-3; ``linear_threshold`` reads 0.05, ``time_until_sleep`` 0.5) falls asleep, its velocity
  set to 0, after 0.5 to 1.2 s (depending on dt): momentum is lost.  Declared ``sleeps``
  True (False tuned), sources in :data:`SOURCES`.
- soft contact and margins: contacts are predictive (formed within the prediction distance,
  0 tuned plus soft CCD's reach, 0.02 default) and push only what the step would bring into
  overlap: a pair 0.01 apart closing at 1 at dt 1e-3 is untouched in a step in both
  variants.  Overlaps are corrected on positions only (pair at rest overlapping by 0.01:
  velocities stay exactly 0, each centre moves 0.0018 away in 100 steps at dt 1e-3).
- touching at the start (distance 0) is a contact: one ball moving at 1 into a touching one
  exchanges velocities in step 1 (both variants); touching balls moving together at 0.3 get
  no impulse (100 steps, velocities float32 0.3).
- simultaneous contacts: tuned, a 5-ball cradle (equal masses, e = 1, striker at 1, dt 1e-3)
  ends as the textbook cradle: the last ball at 1.0, the others 0 (iterations 1, 4 and 50),
  energy to 3e-15.  Default: the chain answers softly, as a whole: after one step the
  striker has -0.278 and the others share the rest; energy loses 19% to 24% (iterations 1,
  4, 50), and a ball left slower than the sleep threshold falls asleep, so momentum ends off
  by up to 7.5% (at 4 iterations with sleeping off it is kept to float32 rounding).
- energy at e = 1: tuned keeps kinetic energy to float32 rounding where impacts are apart (16
  random spheres, 2-D and 3-D, 3 s at dt 1e-3 and 1/60: relative change <= 3.6e-8, momentum
  within 5.9e-7), but a rack of nearly touching balls gains energy: the suite's billiards
  break (15 balls 1e-3 apart, cue ball at 2, kinetic energy 2) ends with 2.26 at dt 1e-3,
  2.65 at 1/240 and 2.48 at 0.1, momentum kept to 1e-7 (cause not established).  Default
  loses 3% (3-D) to 8% (2-D) in the same scenes: friction 0.5 with free rotation turns
  oblique impacts' tangential speed into spin (linear momentum kept within 4.1e-7); rapier's
  linear damping is 0 in both (``damping`` 0 declared).
- impacts are resolved at step ends: centres differ from the exact run by up to the
  closing speed x dt (head-on pair at 1, e = 1: 9.3e-4 at dt 1e-3, both variants alike).

Gravity and static walls, and what they declare.

Walls: one fixed rigid body (``RigidBody.fixed()``, infinite mass, at the origin) carries
one ``Collider.halfspace(normal)`` per wall, translated to ``normal x offset``: parry's
``HalfSpace`` is the solid ``normal . x <= 0`` of its frame with ``normal`` the outward
normal (_rapier3d.pyi ``halfspace(outward_normal)``; parry ``shape/half_space.rs``), exactly
the scene's wall (``(normal, offset)``).  A half-space is solid all the way down and has no
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
the scene calls on one sphere on a ground (gravity -9.81 along z, e 0, a variant's
``scene_tuning`` and the scene's dt and iterations, every step recorded) for each variant,
2-D alike (a sphere r = 0.1, m = 1
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
from dataclasses import dataclass
from typing import Any

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



@dataclass(frozen=True)
class Tuning:
    """Settings a variant adds to a scene; ``None`` instead of a Tuning: rapier's defaults.

    ``parameters``: ``IntegrationParameters`` overrides (a ``dt`` among them is replaced by
    the scene's); with a Tuning every body and collider is the tuned variant's
    (:func:`adapters.rapier.calls.tuned_body`, ``tuned_collider`` with restitution e on
    every collider, combined by ``rule``); ``ccd``: every body also ``ccd_enabled``.
    """

    parameters: tuple[tuple[str, float], ...]
    rule: str = "MAX"
    ccd: bool = False
    """Every body ``ccd_enabled`` (``RigidBodyBuilder.ccd_enabled(True)``), the
    ``rapier-ccd`` variant's switch."""


def scene_settings(tuning: Tuning | None) -> dict[str, Any]:
    """A variant's inputs to the scene calls besides the scene (None: rapier's defaults).

    >>> scene_settings(None)
    {'parameters': (), 'tuned': False, 'rule': 'AVERAGE', 'ccd': False}
    """
    if tuning is None:
        return {"parameters": (), "tuned": False, "rule": "AVERAGE", "ccd": False}
    return {"parameters": tuning.parameters, "tuned": True, "rule": tuning.rule,
            "ccd": tuning.ccd}
