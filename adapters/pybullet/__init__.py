"""PyBullet 3.2.7 (Bullet, double precision) as an engine: ``pybullet`` and ``pybullet-default``.

Each variant has two DIRECT clients per process (no GUI), connected lazily, gravity 0, no
ground plane: one for detection cases, one for responses (world settings are global to a
client, so the variants never share one; detection worlds never step, so their idle bodies
cost response steps nothing).  Collision shapes are cached per client by (geometry, size).
A sphere detection case builds no body: ``getClosestPoints`` takes the two cached shapes and
their positions directly (``collisionShapeA``/``B`` [pybullet.c]: no body, so no pool, filter
or release).  Any other case is two base-only multibodies on the cached shapes: for box
detection static ones (mass 0, no visual shape: what a user making a pure collision query
builds; a static body's AABB is never checked for overflow, see below), for responses
dynamic ones with the case's masses.

Bodies are pooled per client, by shape.  ``prepare`` takes an idle body of the shape
(creating one, ``createMultiBody``, only when none is idle; a pair of equal shapes takes
two), moves it (``resetBasePositionAndOrientation``, identity orientation) and turns its
collision on (``setCollisionFilterGroupMask`` group 1, mask -1: what createMultiBody gives
a dynamic base [URDF2Bullet.cpp]; a new detection body gets the same call, since a static
base gets StaticFilter with a mask that excludes static-static pairs: two static bodies
would never make contact, measured here).  ``release`` turns it off (group 0, mask 0: it
pairs with nothing) and returns it to the pool, where it stays, still, wherever its case
left it: the world keeps no active body between cases.  What makes a reused body a new one,
measured: the filter call removes and re-adds the collider, which drops its broadphase
pairs and contact manifolds and gives it a new proxy id after all others (A before B, as on
creation); a createMultiBody body never sleeps (sleeping is opt-in);
``changeDynamics(mass=)`` recomputes the inertia exactly as createMultiBody does.  Detection
bodies never get a velocity or dynamics; response bodies get their mass, restitution and
the variant's per-body settings on every ``prepare`` and zero velocities on ``release``, so
the steps of later cases leave idle bodies where they are.  A detection client keeps at most
``IDLE_LIMIT`` idle bodies and a response client ``RESPONSE_IDLE_LIMIT`` (the least
recently released are removed beyond): an idle body adds ~0.04 us to
``performCollisionDetection`` and ~0.55 us to a response step (~2 us with the pair alone),
and detection clients never step.  Not pooled (new bodies, removed on ``release``): a case
with a size outside (0, ``SIZE_LIMIT``], a response mass that is not positive and finite, a
negative restitution (``changeDynamics`` ignores negative values, so a reused body would
keep the last one) or a coordinate or speed not within ``COORD_LIMIT``; and a response body
that ends non-finite or beyond it, since a dynamic body whose AABB overflowed is disabled
for good (see below).  A shape once used by a body can never be removed
(``removeCollisionShape`` refuses it even after the body is gone), so a client holding
``SHAPE_LIMIT`` shapes is disconnected and replaced by a new one between cases (~5
ms).  Costs measured here: ``createMultiBody`` ~0.6 ms and ``removeBody`` ~0.05 ms (~2 ms
among 2,000 bodies; each create and remove also leaks ~1 KB); a reset or a filter call ~1
us.  A pooled sphere pair on bodies cost ~32 us (prepare, query, release) against ~11 us
for the bare engine calls (two resets, detection, contact and closest points) and ~1.3 ms
with a body created and removed per case (before spheres moved to shapes alone, which
also spares the suite's many sizes a body each); memory stays flat.  The banner and ``b3Warning``
lines go to the C-level stdout/stderr, so import, connect, creating and removing shapes and
bodies, and ``changeDynamics`` run with file descriptors 1 and 2 on /dev/null (a redirect
costs ~8 us); resets, filter calls and ``query`` print nothing and run without.  The calls,
plain data in and out, are :mod:`adapters.pybullet.calls`; its quiet import (``engine()``),
redirect (``quiet()``) and ``connect`` are shared with the scene runner and the studies.

Detection: ``hit`` is the engine's verdict, "contact points exist" after
``performCollisionDetection`` (stale until then); Bullet's sphere-sphere and box-box
algorithms only add points at distance <= 0 (measured), so the breaking threshold plays no
part.  ``distance`` and ``normal``: the deepest point of ``getClosestPoints(A, B,
1 + 2|cB - cA|)`` (a bound above any possible gap), normal flipped.  Spheres: the same
closest points on the shapes alone, and ``hit`` is their deepest distance <= 0: the very
verdict, since contacts and closest points of two spheres both come from
btSphereSphereCollisionAlgorithm, which adds a point exactly when ``len <= r0 + r1``, i.e.
distance ``len - (r0 + r1) <= 0`` [btDefaultCollisionConfiguration.cpp,
btSphereSphereCollisionAlgorithm.cpp] (checked on every sphere case of the suite: hit,
distance, normal and errors identical to two bodies').  Boxes keep bodies: their closest
points come from GJK (btConvexConvexAlgorithm), their contacts from btBoxBoxDetector, and
"deepest closest point <= 0" is not their verdict (it differs on 577 of the suite's box
cases, face-touching unit cubes among them: closest points 1.7e-18 apart, in contact).
2-D: discs are spheres at z = 0; a 2-D box gets the z half-width 2 x the case's largest
half-width (1 if all are 0), both centred at z = 0, so the z overlap exceeds any x or y
overlap: z is never the axis of least overlap nor a gap, and the 3-D answers are the 2-D
ones (returned as 2-tuples).
2 x, not more, keeps the box small (see the size limits below).

Response: ``query`` resets centres (``resetBasePositionAndOrientation``) and velocities
(``resetBaseVelocity``, no spin), then calls ``stepSimulation`` until the relative velocity
along the line of centres the step detected from no longer approaches (not above 1e-12 x
the case's largest speed), at most 64 steps; it returns ``getBaseVelocity`` and, as
``resolved_at``, the centres at the start of the first step after which
``getContactPoints(A, B)`` is not empty: the configuration whose contact the solver
resolved (a step detects at the centres it starts from, measured here).  None if no step
reported a contact (a grazing pair that passes, bodies whose AABB overflowed).  That step
need not end the approach (the default contactSlop leaves a slow or grazing pair
approaching), so it is not the last step.  2-D runs at z = 0 with vz = 0; a result with
vz != 0 raises.

Conventions, measured here (sources in ``SOURCES``):

- box extents half (``halfExtents``); ``contactNormalOnB`` points from B to A [quickstart
  guide], flipped here.
- touching is contact: touching spheres give a point at distance 0 (``len > r0 + r1`` is
  the only reject) [btSphereSphereCollisionAlgorithm], face-touching boxes four at -0.0.
  Edge/corner-touching boxes read 0.00083/0.00146 apart, no contact: a box's 0.001
  collision margin rounds its edges [btBoxShape.h].  Declared margin 0.002 (both boxes;
  at most 2 (sqrt 3 - 1) 0.001); spheres are exact.  rtol 2^-50: a 2^-40 gap reads exactly.
- restitution: the product of the bodies' values [btManifoldResult.cpp]; A gets the case's
  e, B 1.0.  Below ``restitutionVelocityThreshold`` (0.2 by default) of approach a bounce
  is inelastic [btContactSolverInfo.h].  Separating contacts get no impulse (clamped >= 0)
  [btMultiBodyConstraintSolver.cpp]: resolves_separating False.
- time step 1/240 s in both variants (tuned: set explicitly; default: pybullet's
  ``fixedTimeStep``) [quickstart guide, setTimeStep].  Damping: the multibody default
  linear damping 0.04 [btMultiBody.cpp] acts as dv/dt = -0.04 (1 + |v|) v
  (``DAMPING_K1_LINEAR`` + ``DAMPING_K2_LINEAR`` |v|, measured in scenes, see
  :mod:`adapters.pybullet.scene`); the tuned variant sets it to 0.
- contacts sampled (``sampled_contacts`` True, both variants): detection runs on the
  positions a step starts from [btDiscreteDynamicsWorld.cpp], and a multibody has no CCD
  (``changeDynamics`` sets ``ccdSweptSphereRadius`` on rigid bodies only
  [PhysicsServerCommandProcessor.cpp]); the sphere-sphere algorithm adds no point before
  touching.  ``pybullet-ccd`` (:class:`PyBulletCcd`, scenes only: every sphere a
  maximal-coordinates rigid body with ``ccdSweptSphereRadius`` 0.9 r, which Bullet reads
  only on a rigid body; pybullet sets the motion threshold itself, half the swept radius)
  is the CCD switch.  Speed: a multibody's velocity coordinates are clamped to +-100 m/s
  every step (``m_maxCoordinateVelocity`` [btMultiBody.h], per axis; measured in scenes):
  declared
  ``max_speed`` 100 with ``max_speed_at`` "per coordinate", read at every step.
- mass 0 is a static body: ``isFixedBase = (mass == 0)`` [URDF2Bullet.cpp], immovable,
  an infinitely heavy body; a response against it bounces off it moving at the velocity it
  was given (measured: ``bad-resp-3d-zero-mass``).  Declared ``zero_mass="static"``.
- negative sizes are not read as magnitudes: a negative radius raises ``pybullet.error``
  (``createCollisionShape failed``); a box with one negative half-width answers as the
  textbook's literal formula, one with all negative as neither (measured here).  Declared
  ``negative_extents=""``.

Other facts measured: ``contactSlop`` (1e-5) keeps slop/dt of the approach (0.0024 at dt
1/240), so a default impact finishes a step late; starting overlapped, contact ERP adds
energy; radii 0, negative or NaN raise ``pybullet.error`` (box half-widths 0 or negative
are accepted); coincident sphere centres get (1, 0, 0) on B.  A dynamic body whose AABB
diagonal (the contact breaking threshold 0.02 included) reaches 1e6 (or is not finite) is
dropped from collision for good ("Overflow in AABB": its activation state becomes
DISABLE_SIMULATION, which nothing resets) [btCollisionWorld.cpp]: a response sphere of
radius >= 1e6 / (2 sqrt 3) - 0.02 = 288675.1146 makes no contact (measured; bisected to
1e-10).  Static bodies skip that check, so detection has no such limit; measured there:
sphere contacts up to radius 1.34e154 (sqrt DBL_MAX), box contacts up to half-width
3.4e38 (FLT_MAX).  Still there, whatever the body type: ``getClosestPoints`` of
overlapping boxes is unreliable from half-widths of about 5e3 (overlap 1e-3 of the
half-width sum: at about half the scales measured between 1e4 and 1e7 it reads about
-0.002, twice the margin, instead of the depth), while the contact points stay exact.

Variants: ``pybullet`` (tuned for accuracy; ``TUNED_WORLD`` and ``TUNED_BODY`` of
``pybullet_setup``): restitutionVelocityThreshold 0, contactSlop 0, contactERP 0 (erp and
frictionERP do not act: no joints, no friction), fixed time step 1/240 s set explicitly;
per body lateral, rolling and spinning friction 0, linear and angular damping 0; boxes keep
the 0.001 margin (margin 0 makes GJK read 2^-40 gaps as 0).
``pybullet-default``: only the case's geometry, masses, velocities and restitution;
everything else as pybullet sets it (damping 0.04, lateral friction 0.5, threshold 0.2,
contactSlop 1e-5, default contact ERP, dt 1/240 s).  Both set restitution by the product.
Scenes (``sphere_scene``) are the scene calls of :mod:`adapters.pybullet.calls` with the
variant's ``scene_tuning`` (:mod:`adapters.pybullet.scene`: the tuned settings as a
``Tuning``, or None for the defaults), measured as that module says.

(Longer than 400 lines: about 135 of them are this docstring, the conventions as measured with
their sources; the code is the pooled bodies and the response stepping that uses them.)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from importlib import metadata
from typing import Any, ClassVar

from adapters.pybullet.calls import World, connect, engine, quiet, world
from adapters.pybullet.scene import Tuning, scene_settings
from adapters.stepping import SceneCallsAdapter, scene_inputs
from crosscheck.core.contract import (
    Call,
    Capability,
    Conventions,
    all_capabilities,
    import_problem,
)
from crosscheck.core.geometry import Vec3, to3, z_half
from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase, SceneCase, SphereCase

__all__ = ["TUNED_BODY", "TUNED_WORLD", "PyBulletCcd", "PyBulletDefault", "PyBulletTuned",
           "World", "client",
           "connect", "engine", "quiet", "world"]

Spec = tuple[str, tuple[float, ...], float]
"""A body to build: geometry, size (radius or half-widths) and mass (0: static)."""

TUNED_WORLD: dict[str, float] = {
    "fixedTimeStep": 1.0 / 240.0, "restitutionVelocityThreshold": 0.0,
    "contactSlop": 0.0, "contactERP": 0.0}
"""The tuned variant's ``setPhysicsEngineParameter`` settings: fixed time step 1/240 s set
explicitly, restitutionVelocityThreshold 0, contactSlop 0, contactERP 0 (erp and
frictionERP do not act: no joints, no friction)."""
TUNED_BODY: dict[str, float] = {
    "lateralFriction": 0.0, "rollingFriction": 0.0, "spinningFriction": 0.0,
    "linearDamping": 0.0, "angularDamping": 0.0}
"""The tuned variant's per-body ``changeDynamics`` settings: lateral, rolling and spinning
friction 0, linear and angular damping 0."""

GH = "https://github.com/bulletphysics/bullet3/blob/master/"
SOURCES = (
    "https://docs.google.com/document/d/10sXEhzFRSnvFcl3XxNGhnD4N2SedqwdAvK3dsihxVUA",
    GH + "examples/pybullet/pybullet.c",
    GH + "src/BulletCollision/CollisionDispatch/btSphereSphereCollisionAlgorithm.cpp",
    GH + "src/BulletCollision/CollisionDispatch/btDefaultCollisionConfiguration.cpp",
    GH + "src/BulletCollision/CollisionDispatch/btBoxBoxDetector.cpp",
    GH + "src/BulletCollision/CollisionDispatch/btCollisionWorld.cpp",
    GH + "src/BulletCollision/CollisionShapes/btBoxShape.h",
    GH + "src/BulletCollision/CollisionDispatch/btManifoldResult.cpp",
    GH + "src/BulletCollision/CollisionDispatch/btCollisionObject.cpp",
    GH + "src/BulletDynamics/ConstraintSolver/btContactSolverInfo.h",
    GH + "src/BulletDynamics/Featherstone/btMultiBodyConstraintSolver.cpp",
    GH + "src/BulletDynamics/Featherstone/btMultiBody.cpp",
    GH + "examples/Importers/ImportURDFDemo/URDF2Bullet.cpp",
    GH + "src/BulletDynamics/Featherstone/btMultiBody.h",
    GH + "src/BulletDynamics/Dynamics/btDiscreteDynamicsWorld.cpp",
    GH + "examples/SharedMemory/PhysicsServerCommandProcessor.cpp",
    GH + "src/BulletCollision/CollisionDispatch/btConvexPlaneCollisionAlgorithm.cpp",
    GH + "src/BulletCollision/NarrowPhaseCollision/btPersistentManifold.cpp",
    GH + "src/BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.cpp",
    GH + "src/BulletCollision/CollisionDispatch/btCollisionDispatcher.cpp",
    GH + "src/BulletCollision/CollisionShapes/btCollisionShape.cpp",
)
BOX_MARGIN = 0.001
MAX_STEPS = 64
APPROACH_RTOL = 1e-12

MAX_COORDINATE_VELOCITY = 100.0
"""btMultiBody's ``m_maxCoordinateVelocity``: each velocity coordinate clamped to +-100 m/s
in ``applyDeltaVeeMultiDof`` every step (btMultiBody.h/.cpp; measured: a free ball at 200 or
1000 m/s ends at 100, per axis)."""
DEFAULT_SLOP = 1e-5
"""pybullet's default contactSlop (``m_linearSlop`` in PhysicsServerCommandProcessor.cpp)."""
WALLS_NOTE = (
    "Walls (sphere_scene with surroundings): a static GEOM_PLANE per wall (btStaticPlaneShape, "
    "a half-space: any depth is a contact, nothing tunnels), restitution sqrt(e) like the "
    "spheres, so the product is e (wall_restitution ''), friction as the variant's spheres.  "
    "Sphere-plane contacts are speculative: btConvexPlaneCollisionAlgorithm adds a point "
    "below the relative breaking threshold 0.02 sqrt(3) r (gContactBreakingThreshold 0.02, "
    "btPersistentManifold.cpp, times the sphere's angular motion disc, btCollisionShape.cpp, "
    "CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD in btCollisionDispatcher.cpp; bisected) and "
    "the solver lets the gap close in one step (velocity error - distance / dt, "
    "btMultiBodyConstraintSolver.cpp), with the bounce e |v| already in its target, so a "
    "sphere reaching a wall from within that band loses part of its bounce or stops; one "
    "crossing it within a step lands up to a step's travel deep.  Sphere-sphere "
    "points exist only from touching, so a sphere resting on another sinks up to one step's "
    "|g| dt^2 (rest_sink_steps 1).  No sleeping: createMultiBody without "
    "URDF_ENABLE_SLEEPING makes a multibody that cannot sleep and a rigid body "
    "DISABLE_DEACTIVATION (URDF2Bullet.cpp; measured: 0.1 m/s kept 5 s).")
