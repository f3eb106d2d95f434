"""Rapier through its official Python bindings (rapier3d 0.36.1): ``rapier``, ``rapier-default``.

rapier3d 0.36.1 is the PyO3 build of Rapier 0.36.1 (3-D, ``Real`` = f32) with parry3d
0.31.1 (the wheel's SBOM); it imports numpy undeclared (numpy is in our dependencies).
Kinds: ``aabb``, ``sphere``, ``sphere_response`` in 3-D, and in 2-D run in the plane z = 0
(as fcl does): a disc is a ball at z = 0, a 2-D box a cuboid with the z half-width of
:func:`crosscheck.core.geometry.z_half` (z is never the axis of least overlap nor a gap), a
2-D response locks z translation; answers come back as 2-tuples.  Scenes (``sphere_scene``,
2-D and 3-D) are the scene calls of :mod:`adapters.rapier.calls` with the variant's
``scene_tuning`` (:mod:`adapters.rapier.scene`: its settings, gravity and walls, and the
conventions as measured and declared).  Times of impact (``sphere_toi``, 2-D and
3-D) are a shape cast (``toi_target`` 0, ``toi_tolerance`` 0).

Detection.  The bindings expose no pairwise parry query (no ``contact``/``distance`` of two
shapes at two poses): the narrow phase is the pairwise query they have.  ``prepare`` builds
two standalone ``Collider`` s (``SharedShape.ball(radius)`` or ``SharedShape.cuboid`` with
half-extents, at the case's centres, identity rotation) with ``ActiveCollisionTypes.all()``:
a standalone collider counts as fixed, and the default types leave fixed-fixed pairs out
(collider_components.rs), so without it the pair is never formed (measured).  ``query``
runs two ``CollisionPipeline.step(prediction, ...)`` passes, each over a new ``ColliderSet``,
``BroadPhaseBvh`` and ``NarrowPhase`` (a set once stepped is invisible to a new broad phase,
measured; new sets make every query the first): the narrow phase calls parry's contact
manifold of the pair (contact_manifolds_ball_ball.rs, contact_manifolds_cuboid_cuboid.rs).

- ``hit``: ``ContactPair.has_any_active_contact`` at the variant's prediction distance: a
  pair has active (solver) contacts only for points with ``dist < prediction``
  (pair_update.rs), and a ball pair has contact points only for ``dist < prediction``.
- ``distance``, ``normal``: from a second pass whose prediction distance reaches past any gap
  (``1 + 2 (|cb - ca| + the sizes)``): the smallest ``ContactData.dist`` (signed, gap
  positive) and the world ``ContactManifoldData.normal`` of its manifold, which points from
  collider1 to collider2 (negated if rapier stores the pair as (B, A)).  No contact point:
  both Undefined, with the reason.

Response: the calls step a new world per query, built from the
builders ``prepare`` makes (dynamic bodies with ``Collider.ball(r).mass(m)``), up to the
first step whose solver pushed A and B apart; ``resolved_at`` is the centres at its start.

Variants (the sources are in ``SOURCES``; Rapier files at tag v0.35.2, the nearest tag to
0.36.1 we can read, parry files at v0.25.3; every fact below was re-measured with 0.36.1):

- ``rapier``: detection at prediction distance 0 (``dist < 0``).  Responses:
  ``normalized_prediction_distance`` 0, ``normalized_max_linear_velocity`` f32::MAX (no
  speed cap), dt 1/60 set explicitly, bodies ``soft_ccd_prediction`` 1e30 (predictive
  contacts whatever the step's travel), rotations locked, no sleeping, damping 0, friction
  0, restitution rule Multiply with A = e and B = 1 (e exactly); why not a smaller dt: see
  the module docstring's last paragraph.
- ``rapier-default``: only geometry, masses, velocities and restitution (both colliders e,
  averaged by the default rule: e exactly), plus ``ActiveCollisionTypes.all()`` for
  detection; prediction distance 0.02 (``IntegrationParameters().prediction_distance()``),
  dt 1/60, friction 0.5, rotation free, sleeping allowed, speeds capped at 400.

Conventions (declared in ``TUNED`` and ``DEFAULT``):

- box extents: half (``SharedShape.cuboid(hx, hy, hz)``) [_rapier3d.pyi]; normal from A to B
  (``ContactManifoldData.normal`` = collider1's rotation x ``local_n1``) [pair_update.rs].
- touching: a contact needs ``dist < prediction`` [contact_manifolds_ball_ball.rs,
  pair_update.rs].  ``rapier``: touching is apart at every feature (textbook for spheres,
  not for boxes).  ``rapier-default``: touching and gaps below 0.02 are contact (touching
  True, ``verdict_margins`` 0.019999999552965164 at every feature, integration_parameters.rs):
  the verdict only; distance and normal come from the wide pass (``margins`` {}).
- precision: f32 throughout, rtol 2^-21 (4 float32 ulps of the case's size; measured on
  2,000 random sphere and 2,000 box pairs at scales 1e-3 to 1e3: distances within 2.1e-7 x
  size; responses within 2^-21 x the speed but for the f32-gap effect above).
- restitution: ``CoefficientCombineRule`` (the stronger rule of the two colliders wins;
  Average by default) [coefficient_combine_rule.rs]; a new contact bounces when the combined
  e > 0 (``is_bouncy``) [contact_pair.rs]: no threshold (0).  The bounce is an end-of-step
  pass that sets the normal velocity to -e x the approach, only on a contact that carried a
  normal impulse, which is clamped at >= 0 [contact_constraint_element.rs]: bodies already
  separating are left alone (``resolves_separating`` False).
- time step: 1/60 s in both; damping 0 (rapier's default linear damping is 0).
- speed cap: "Maximum linear velocity a body may have after each solver substep" (400 m/s)
  [integration_parameters.rs], before the bounce [contact_constraint_element.rs]: declared
  "before restitution" in ``rapier-default`` (measured, ``speed-cap`` cases of
  cases/response.toml: A at 1000 m/s onto B, e = 1: plastic 500 each, capped to 400, then
  bounce -+500: -100 and 900); ``rapier`` none.
- mass 0 is immovable: parry's ``MassProperties`` stores ``inv(m)``, 0 for m = 0 exactly
  ("zero = infinite mass") [mass_properties.rs, utils/inv.rs]; ``zero_mass`` "static"
  (measured: a body of mass 0 at -1 sends the other back at -3 and keeps its velocity; a
  mass of 1e-21 is still a light body).  An infinite mass is immovable too.
- negative sizes read literally (``negative_extents`` ""; measured: a ball of radius -0.5 at
  0.75 from a unit ball reads 0.25 apart, a cuboid of half-width -1 the per-axis formula).

Faults measured here (pinned in tests/adapters/test_rapier.py; none is a documented rule, so
no ``no_value`` is declared and a missing value is ``error``):

- NaN anywhere, or an infinite centre or size, is ignored without a word (no contact pair,
  hit False; a NaN mass: no contact; a NaN restitution: no bounce).  ``check_inputs`` raises
  instead (recorded as ``error``), also for a finite number beyond float32's range.  An
  infinite velocity or restitution ends in rapier's quarantine: ``query`` raises.
- small boxes: a face contact needs the unnormalised face normal (4 hx hy of the reference
  face) above f32::EPSILON (parry's ``relative_eq!(denom, 0.0)`` in
  polygonal_feature3d.rs), so overlapping cubes of half-width <= 1.7263e-4 never collide
  (bisected) and zero-size boxes give no contact point at all.
- ball pairs whose squared centre distance overflows f32 (centres more than ~1.8e19 apart)
  give no contact point; centres far from the origin lose the gap to f32 rounding (at 1e8
  the spacing is 8: a 3-4-5 pair there reads coincident).
- separated boxes get a point in the wide pass only where the support faces overlap in
  projection (face, some edge and corner gaps); otherwise the distance is Undefined.
- a negative mass (1/ma + 1/mb < 0): no impulse, the bodies pass through each other; a
  negative restitution is read as 0.

Over 400 lines: about 120 of them are this docstring, the conventions as measured, and
the three variants' settings with their declared conventions belong together.

The calls, plain data in and out, are :mod:`adapters.rapier.calls`.  Responses: each ask
builds a new ``PhysicsWorld`` (gravity 0) from the builders, so every ask is the first
(builders are copied on insertion), and steps it up to the first step after which the pair
carries a normal impulse (``ContactPair.total_impulse_magnitude() > 0``), or until the bodies
stop approaching without one (``MAX_STEPS`` at most); ``resolved_at`` is the centres at the
start of that step (``PhysicsPipeline.step`` computes contacts before it solves).  One step,
not more: a contact that persists is no longer "new" (it bounces only if e >= 1,
contact_pair.rs).  The tuned variant keeps dt = 1/60: its bodies have
``soft_ccd_prediction``, so a closing pair is resolved in the step in which it meets
(measured on 300 random touching or closing pairs: worst velocity error 9.4e-6 x the speed
at dt 1/60, 6e-5 at 1/240, 4e-4 at 1e-3).  A body whose state became non-finite is
quarantined by rapier (``PhysicsWorld.quarantine``): the ask raises then.  Times of impact:
``QueryPipeline.cast_shape`` of A's ball with the relative velocity against B's at rest
(exact for translations; parry's ball-ball cast is analytic); inputs the engine would take
unchecked are refused (:func:`adapters.shared.toi_refusal`).  The builders are shared with
the scene runner (:mod:`adapters.rapier.calls`).
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import replace
from importlib import metadata
from typing import Any, ClassVar

from adapters.rapier import scene as rapier_walls  # gravity and walls
from adapters.rapier.scene import Tuning, scene_settings
from adapters.shared import toi_refusal
from adapters.stepping import SceneCallsAdapter, scene_inputs
from crosscheck.core import contract
from crosscheck.core.claims import Claim
from crosscheck.core.contract import (
    FEATURES,
    Call,
    Capability,
    Conventions,
    all_capabilities,
    pair_inputs,
    refused,
    response_inputs,
)
from crosscheck.core.geometry import to3
from crosscheck.core.model import Kind
from crosscheck.core.schema import (
    AabbCase,
    PairCase,
    ResponseCase,
    SceneCase,
    SphereCase,
    ToiCase,
)

RAPIER = "https://github.com/dimforge/rapier/blob/v0.35.2/"
PARRY = "https://github.com/dimforge/parry/blob/v0.25.3/src/"
SOURCES = (
    "https://pypi.org/project/rapier3d/0.36.1/",
    RAPIER + "python/rapier-py-3d/python/rapier3d/_rapier3d.pyi",
    RAPIER + "src/pipeline/collision_pipeline.rs",
    RAPIER + "src/geometry/narrow_phase/pair_update.rs",
    RAPIER + "src/geometry/collider_components.rs",
    RAPIER + "src/geometry/contact_pair.rs",
    RAPIER + "src/dynamics/coefficient_combine_rule.rs",
    RAPIER + "src/dynamics/integration_parameters.rs",
    RAPIER + "src/dynamics/solver/contact_constraint/contact_constraint_element.rs",
    PARRY + "query/contact_manifolds/contact_manifolds_ball_ball.rs",
    PARRY + "query/contact_manifolds/contact_manifolds_cuboid_cuboid.rs",
    PARRY + "shape/polygonal_feature3d.rs",
    PARRY + "mass_properties/mass_properties.rs",
    PARRY + "utils/inv.rs",
)
F32_MAX = 3.4028234663852886e38  # the largest finite float32: rapier's Real
DEFAULT_PREDICTION = 0.019999999552965164
"""``IntegrationParameters().prediction_distance()``: 0.02 (as float32) x length_unit 1."""
DEFAULT_MAX_SPEED = 400.0  # normalized_max_linear_velocity x length_unit 1 (m/s)
DEFAULT_DT = 0.01666666753590107
"""``IntegrationParameters().dt``: 1/60 as float32."""
TUNED_DT = 1.0 / 60.0
"""The tuned step, set explicitly: rapier's default (why not smaller: the module docstring)."""
MAX_STEPS = 100_000
APPROACH_RTOL = 2.0**-20
"""A response stops once the approach speed is below this x the case's largest speed."""
TOI_PARRY = "https://github.com/dimforge/parry/blob/v0.25.3/src/query/"
TOI_SOURCES = (
    "https://github.com/dimforge/rapier/blob/v0.35.2/python/rapier-py-3d/python/rapier3d/"
    "_rapier3d.pyi",  # QueryPipeline.cast_shape, ShapeCastOptions, ShapeCastHit
    TOI_PARRY + "shape_cast/shape_cast.rs",  # ShapeCastOptions, ShapeCastHit, statuses
    TOI_PARRY + "shape_cast/shape_cast_ball_ball.rs",  # analytic: ray against the summed ball
    TOI_PARRY + "ray/ray_ball.rs",  # ray_toi_with_ball
)
TOI_NOTES = (
    "Times of impact: QueryPipeline.cast_shape of A's ball with velocity va - vb against B's "
    "ball at rest (B's frame; exact for translations), ShapeCastOptions(max_time_of_impact="
    "duration, target_distance=0, stop_at_penetration=True); parry's ball-ball cast is "
    "analytic (toi_target 0, toi_tolerance 0, f32); normal = -normal1 as the engine gives it "
    "(not renormalised). ")


