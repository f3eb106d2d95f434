"""Box2D v3.1.1 through pyb2d3 0.11.1 (``import pyb2d3``) as an engine: ``box2d3``,
``box2d3-default`` and ``box2d3-bullet``.

Box2D v3 is a rewrite of v2 in C (soft step solver, sub-stepping, speculative contacts,
continuous collision against static bodies by default).  It is 2-D and float32: every 3-D case
is skipped ("2-D engine") and every input is rounded to float32.  Kinds: ``aabb`` (boxes),
``sphere`` (circles), ``sphere_response`` and ``sphere_scene`` (:mod:`adapters.box2d3.calls`,
plain data in and out, also the repro script).  No ``sphere_toi``: pyb2d3 0.11.1 compiles its
bindings of ``b2TimeOfImpact``, ``b2ShapeDistance`` and ``b2ShapeCast`` out (``#if 0`` in
src/export_collision.cpp at v0.11.1; ``pyb2d3.time_of_impact`` does not exist).

Detection by a step (``aabb``, ``sphere``): pyb2d3 0.11.1 binds neither Box2D's narrow phase
nor ``b2Body_GetContactData``; a manifold reaches Python only in a begin-touch event
(``b2ContactBeginTouchEvent.manifold``, "recorded before the solver is called", types.h), and
``b2World_Step`` does no collision work on a zero time step (world.c).  So ``prepare`` builds a
world with two dynamic bodies, disabled; ``query`` enables them at the case's centres at rest,
steps once and reads the pair's begin-touch event (see :mod:`adapters.box2d3.calls`).

- touching: Box2D calls a pair touching when its manifold has points (``touching = pointCount
  > 0``, ``b2UpdateContact`` in contact.c); begin-touch events and contact data follow that
  flag.  The manifold functions keep points up to ``B2_SPECULATIVE_DISTANCE`` (``4
  B2_LINEAR_SLOP`` = 0.02 m) apart (``separation > B2_SPECULATIVE_DISTANCE`` rejects,
  manifold.c): "speculative contact points have positive separation" (simulation.md).  So
  ``hit`` is the engine's touching flag (a begin-touch event), declared with the verdict margin
  0.02 at every feature (``verdict_margins``): pairs up to 0.02 apart are touching by Box2D's
  definition; exact touching is contact everywhere (separation 0 <= 0.02).
- distance: the least ``separation`` of the manifold's points ("negative if penetrating",
  collision.h), a signed distance with a depth; no event (farther than 0.02): no distance (None,
  ``skip``) and no normal.
- normal: ``b2Manifold.normal`` ("points from shape A to body B", collision.h), negated when
  Box2D ordered the pair's shapes B, A.  Coincident circle centres (closer than
  ``FLT_EPSILON``) give the zero vector (``b2GetLengthAndNormalize``, math_functions.h): no
  normal (declared ``no_value`` "float32-textbook": where the float32 centres coincide;
  closer than ``FLT_EPSILON`` but apart in float32, the row is an ``error``, Box2D's absolute
  threshold).
- margins: float32 arithmetic: ``FLT_EPSILON`` absolute at every feature, plus ``RTOL``
  (2^-21, 8 float32 units) of the case's size.

Response (``sphere_response``): a world (gravity 0) with two dynamic discs (density 0, mass set
by ``mass_data``), A's restitution e and B's 0 (``b2DefaultRestitutionCallback``: max).  Each
query re-enables both (no warm start), puts back the case's state and steps until the bodies
stop approaching (``resolved_at``: the centres before that step, if it changed a velocity).

Conventions (each from Box2D v3.1.1's sources, ``SOURCES``; measured where said):

- restitution threshold: ``b2WorldDef.restitutionThreshold`` = 1 m/s (types.c); restitution is
  skipped when ``relativeVelocity + threshold > 0`` (contact_solver.c), so an approach of
  exactly 1 m/s bounces: declared 1.0 (the textbook's strict "below" reading).  A speculative
  point that took no impulse gets no bounce either.
- bounce at the step's end, from the approach at its start: the solver's stages run
  prepare contacts (``relativeVelocity = dot(normal, vB - vA)`` from the velocities the step
  starts with, contact_solver.c L1559-L1562, overflow L150-L153), then per sub-step integrate
  velocities, solve, integrate positions and relax, and only after the sub-steps
  ``b2ApplyRestitution`` (solver.c L731-L739 ``b2SolverStage``, L1075-L1089): a point gets
  ``vn = -e relativeVelocity`` unless ``relativeVelocity + threshold > 0`` or its
  ``totalNormalImpulse`` is 0 (contact_solver.c L1996-L2013, overflow L436-L451), once per
  step, not iterated ("it is possible to get more accurate restitution by iterating",
  L425).  So the step that meets a contact only stops the approach (the soft solve; an
  overlap pushed out at most ``maxContactPushSpeed`` 3 m/s, types.c) and the bounce leaves
  a step late: declared ``bounce_at_step_end`` (each centre up to its share of ``e`` x the
  closing speed x dt behind the discrete run).  And the bounce is the approach stored at
  the step start: a pair at rest when the step starts and pushed within it (a chain: a
  Newton's cradle, a billiards rack within the 0.02 m speculative distance) gets none, and a
  fall meets the threshold up to ``|g| dt`` slower than its impact: declared
  ``bounce_from_step_start`` (energy lost, never gained).  A new pair's contact is made and
  collided in the same step: ``b2World_Step`` runs ``b2UpdateBroadPhasePairs`` (which calls
  ``b2CreateContact``, broad_phase.c L435, adding it to the awake set's contact sims,
  contact.c L298) before ``b2Collide`` (world.c L738, L776), which updates those sims too
  (world.c L535-L542): no contact is found a step late.
- speed cap: ``maximumLinearSpeed`` (default 400 m/s, types.c) clamps each body's velocity in
  every sub-step's velocity integration, before the contact solve (solver.c), while the
  bounce, added after the sub-steps, takes the approach speed the step started with
  (``relativeVelocity``, contact_solver.c): declared ``max_speed_at`` "before the contact
  solve".  The tuned variants set it to ``B2_HUGE`` (1e5 m/s): no case meets it.
- soft contact: ``contactHertz`` 30, ``contactDampingRatio`` 10, ``maxContactPushSpeed`` 3 m/s
  (types.c), static contacts at twice the hertz (world.c); joints 60 Hz and 2
  (``B2_JOINT_CONSTRAINT_HERTZ``, constants.h; no joints here).  Scenes: see
  :mod:`adapters.box2d3.scene`.
- sub-steps: ``b2World_Step(worldId, timeStep, subStepCount)``, 4 as recommended (hello.md).
- friction: ``sqrt(fA fB)`` (``b2DefaultFrictionCallback``), default 0.6 (``b2DefaultShapeDef``).
- zero mass: ``b2Body_SetMassData`` sets ``invMass = mass > 0 ? 1 / mass : 0`` (body.c): a
  dynamic body of mass 0 is immovable: declared ``zero_mass`` "static".  Negative and NaN
  masses (asserted against only in debug builds; pyb2d3's release build keeps them, measured)
  are refused.
- sleeping: ``enableSleep`` true, ``B2_TIME_TO_SLEEP`` 0.5 s, ``sleepThreshold`` 0.05 m/s
  (constants.h, types.c): on in the default variant, off in the tuned ones.
- continuous: ``enableContinuous`` true (types.c): a fast dynamic body (one step's travel above
  half its smallest extent) is swept against static bodies; bullets (``isBullet``) also against
  kinematic and non-bullet dynamic bodies, "but not other bullets" (simulation.md, solver.c).
  So between two dynamic discs contacts are sampled at step starts in every variant, the
  bullet one included (every disc a bullet, as ``box2d-bullet`` in v2; bullets are not swept
  against bullets): ``sampled_contacts`` True everywhere.  One bullet among plain dynamic
  discs is swept against where the other disc ends the step (solver.c: a non-fast body's
  sweep starts at its end position), so it stops short and bounces a step late or misses a
  disc that passed: measured, and modelled by no scene rule yet, so no variant declares it.

Engine behaviour the report shows as ``error`` (from the sources above, not hidden): centres
closer than ``FLT_EPSILON`` (sizes near 1e-9) give a zero normal, so such a pair neither gets a
normal nor responds (math_functions.h); a pair found at a step start with its centres nearly
through each other (a deep overlap) has them cross within the soft step, and the bounce, taken
along the step start's normal, sends them back into each other every step (caught inside
each other to the end); restitution applied once per contact and not iterated can add energy
where a body bounces off several contacts in one step (a billiards break at a small step);
an oblique impact closing below the threshold, met at a speculative gap, is stopped along two
normals over two steps, which no one-event run models; the default variant's friction 0.6
and free rotation change oblique bounces, which the scene rules do not model; a response at
1e12 from the origin never moves in float32 (a step's travel is below the spacing there) and
runs to the step cap (``timeout``).

Guarded inputs (``ValueError``, the reason in the message): pyb2d3 is a release build
(``B2_ASSERT`` compiled out, base.h), so Box2D takes NaN centres and velocities, negative radii
and half-widths (an inside-out box or a circle that collides with nothing, measured) and
negative masses silently: all refused, with non-finite inputs and negative or NaN restitution.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from importlib.metadata import version as dist_version
from typing import Any, ClassVar

from adapters.box2d3.calls import engine
from adapters.box2d3.scene import B2_HUGE, Variant, scene_settings, with_walls
from adapters.stepping import SceneCallsAdapter, scene_inputs
from crosscheck.core.claims import Claim
from crosscheck.core.contract import (
    Call,
    Capability,
    Conventions,
    import_problem,
    pair_inputs,
    refused,
    response_inputs,
)
from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, AnyCase, PairCase, ResponseCase, SceneCase, SphereCase

BOX2D_VERSION = "3.1.1"
"""The Box2D release pyb2d3 0.11.1 builds (``GIT_TAG v3.1.1`` in its CMakeLists.txt)."""
B3 = "https://github.com/erincatto/box2d/blob/v3.1.1/"
PYB2D3 = "https://github.com/DerThorsten/pyb2d3/blob/v0.11.1/"
SOURCES = (
    B3 + "src/constants.h",  # B2_LINEAR_SLOP, B2_SPECULATIVE_DISTANCE, B2_HUGE, sleep time
    B3 + "src/types.c",  # b2DefaultWorldDef: thresholds, hertz, 400 m/s; shape def friction 0.6
    B3 + "include/box2d/types.h",  # world def fields, b2ContactBeginTouchEvent, isBullet
    B3 + "include/box2d/collision.h",  # b2Manifold normal A to B, separation negative overlap
    B3 + "src/manifold.c",  # b2CollideCircles / b2CollidePolygons: speculative reject
    B3 + "src/contact.c",  # b2UpdateContact: touching = pointCount > 0
    B3 + "src/world.c",  # b2World_Step (no collision at dt 0), mixing callbacks, softness
    B3 + "src/solver.c",  # speed clamp, continuous, bullets; restitution after the sub-steps
    B3 + "src/contact_solver.c",  # restitution from the step start's relativeVelocity, once
    B3 + "src/broad_phase.c",  # b2UpdateBroadPhasePairs creates contacts before b2Collide
    B3 + "src/body.c",  # b2Body_SetMassData: invMass 0 for mass 0
    B3 + "include/box2d/base.h",  # B2_ASSERT compiled out without B2_ENABLE_ASSERT / NDEBUG
    B3 + "include/box2d/math_functions.h",  # b2GetLengthAndNormalize: zero below FLT_EPSILON
    B3 + "docs/simulation.md",  # speculative contact, contact events, bullets
    B3 + "docs/hello.md",  # four sub-steps recommended
    B3 + "docs/FAQ.md",  # "moving objects in the range 0.1 - 10 meters"
    PYB2D3 + "src/export_collision.cpp",  # distance / TOI bindings compiled out (#if 0)
    PYB2D3 + "CMakeLists.txt",  # FetchContent box2d GIT_TAG v3.1.1
)
LINEAR_SLOP = 0.005
"""``B2_LINEAR_SLOP`` (0.005 m x ``b2_lengthUnitsPerMeter`` 1, constants.h)."""
SPECULATIVE_DISTANCE = 4.0 * LINEAR_SLOP
"""``B2_SPECULATIVE_DISTANCE``: manifold points are kept up to this far apart (0.02 m)."""
FLT_EPSILON = 2.0**-23
RTOL = 2.0**-21
"""8 float32 units (2^-24) of the case's size."""
THRESHOLD = 1.0
"""``restitutionThreshold``: an approach of at least 1 m/s bounces (contact_solver.c)."""
DEFAULT_MAX_SPEED = 400.0
"""``maximumLinearSpeed``'s default: "400 meters per second, faster than the speed of sound"."""
DEFAULT_FRICTION = 0.6
"""``b2DefaultShapeDef`` friction; mixed as ``sqrt(fA fB)`` = 0.6."""
MAX_STEPS = 100_000
"""Step cap of a response query (bodies still approaching without a velocity change)."""
CAPABILITIES = frozenset({(Kind.AABB, 2), (Kind.SPHERE, 2), (Kind.SPHERE_RESPONSE, 2),
                          (Kind.SPHERE_SCENE, 2)})