"""What every variant declares about gravity and walls (see adapters/pybullet/scene.py)."""

SIZE_LIMIT = 1e5
"""Largest pooled size: an AABB diagonal 2 sqrt 3 x 1e5 stays well below Bullet's 1e6."""
COORD_LIMIT = 1e12
"""Largest pooled coordinate or speed (an ulp at 1e12 is 1.2e-4: no AABB overflow)."""


def client(name: str, settings: dict[str, float]) -> int:
    """The DIRECT client of world ``name`` (a variant's detection world is its own name)."""
    return world(name, settings).cid


def box_sizes(case: AabbCase) -> tuple[Vec3, Vec3]:
    """3-D half-widths of the two boxes; 2-D boxes get the z half-width of the embedding."""
    if case.dim == 3:
        return to3(case.a.half), to3(case.b.half)
    hz = z_half(case.a.half, case.b.half)
    return (case.a.half[0], case.a.half[1], hz), (case.b.half[0], case.b.half[1], hz)


def body_specs(case: PairCase) -> list[Spec]:
    """The two bodies of a case: static (mass 0) for detection, the case's masses for responses."""
    if isinstance(case, AabbCase):
        size_a, size_b = box_sizes(case)
        return [("box", size_a, 0.0), ("box", size_b, 0.0)]
    if isinstance(case, ResponseCase):
        return [("sphere", (case.a.radius,), case.a.mass),
                ("sphere", (case.b.radius,), case.b.mass)]
    return [("sphere", (case.a.radius,), 0.0), ("sphere", (case.b.radius,), 0.0)]