# --- inputs rapier cannot take ----------------------------------------------------------------


def _numbers(case: PairCase) -> list[tuple[str, float]]:
    """Every number of a case with its name: centres, sizes, and for responses the rest."""
    named = [(f"{s}.center[{i}]", x) for s, body in (("a", case.a), ("b", case.b))
             for i, x in enumerate(body.center)]
    if isinstance(case, AabbCase):
        return named + [(f"{s}.half[{i}]", x) for s, body in (("a", case.a), ("b", case.b))
                        for i, x in enumerate(body.half)]
    named += [("a.radius", case.a.radius), ("b.radius", case.b.radius)]
    if isinstance(case, ResponseCase):
        named += [("a.mass", case.a.mass), ("b.mass", case.b.mass),
                  ("restitution", case.restitution)]
        named += [(f"{s}.velocity[{i}]", x) for s, body in (("a", case.a), ("b", case.b))
                  for i, x in enumerate(body.velocity)]
    return named


def refusal(case: PairCase) -> Exception | None:
    """The exception for an input rapier would take without a word and mishandle (see the
    module docstring): NaN anywhere, infinite geometry, or a number beyond float32's range."""
    for name, x in _numbers(case):
        geometric = not name.startswith(("restitution", "a.m", "b.m", "a.v", "b.v"))
        if math.isnan(x) or (math.isinf(x) and geometric):
            return ValueError(f"{name} = {x!r}: rapier takes it without a word (measured: no "
                              "contact, or no bounce), so the adapter does not ask it")
        if math.isfinite(x) and abs(x) > F32_MAX:
            return OverflowError(f"{name} = {x!r} is beyond float32's largest finite value "
                                 f"{F32_MAX:.8g}: rapier (f32) would read it as infinite")
    return None