def _finite(xs: Sequence[float]) -> bool:
    return all(math.isfinite(x) for x in xs)


def refusal(case: PairCase) -> str | None:
    """Why the adapter refuses ``case``: an input Box2D would silently mis-handle (or None)."""
    sizes = [*case.a.half, *case.b.half] if isinstance(case, AabbCase) else [
        case.a.radius, case.b.radius]
    if not _finite([*case.a.center, *case.b.center, *sizes]):
        return "non-finite input: Box2D's release build takes it unchecked (B2_ASSERT is off)"
    if any(x < 0 for x in sizes):
        return ("negative size: Box2D builds an inside-out box or a circle that collides with "
                "nothing (see the adapter's conventions)")
    if not isinstance(case, ResponseCase):
        return None
    if not _finite([*case.a.velocity, *case.b.velocity]):
        return "non-finite velocity: Box2D's release build takes it unchecked"
    if not all(m >= 0 for m in (case.a.mass, case.b.mass)):
        return "mass NaN or negative: b2Body_SetMassData keeps it (asserted only in debug)"
    if not case.restitution >= 0:
        return "restitution negative or NaN: Box2D mixes restitutions by max(e, 0)"
    return None


_NOTES = (
    "float32 engine (inputs rounded to float32). Detection by one world step (pyb2d3 0.11.1 "
    "binds no narrow phase nor b2ShapeDistance/b2TimeOfImpact): hit = Box2D's touching flag "
    "(manifold points, begin-touch event), which includes speculative points up to "
    "B2_SPECULATIVE_DISTANCE = 0.02 m apart (declared verdict margin 0.02); distance = the "
    "least point separation (negative: overlap); no contact beyond 0.02: no distance, no "
    "normal. Restitution threshold 1 m/s (an approach of exactly 1 bounces). "
    "Mass 0 is immovable (invMass 0). Refused: negative sizes, negative or NaN masses, "
    "negative restitution, non-finite inputs (pyb2d3 is a release build: no B2_ASSERT). "
    "Between two dynamic discs contacts are found at step starts (speculative within 0.02 m "
    "only): sampled_contacts; continuous collision sweeps dynamic bodies against static ones "
    "(enableContinuous), bullets also against non-bullet dynamic ones, never other bullets. "
    "The bounce is added once, after the sub-steps (b2ApplyRestitution), from the approach "
    "stored at the step start, where it is at least the threshold and the point took an "
    "impulse: bounce_at_step_end, bounce_from_step_start. ")