def ordinary(case: PairCase, ca: Vec3, cb: Vec3, specs: Sequence[Spec]) -> bool:
    """Whether the case's bodies may come from the pool (see the module docstring).

    A negative restitution is not: ``changeDynamics`` ignores negative values (pybullet.c
    sends only values >= 0), so a reused body would keep its last case's restitution
    where a new one has 0.  (Comparisons with NaN are False: NaN is never ordinary.)
    """
    (_, size_a, mass_a), (_, size_b, mass_b) = specs
    numbers: tuple[float, ...] = (*ca, *cb)
    if isinstance(case, ResponseCase):
        if not (0.0 <= case.restitution <= COORD_LIMIT
                and 0.0 < mass_a < math.inf and 0.0 < mass_b < math.inf):
            return False
        numbers += (*case.a.velocity, *case.b.velocity)
    return (all(0.0 < x <= SIZE_LIMIT for x in (*size_a, *size_b))
            and all(-COORD_LIMIT <= x <= COORD_LIMIT for x in numbers))


class PyBulletTuned(SceneCallsAdapter):
    """PyBullet tuned for accuracy (see the module docstring)."""

    name: ClassVar[str] = "pybullet"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "pybullet"
    package: ClassVar[str] = "pybullet"
    settings: ClassVar[str] = (
        "DIRECT, gravity 0, dt 1/240 s (explicit), restitutionVelocityThreshold 0, "
        "contactSlop 0, contactERP 0; per body lateral/rolling/spinning friction 0, "
        "linear/angular damping 0; restitution A = e, B = 1 (product); "
        "boxes keep the default 0.001 collision margin")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(
        *(k for k in Kind if k is not Kind.SPHERE_TOI))
    world: ClassVar[dict[str, float]] = TUNED_WORLD
    body: ClassVar[dict[str, float]] = TUNED_BODY
    scene_tuning: ClassVar[Tuning | None] = Tuning(TUNED_WORLD, TUNED_BODY)
    """What scenes are built with (see adapters/pybullet/scene.py); None: engine defaults."""
    conventions: ClassVar[Conventions] = Conventions(
        box_extents="half",
        normal="B to A (contactNormalOnB of getClosestPoints); flipped by the adapter",
        touching={"sphere": True},
        margins=dict.fromkeys(("face", "edge", "corner"), 2 * BOX_MARGIN),
        rtol=2.0**-50,
        restitution="product of the bodies' restitutions; the adapter sets A = e, B = 1",
        restitution_threshold=0.0,
        resolves_separating=False,
        time_step=1.0 / 240.0,
        damping=0.0,
        zero_mass="static",
        negative_extents="",
        sampled_contacts=True,
        max_speed=MAX_COORDINATE_VELOCITY,
        max_speed_at="per coordinate",
        rest_gap=(0.0, 0.0),
        rest_sink_steps=1.0,
        rest_sink_s2=0.0,
        sleeps=False,
        wall_restitution="",
        notes=("hit = contact points exist after performCollisionDetection between static "
               "(mass 0) bodies (touching spheres and face-touching boxes are contacts); the "
               "0.001 box margin rounds edges and corners: edge/corner-touching boxes read "
               "0.00083/0.00146 apart; 2-D at z = 0, 2-D boxes get z half-width 2x the "
               "largest half-width.  Responses: dynamic bodies stepped at dt 1/240 until no "
               "longer approaching; resolved_at = the centres at the start of the first step "
               "that reported the contact.  Measured limits: a dynamic body whose AABB "
               "diagonal (breaking threshold 0.02 included) reaches 1e6 makes no contact "
               "(\"Overflow in AABB\"): response spheres of radius >= 288675.1146; static "
               "detection bodies have no such check (contacts measured up to radius 1.34e154 "
               "and box half-width 3.4e38); getClosestPoints of overlapping boxes from "
               "half-width ~5e3 may read -0.002 (-2 x margin) instead of the depth.  Mass 0 "
               "is a static body (isFixedBase = mass == 0 in URDF2Bullet.cpp).  A negative "
               "radius raises; a box with one negative half-width reads literally (measured "
               "here).  Contacts are sampled at step starts (sampled_contacts): collision "
               "detection runs on the positions a step starts from "
               "(btDiscreteDynamicsWorld::internalSingleStepSimulation) and a multibody has "
               "no CCD (changeDynamics sets ccdSweptSphereRadius on rigid bodies only, "
               "PhysicsServerCommandProcessor.cpp): fast pairs pass through each other.  "
               "Multibody velocity coordinates are clamped to +-100 m/s every step "
               "(btMultiBody m_maxCoordinateVelocity 100, applyDeltaVeeMultiDof; per axis, "
               "not the norm; measured in scenes): declared max_speed 100 acting per "
               "coordinate, read by responses and scenes, and at every step (a fall that "
               "gravity speeds past it goes on at 100).  " + WALLS_NOTE
               + "  Tuned: contactSlop 0 and "
               "contactERP 0, so the solver's rest target is distance 0 (rest_gap 0, 0) and "
               "a penetration (a landing depth) is never pushed out; "
               "restitutionVelocityThreshold 0 gives a resting contact the bounce e |g| dt, "
               "so a sphere on a wall with e > 0 rests "
               "floating e |g| dt^2 above it (its speculative target), and one on a sphere "
               "hops; a column of spheres creeps into the ground (no positional correction; "
               "measured in adapters/pybullet/scene.py)"),
        sources=SOURCES,
    )

    calls: ClassVar[str] = "adapters.pybullet.calls"

    def version(self) -> str:
        return metadata.version("pybullet")

    def available(self) -> str | None:
        return import_problem(engine, "pybullet")

    binding_objects: ClassVar[tuple[str, ...]] = ("pybullet.cpython-*.so",)
    """The engine's shared objects for the instruction timer: pybullet's one C extension, Bullet
    linked in (entry points such as pybullet_getClosestPointData).
    """

    def binding_call(self) -> Callable[[], object]:
        """``getNumBodies`` on the variant's detection client: one call into the C API."""
        bt, cid = engine(), client(self.name, self.world)
        return lambda: bt.getNumBodies(physicsClientId=cid)

    def _shapes(self, case: PairCase, world_name: str) -> dict[str, Any]:
        specs = body_specs(case)
        return {"world_name": world_name, "settings": self.world, "a": specs[0],
                "b": specs[1], "a_center": to3(case.a.center), "b_center": to3(case.b.center),
                "dim": case.dim}

    def _pair(self, case: PairCase, world_name: str) -> dict[str, Any]:
        inputs = self._shapes(case, world_name)
        pooled = ordinary(case, inputs["a_center"], inputs["b_center"], (inputs["a"], inputs["b"]))
        return {**inputs, "pooled": pooled}

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """Boxes: two pooled bodies; spheres: their cached shapes alone, no body."""
        if isinstance(case, SphereCase):
            return Call("sphere_shapes", "closest", self._shapes(case, self.name))
        return Call("pair", "detect", {**self._pair(case, self.name), "response": False},
                    release="release")

    def response_call(self, case: ResponseCase) -> Call:
        speeds = [abs(x) for x in (*case.a.velocity, *case.b.velocity)]
        return Call("response_pair", "respond", {
            **self._pair(case, self.name + "/response"), "body_settings": self.body,
            "a_velocity": to3(case.a.velocity), "b_velocity": to3(case.b.velocity),
            "restitution": case.restitution, "tol": APPROACH_RTOL * max(speeds, default=0.0),
            "max_steps": MAX_STEPS}, release="release")

    def scene_settings(self) -> dict[str, Any]:
        """The variant's inputs to the scene calls besides the scene (``scene_tuning``)."""
        return scene_settings(self.scene_tuning)

    def scene_call(self, case: SceneCase) -> Call:
        return Call("scene", "step_scene", {**scene_inputs(case), **self.scene_settings()},
                    release="release_scene")