def check_inputs(case: PairCase) -> None:
    """Raise :func:`refusal`'s exception, if any."""
    why = refusal(case)
    if why is not None:
        raise why


def _reach(case: PairCase) -> float:
    """A prediction distance above any gap of the case (capped at float32's largest)."""
    sizes = sum(abs(x) for name, x in _numbers(case) if "center" not in name)
    return min(F32_MAX, 1.0 + 2.0 * (math.dist(to3(case.a.center), to3(case.b.center)) + sizes))


# --- the adapters -----------------------------------------------------------------------------

_NOTES = ("Detection: narrow phase of two standalone colliders (ActiveCollisionTypes.all()) in "
          "new sets per pass; hit = has_any_active_contact at the variant's prediction "
          "distance; distance and normal = deepest contact point of a pass whose prediction "
          "reaches past any gap (Undefined when rapier gives none: zero-size boxes, boxes of "
          "half-width <= 1.7e-4, some edge or corner gaps).  Responses: first step whose "
          "solver put an impulse on the pair; resolved_at = centres at its start.  f32: "
          "centres far from the origin lose small gaps.  Mass 0 is immovable; with 1/ma + "
          "1/mb < 0 no impulse; negative restitution reads as 0; NaN or infinite geometry: "
          "the adapter raises (rapier ignores it).  ")