def _conventions(variant: Variant, settings: str) -> Conventions:
    cap = DEFAULT_MAX_SPEED if variant.max_speed is None else variant.max_speed
    margin = FLT_EPSILON
    return with_walls(Conventions(
        box_extents="half (b2MakeBox(hx, hy): vertices at +-hx, +-hy)",
        normal="A to B (b2Manifold.normal, shape A to shape B; negated when Box2D orders B, A)",
        touching={"sphere": True, "face": True, "corner": True},
        margins={"sphere": margin, "face": margin, "corner": margin},
        verdict_margins={f: SPECULATIVE_DISTANCE for f in ("sphere", "face", "corner")},
        rtol=RTOL,
        restitution="max of the shapes' restitutions (b2DefaultRestitutionCallback); A = e, B = 0",
        restitution_threshold=THRESHOLD,
        resolves_separating=False,
        time_step=variant.dt,
        damping=0.0,
        friction=DEFAULT_FRICTION if variant.friction is None else variant.friction,
        max_speed=cap,
        max_speed_at="before the contact solve",
        sampled_contacts=True,
        bounce_at_step_end=True,
        bounce_from_step_start=True,
        zero_mass="static",
        negative_extents="",
        no_value=("float32-textbook",),
        notes=_NOTES + settings,
        sources=SOURCES,
    ), variant)