class PyBulletDefault(PyBulletTuned):
    """PyBullet as a user gets it: only geometry, masses, velocities and restitution are set."""

    name: ClassVar[str] = "pybullet-default"
    settings: ClassVar[str] = (
        "DIRECT, gravity 0; restitution A = e, B = 1 (product); everything else default "
        "(damping 0.04, lateral friction 0.5, restitutionVelocityThreshold 0.2, "
        "contactSlop 1e-5, default contact ERP, dt 1/240 s)")
    world: ClassVar[dict[str, float]] = {}
    body: ClassVar[dict[str, float]] = {}
    scene_tuning: ClassVar[Tuning | None] = None
    conventions: ClassVar[Conventions] = replace(
        PyBulletTuned.conventions,
        restitution_threshold=0.2,
        damping=0.04,
        friction=0.25,
        rest_gap=(-DEFAULT_SLOP, 0.0),
        notes=PyBulletTuned.conventions.notes.split("  Tuned: contactSlop 0")[0]
        + "  Default: the rest target is distance + contactSlop = 0 (contactSlop 1e-5 and "
          "contact ERP 0.08 in PhysicsServerCommandProcessor.cpp; the slop is the allowed "
          "penetration), so rest_gap (-1e-5, 0); approaches slower than 0.2 do not bounce."
        + "  Default damping 0.04 (dv/dt = -0.04 (1 + |v|) v, btMultiBody.cpp; measured in "
          "adapters/pybullet/scene.py), friction 0.5 per body (btCollisionObject.cpp; "
          "combined as the product 0.25 in btManifoldResult::calculateCombinedFriction) "
          "and contactSlop 1e-5 act on responses",
    )