CCD_GUIDE = "https://rapier.rs/docs/user_guides/python/rigid_body_ccd"
"""Rapier's CCD guide: 'By default, CCD is disabled for all the rigid-bodies'; soft CCD:
predictive contacts made ahead of the motion."""
TUNED = Conventions(
    box_extents="half (SharedShape.cuboid takes half-extents)",
    normal="ContactManifoldData.normal points from collider1 to collider2: A to B (negated if "
           "rapier stores the pair as (B, A))",
    touching=dict.fromkeys(FEATURES, False),
    margins={},
    rtol=2.0**-21,
    restitution="rule Multiply on both colliders, A = e and B = 1: e exactly",
    restitution_threshold=0.0,
    resolves_separating=False,
    time_step=TUNED_DT,
    damping=0.0,
    zero_mass="static",
    negative_extents="",
    toi_target=0.0,
    toi_tolerance=0.0,
    # gravity and walls (adapters/rapier/scene.py): no slop, a 60 Hz spring at the wall,
    # no sleeping, the scene's e on the wall under the variant's rule (Max: e)
    rest_gap=(0.0, 0.0), rest_sink_steps=0.0, rest_sink_s2=rapier_walls.REST_SINK_S2,
    sleeps=False, wall_restitution="",
    speculative_contacts=True,
    notes=_NOTES + TOI_NOTES + rapier_walls.TUNED_NOTES
    + "Tuned: prediction 0, soft CCD, friction 0, no speed cap.  Soft CCD (every body's "
      "soft_ccd_prediction 1e30) makes a predictive contact at each step start for the gap "
      "the step's motion closes: an impact is met at the start of the step that holds it, "
      "along the line of centres there (declared speculative_contacts; measured on "
      "fast-oblique: the final velocities are the elastic response along that line).",
    sources=SOURCES + TOI_SOURCES + rapier_walls.SOURCES + (CCD_GUIDE,),
)
DEFAULT = replace(
    TUNED,
    touching=dict.fromkeys(FEATURES, True),
    verdict_margins=dict.fromkeys(FEATURES, DEFAULT_PREDICTION),
    max_speed=DEFAULT_MAX_SPEED, max_speed_at="before restitution",
    sampled_contacts=True,
    speculative_contacts=False,
    restitution="rapier's default rule Average, both colliders e: (e + e) / 2 = e exactly",
    time_step=DEFAULT_DT,
    friction=0.5,
    sleeps=True,  # RigidBodyActivation defaults; walls otherwise as tuned (Average: e)
    sources=(*TUNED.sources, RAPIER + "src/dynamics/rigid_body.rs"),
    notes=_NOTES + TOI_NOTES + rapier_walls.DEFAULT_NOTES + (
                    "Defaults: prediction 0.02 (touching and gaps below it are contact), "
                    "friction 0.5 (ColliderBuilder default, combined by Average) and free "
                    "rotation: oblique responses lose tangential speed to friction (declared), "
                    "speed cap 400 before the bounce (declared max_speed).  Contacts sampled "
                    "at step starts (declared sampled_contacts): 'By default, CCD is disabled "
                    "for all the rigid-bodies' (rapier.rs, rigid-body CCD guide) and "
                    "soft_ccd_prediction is 0 (rigid_body.rs), so a contact forms only from "
                    "a step start within the 0.02 prediction distance; faster pairs pass "
                    "through each other (measured in adapters/rapier/scene.py)."),
)