WORKING_RANGE = 16e3
"""How far from the origin Box2D's positions keep their precision (m): constants.h, B2_HUGE:
"Positions greater than about 16km will have precision problems"."""
TUNED_FOR = (0.1, 10.0)
"""The sizes Box2D is tuned for (FAQ.md: "moving objects in the range 0.1 - 10 meters")."""
TUNNELLING = Claim(
    "velocities", ("sphere_scene",), 1.0,
    "\"By default, Box2D uses continuous collision detection (CCD) to prevent dynamic bodies "
    "from tunneling through static bodies\" (simulation.md, Bullets; the v3.0 release notes: "
    "it \"seems to prevent almost all dynamic versus static tunneling\"). Checked on the "
    "fast-wall block: a pass-through keeps the normal velocity (error 2 v_n / |v|: 2 head-on, "
    "1.41 at 45 degrees), a caught elastic bounce reverses it (error below 1: at most the "
    "tangential change friction makes)",
    B3 + "docs/simulation.md#L364-L369", blocks=("fast-wall",), dims=(2,))
PRECISION = Claim(
    "distance", ("sphere", "aabb"), RTOL,
    "float32 throughout (b2Vec2 of float, math_functions.h): a distance is off by a few "
    "float32 units of the numbers it is computed from, for the sizes Box2D is tuned for "
    "(FAQ.md: \"moving objects in the range 0.1 - 10 meters\") and within the range it "
    "names (constants.h, B2_HUGE: \"Positions greater than about 16km will have precision "
    "problems\")",
    B3 + "include/box2d/math_functions.h", dims=(2,), relative=True, relative_to="length",
    gap=(-math.inf, SPECULATIVE_DISTANCE), size=TUNED_FOR, offset=WORKING_RANGE)