CCD_FRACTION = 0.9
"""pybullet-ccd: each sphere's ``ccdSweptSphereRadius`` as a fraction of its radius."""
PYBULLET_CCD_SOURCES = (
    GH + "examples/SharedMemory/PhysicsServerCommandProcessor.cpp",
    GH + "src/BulletDynamics/Dynamics/btDiscreteDynamicsWorld.cpp",
)


class PyBulletCcd(PyBulletTuned):
    """PyBullet tuned, spheres as rigid bodies with a swept sphere of 0.9 r (scenes only)."""

    name: ClassVar[str] = "pybullet-ccd"
    settings: ClassVar[str] = (
        "the pybullet variant's settings; scenes only: every sphere a maximal-coordinates "
        "body (createMultiBody useMaximalCoordinates=True, a btRigidBody) with "
        f"changeDynamics ccdSweptSphereRadius = {CCD_FRACTION} x its radius (pybullet sets "
        "ccdMotionThreshold to half of it)")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE_SCENE)
    scene_tuning: ClassVar[Tuning | None] = Tuning(
        TUNED_WORLD, TUNED_BODY, maximal=True, ccd=CCD_FRACTION)
    conventions: ClassVar[Conventions] = replace(
        PyBulletTuned.conventions,
        sampled_contacts=False,
        max_speed=None, max_speed_at="",
        restitution_model="predictive",
        notes=("Scenes only.  Bullet CCD on rigid (maximal-coordinates) bodies: a sphere "
               "moving more than half its swept radius (0.9 r) in a step is swept against "
               "the others; a hit makes a predictive contact (restitution 0: m_combinedRestitution "
               "= 0 in createPredictiveContactsInternal, declared restitution_model "
               "predictive) and clamps the motion to the hit (btDiscreteDynamicsWorld.cpp), "
               "so no pass-through was measured but a caught impact keeps only part of its "
               "bounce, between none and e of it.  Rigid bodies "
               "have no multibody speed clamp (100 m/s per coordinate).  Measured in "
               "adapters/pybullet/scene.py"),
        sources=SOURCES + PYBULLET_CCD_SOURCES,
    )