F32_CLAIM = Claim(
    "distance", ("sphere", "aabb"), 2.0**-21,
    "parry3d, the f32 build rapier3d bundles: Real is f32, \"the scalar type used throughout "
    "this crate\", and DEFAULT_EPSILON = Real::EPSILON (2^-23), \"the default tolerance used "
    "for geometric operations\"; read here as a distance within 4 such epsilons of the "
    "numbers the engine holds (2^-21 x the case's largest |coordinate|, radius or half-width, "
    "the adapter's rtol)", PARRY + "lib.rs", relative=True, relative_to="length")
"""float32 arithmetic as a bound on the distance (parry's ``Real`` and ``DEFAULT_EPSILON``)."""


def prediction_claim(prediction: float) -> Claim:
    """No contact beyond the prediction distance: the verdict is right on every pair apart by
    more than ``prediction`` (the variant's)."""
    return Claim(
        "hit", ("sphere", "aabb"), 0.0,
        "IntegrationParameters::prediction_distance: \"The maximal distance separating two "
        "objects that will generate predictive contacts\" (documented \"default: 0.002m\"; "
        f"the code's default is 0.02); this variant detects at {prediction:.3g}, so a pair "
        "apart by more has no contact (hit false)",
        RAPIER + "src/dynamics/integration_parameters.rs",
        gap=(math.nextafter(prediction, math.inf), math.inf))