SLOP = Claim(
    "settle", ("sphere_scene",), LINEAR_SLOP,
    "B2_LINEAR_SLOP: \"A small length used as a collision and constraint tolerance. Usually "
    "it is chosen to be numerically significant, but visually insignificant\" (0.005 m): a "
    "resting disc's gap to the ground (the suite's settle) within it; the regime: the sizes "
    "Box2D is tuned for (FAQ.md: \"moving objects in the range 0.1 - 10 meters\"), the "
    "resting blocks, within the range constants.h names (\"Positions greater than about "
    "16km will have precision problems\")",
    B3 + "src/constants.h#L19-L23", blocks=("rest-2d",), dims=(2,), size=TUNED_FOR,
    offset=WORKING_RANGE)


class Box2d3Tuned(SceneCallsAdapter):
    """Box2D v3 set for accuracy: small step, no friction, no rotation, no sleep, no cap."""

    name: ClassVar[str] = "box2d3"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "pyb2d3"
    package: ClassVar[str] = "pyb2d3"
    variant: ClassVar[Variant] = Variant(dt=1e-3, friction=0.0, fixed_rotation=True,
                                         sleep=False, max_speed=B2_HUGE)
    settings: ClassVar[str] = (
        "dt 1e-3 s, 4 sub-steps, friction 0, fixed rotation, sleeping off, maximumLinearSpeed "
        "B2_HUGE (1e5 m/s); restitution A = e, B = 0; detection: one step of a world")
    capabilities: ClassVar[frozenset[Capability]] = CAPABILITIES
    conventions: ClassVar[Conventions] = _conventions(variant, settings)
    claims: ClassVar[tuple[Claim, ...]] = (TUNNELLING, PRECISION, SLOP)
    supersedes: ClassVar[str] = "box2d"
    scene_tuning: ClassVar[Variant | None] = variant
    """What scenes are built with (its dt replaced by the scene's)."""

    calls: ClassVar[str] = "adapters.box2d3.calls"

    def version(self) -> str:
        return f"{dist_version('pyb2d3')} (Box2D {BOX2D_VERSION})"

    def available(self) -> str | None:
        return import_problem(engine, "pyb2d3")

    binding_objects: ClassVar[tuple[str, ...]] = ("_pyb2d3*.so",)
    """pyb2d3's nanobind module, Box2D compiled in."""

    def binding_call(self) -> Callable[[], object]:
        """A zero ``b2Vec2``: one object made through pyb2d3's binding."""
        return engine().Vec2  # type: ignore[no-any-return]

    def unsupported(self, case: AnyCase) -> str | None:
        if case.dim != 2:
            return f"box2d3 is a 2-D engine: no {case.kind} in {case.dim}-D"
        return super().unsupported(case)

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """One step of a world with the pair at rest; refused for inputs Box2D mis-handles."""
        v, why = self.variant, refused(refusal(case))
        build = "boxes" if isinstance(case, AabbCase) else "circles"
        return Call(build, "collide", {**pair_inputs(case), "dt": v.dt,
                                       "sub_steps": v.sub_steps}, refusal=why)

    def response_call(self, case: ResponseCase) -> Call:
        """Two discs stepped until a velocity changes."""
        v = self.variant
        return Call("world", "respond", {
            **response_inputs(case), "dt": v.dt, "sub_steps": v.sub_steps,
            "friction": v.friction,
            "fixed_rotation": v.fixed_rotation, "sleep": v.sleep, "bullet": v.bullet,
            "max_speed": v.max_speed, "max_steps": MAX_STEPS}, refusal=refused(refusal(case)))

    def scene_settings(self) -> dict[str, Any]:
        """The variant's inputs to the scene calls besides the scene (``scene_tuning``)."""
        return scene_settings(self.scene_tuning)

    def scene_call(self, case: SceneCase) -> Call:
        return Call("scene", "step_scene", {**scene_inputs(case), **self.scene_settings()},
                    release="release_scene")