class RapierTuned(SceneCallsAdapter):
    """Rapier set for the textbook rules and accuracy (see the module docstring)."""

    name: ClassVar[str] = "rapier"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "rapier3d"
    package: ClassVar[str] = "rapier3d"
    settings: ClassVar[str] = (
        "detection: prediction distance 0, ActiveCollisionTypes.all(); responses: gravity 0, "
        "dt 1/60 (explicit), normalized_prediction_distance 0, normalized_max_linear_velocity "
        "f32::MAX, soft_ccd_prediction 1e30, rotations locked, no sleeping, damping 0, "
        "friction 0, restitution rule Multiply with A = e, B = 1; 2-D: z = 0, z locked")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(
        Kind.AABB, Kind.SPHERE, Kind.SPHERE_RESPONSE, Kind.SPHERE_SCENE, Kind.SPHERE_TOI)
    conventions: ClassVar[Conventions] = TUNED
    claims: ClassVar[tuple[Claim, ...]] = (F32_CLAIM, prediction_claim(0.0))
    prediction: ClassVar[float] = 0.0
    """Detection: the verdict's prediction distance (``normalized_prediction_distance``)."""
    parameters: ClassVar[tuple[tuple[str, float], ...]] = (
        ("dt", TUNED_DT), ("normalized_prediction_distance", 0.0),
        ("normalized_max_linear_velocity", F32_MAX))
    """Responses: the ``IntegrationParameters`` the world gets."""
    scene_tuning: ClassVar[Tuning | None] = Tuning(parameters)
    """What scenes are built with (adapters/rapier/scene.py; its dt is the scene's); None:
    rapier's defaults."""

    calls: ClassVar[str] = "adapters.rapier.calls"
    tuned: ClassVar[bool] = True
    """Responses: the tuned builders (adapters.rapier.calls), else rapier's defaults."""

    def version(self) -> str:
        return metadata.version("rapier3d")

    def available(self) -> str | None:
        return contract.import_problem(lambda: importlib.import_module("rapier3d"), "rapier3d")

    binding_objects: ClassVar[tuple[str, ...]] = ("_rapier3d*.so",)  # PyO3, Rapier within

    def binding_call(self) -> Callable[[], object]:
        """``Vec3.zeros()``: one float32 vector made through the PyO3 binding."""
        import rapier3d as rp

        return rp.Vec3.zeros

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """The verdict at the variant's prediction, distance and normal past any gap."""
        why, reach = refusal(case), _reach(case)
        build = "cuboids" if isinstance(case, AabbCase) else "balls"
        return Call(build, "detect", {**pair_inputs(case), "prediction": self.prediction,
                                      "reach": reach}, refusal=why)

    def response_call(self, case: ResponseCase) -> Call:
        """A new world per ask, stepped to the first step that pushed the pair apart."""
        a, b = case.a, case.b
        speeds = [abs(x) for x in (*a.velocity, *b.velocity)]
        return Call("response", "respond", {
            **response_inputs(case), "tuned": self.tuned, "parameters": self.parameters,
            "tol": APPROACH_RTOL * max(speeds, default=0.0), "max_steps": MAX_STEPS},
            refusal=refusal(case))

    def scene_settings(self) -> dict[str, Any]:
        """The variant's inputs to the scene calls besides the scene (``scene_tuning``)."""
        return scene_settings(self.scene_tuning)

    def scene_call(self, case: SceneCase) -> Call:
        return Call("scene", "step_scene", {**scene_inputs(case), **self.scene_settings()},
                    release="release_scene")

    def toi_call(self, case: ToiCase) -> Call:
        """``cast_shape``; refused for inputs rapier would take unchecked."""
        a, b = case.a, case.b
        inputs: dict[str, Any] = {
            "a_center": a.center, "a_radius": a.radius, "a_velocity": a.velocity,
            "b_center": b.center, "b_radius": b.radius, "b_velocity": b.velocity,
            "duration": case.duration}
        return Call("cast", "cast_shape", inputs, refusal=refused(toi_refusal(**inputs)))



class RapierDefault(RapierTuned):
    """Rapier out of the box: only geometry, masses, velocities and restitution are set."""

    name: ClassVar[str] = "rapier-default"
    settings: ClassVar[str] = (
        "detection: default prediction distance 0.02, ActiveCollisionTypes.all(); responses: "
        "gravity 0, both colliders restitution e (default rule Average), everything else "
        "default (dt 1/60, friction 0.5, rotation free, sleeping, speed cap 400); "
        "2-D: z = 0, z locked")
    conventions: ClassVar[Conventions] = DEFAULT
    claims: ClassVar[tuple[Claim, ...]] = (F32_CLAIM, prediction_claim(DEFAULT_PREDICTION))
    prediction: ClassVar[float] = DEFAULT_PREDICTION
    parameters: ClassVar[tuple[tuple[str, float], ...]] = ()
    scene_tuning: ClassVar[Tuning | None] = None
    tuned: ClassVar[bool] = False


RAPIER_CCD_SOURCES = (
    RAPIER + "src/dynamics/rigid_body.rs",  # enable_ccd: bullets
    RAPIER + "src/dynamics/ccd/ccd_solver.rs",  # pass 1 fixed, pass 2 bullets
)


class RapierCcd(RapierTuned):
    """Rapier tuned with every body ``ccd_enabled`` (scenes only)."""

    name: ClassVar[str] = "rapier-ccd"
    settings: ClassVar[str] = (
        "the rapier variant's settings (soft_ccd_prediction 1e30 among them); every body "
        "ccd_enabled(True)")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE_SCENE)
    claims: ClassVar[tuple[Claim, ...]] = ()  # scenes only: no distance or verdict to claim
    scene_tuning: ClassVar[Tuning | None] = Tuning(RapierTuned.parameters, ccd=True)
    conventions: ClassVar[Conventions] = replace(
        RapierTuned.conventions,
        sampled_contacts=False,
        notes=("Scenes only.  Every body ccd_enabled (a bullet: swept against fixed and "
               "non-bullet bodies, never against another bullet, rigid_body.rs), on the "
               "tuned variant's soft CCD (predictive contacts whatever the travel).  "
               "Measured in adapters/rapier/scene.py: ccd_enabled changes no fast-body "
               "result; soft CCD catches them.  Gravity and walls as the tuned variant's "
               "(half-spaces; resting gap and elastic drops measured equal to it, "
               "adapters/rapier/scene.py)"),
        sources=RapierTuned.conventions.sources + RAPIER_CCD_SOURCES,
    )