class Box2d3Default(Box2d3Tuned):
    """Box2D v3 out of the box: only geometry, masses, velocities and restitution are set."""

    name: ClassVar[str] = "box2d3-default"
    variant: ClassVar[Variant] = Variant(dt=1.0 / 60.0, friction=None, fixed_rotation=False,
                                         sleep=True, max_speed=None)
    settings: ClassVar[str] = (
        "Box2D v3 defaults: dt 1/60 s, 4 sub-steps, friction 0.6, rotation free (disc moment), "
        "sleeping on, maximumLinearSpeed 400 m/s; restitution A = e, B = 0")
    conventions: ClassVar[Conventions] = _conventions(variant, settings)
    supersedes: ClassVar[str] = "box2d-default"
    scene_tuning: ClassVar[Variant | None] = None


class Box2d3Bullet(Box2d3Tuned):
    """Box2D v3 tuned with every disc a bullet (scenes only)."""

    name: ClassVar[str] = "box2d3-bullet"
    variant: ClassVar[Variant] = replace(Box2d3Tuned.variant, bullet=True)
    settings: ClassVar[str] = (
        "the box2d3 variant's settings (scenes: the scene's dt, 4 sub-steps, friction 0, "
        "fixed rotation, sleeping off, no speed cap); every disc a bullet (isBullet)")
    capabilities: ClassVar[frozenset[Capability]] = frozenset({(Kind.SPHERE_SCENE, 2)})
    claims: ClassVar[tuple[Claim, ...]] = (TUNNELLING, SLOP)
    supersedes: ClassVar[str] = "box2d-bullet"
    scene_tuning: ClassVar[Variant | None] = variant
    conventions: ClassVar[Conventions] = replace(
        Box2d3Tuned.conventions,
        notes=("Scenes only (2-D). Every disc a bullet (b2BodyDef.isBullet): swept against "
               "static, kinematic and non-bullet dynamic bodies, but \"not other bullets\" "
               "(simulation.md; b2ContinuousQueryCallback skips bullets, solver.c): between "
               "two discs contacts are still sampled at step starts (sampled_contacts), unlike "
               "box2d-bullet in v2, whose bullets are swept against each other. "
               + Box2d3Tuned.conventions.notes))
