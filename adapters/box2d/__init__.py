"""Box2D 2.3.0 through pybox2d 2.3.10 (``import Box2D``) as an engine: ``box2d``, ``box2d-default``.

Box2D is a 2-D engine in float32 (``float32`` is C ``float`` throughout): every 3-D case
is skipped with the reason "2-D engine", and every input is rounded to float32 on its way
into the engine.  Kinds: ``aabb`` (polygon boxes), ``sphere`` (circles) and
``sphere_response``, and ``sphere_scene`` (the scene calls, see below),
and ``sphere_toi``: ``b2TimeOfImpact`` on two circles (:mod:`adapters.box2d_toi`, where its
conventions, ``toi_target`` -0.015 and ``toi_tolerance`` 0.00125, are derived and cited).

Detection (``aabb``, ``sphere``): ``prepare`` builds two shapes (``b2PolygonShape(box=(hx,
hy))`` or ``b2CircleShape(radius=r)``) and two ``b2Transform`` s at the case's centres
(angle 0), with no world.  ``query`` calls Box2D's narrow phase, the function a world's
contact calls on every step: ``b2CollidePolygons`` / ``b2CollideCircles`` into a
``b2Manifold``.

- points in the manifold -> ``hit`` True; ``normal`` = ``b2WorldManifold.normal`` after
  ``Initialize`` ("world vector pointing from A to B", b2Collision.h; the e_faceB case is
  negated there), used as is.  ``distance`` is absent (None, scored ``skip``, "engine reported
  no distance"): Box2D has no penetration depth.  ``b2Distance`` is GJK without EPA: on
  overlapping cores it returns 0, on overlapping radii it returns 0 by definition
  (b2Distance.cpp), and pybox2d's ``b2WorldManifold`` has no ``separations`` (the bundled
  2.3.0 does not compute them).  Undefined was the other choice; it would be scored as a
  wrong answer (``disagree``/``error``) on every overlapping pair, while the engine does not
  answer wrongly: it does not answer.  Hence None.
- no points -> ``hit`` False; ``distance`` and ``normal`` from ``b2Distance`` (witness
  points ``pointA`` -> ``pointB``, normalised here in float64; None when they coincide).
  Tuned: ``useRadii=False`` on boxes of radius 0 (the gap itself; with ``useRadii=True`` a
  gap below ``b2_epsilon`` reads 0).  Circles always take ``useRadii=True``: a circle's
  distance proxy is its centre with the radius as skin.  Default: ``useRadii=True``
  (pybox2d's default), which subtracts the two 0.01 polygon skins.
``b2TestOverlap`` would give only a verdict, and its threshold is ``distance < 10 b2_epsilon``
(with the skins), not the contact rule a world uses; a world with contacts would add a
broad phase and a step to the same narrow phase.

Response (``sphere_response``): ``prepare`` builds a ``b2World`` (gravity 0) with two
dynamic bodies (``CreateDynamicBody`` with the case's centre and velocity: Box2D's body
definition asserts that both are finite, so NaN or inf raises ``AssertionError`` there),
each with one circle fixture (density 0, so ``massData`` sets the mass exactly: the case's
mass, centre 0).  ``query`` resets the pair (both bodies deactivated and reactivated, which
destroys the contact and its cached impulses: no warm start from an earlier query; then
``transform``, velocity, angular velocity 0, awake), and steps until the first step after
which the pair's contact is ``touching``, or until they no longer approach, or
``MAX_STEPS``.  ``b2World::Step`` first updates contacts (the narrow phase at the positions
the step starts from), then solves the touching ones and integrates: ``resolved_at`` is the
centres read before that step.  The velocities after it are the answer (position
correction moves positions only).  Restitution: Box2D mixes the fixtures' values by
``max`` (b2MixRestitution), so A's fixture gets the case's ``e`` and B's 0.

Scenes (``sphere_scene``, 2-D) are the scene calls of :mod:`adapters.box2d.calls` (worlds
built as responses are), with the variant's ``scene_tuning``: ``box2d`` passes its ``variant``
(dt and iterations from the scene), ``box2d-default`` None (Box2D's defaults); the scene
conventions, measured, are in :mod:`adapters.box2d.scene`'s docstring, and so are the walls
of scenes with surroundings (static bodies with box fixtures) and the declared ``rest_gap``
(-b2_linearSlop, polygon radius), ``rest_sink_steps``, ``sleeps`` and ``wall_restitution``
(``scene.with_walls``).

Variants (sources below):

- ``box2d``: polygon ``radius = 0`` (no skin) and ``useRadii=False`` for boxes; response:
  dt 1e-3 s, 8 velocity and 3 position iterations, friction 0, ``fixedRotation`` (the
  moment plays no part without friction; it also makes a zero radius harmless), sleeping
  off with ``SetAllowSleeping(False)`` (a slow body would fall asleep before it arrives).
  pybox2d's ``b2World(doSleep=False)`` and ``world.allowSleeping = False`` only set a Python
  attribute: Box2D keeps sleeping on (measured; ``GetAllowSleeping()`` stays True).
- ``box2d-default``: polygon skin ``b2_polygonRadius`` (0.01 per box, kept), ``useRadii``
  True; response: dt 1/60 s with 8 and 3 iterations (the pybox2d testbed's ``hz``,
  ``velocityIterations``, ``positionIterations``; ``Step`` has no defaults), friction 0.2
  (``b2FixtureDef`` default), rotation free with the disc's moment ``m r^2 / 2`` (what a
  density gives), sleeping allowed (``b2World`` default): a body slower than
  ``b2_linearSleepTolerance`` (0.01 m/s) for ``b2_timeToSleep`` (0.5 s) falls asleep with its
  velocity zeroed (b2Island.cpp), so a slow approach from afar stops before it arrives.

Conventions (each from Box2D's source as pybox2d 2.3.10 bundles it, ``SOURCES``):

- box extents half: ``box=(hx, hy)`` calls ``SetAsBox(hx, hy)``, vertices at +-hx, +-hy
  [Box2D_shapes.i, b2PolygonShape.cpp].
- normal A to B (above).
- touching: circles touching collide (``distSqr > radius * radius`` is the only reject,
  b2CollideCircle.cpp); face-touching boxes collide (``separation > totalRadius`` rejects);
  corner-touching boxes of radius 0 do NOT (the incident edge clips to no point at the
  reference face's side planes: measured); with the default skins they do (within 0.02).
  Declared per variant: tuned sphere/face contact, corner apart; default all contact.
- margins (distance and normal): ``b2_epsilon`` (FLT_EPSILON, 1.19e-7) everywhere: Box2D
  uses it as an absolute length tolerance (b2Distance.cpp: GJK stops as "overlapped" below
  it, and with radii a distance not above it reads 0; b2Collision.cpp: circle centres
  closer than it get the normal (1, 0)); measured: spheres of radius 1e-9 a gap of 1e-12
  apart read 0, boxes of half-width 1e-9 a gap of 2e-9 apart read 4e-9.  Default: plus
  0.02 at faces and corners (two ``b2_polygonRadius`` = 2 x 2 ``b2_linearSlop``,
  b2Settings.h): the distance is the gap less it.  The verdict does not use
  ``b2_epsilon`` (``distSqr > radius * radius`` and ``separation > totalRadius`` reject,
  b2CollideCircle.cpp, b2CollidePolygon.cpp): its margins (``verdict_margins``) are none in
  the tuned variant and the two skins, 0.02 at faces and corners, in the default one.
- rtol ``RTOL`` = 2^-21 (8 float32 units of 2^-24), of the case's size: every input is
  rounded to float32 and every operation is float32.  Measured on 2,000 random unit box
  pairs at a 1e6 offset, gaps 0.05 to 1: distance off by a median 0.018, worst 0.060 (the
  float32 spacing there is 0.0625: a 0.2 gap reads 0.1875), within 2^-21 x 1e6 = 0.48.
- restitution: ``max`` of the fixtures', A = e and B = 0 gives e.  Restitution threshold:
  ``b2_velocityThreshold`` = 1 m/s, compiled in; the solver bounces only when ``vRel <
  -b2_velocityThreshold`` in float32 (b2ContactSolver.cpp), so an approach of exactly 1
  m/s is inelastic: declared ``THRESHOLD`` = 1 + 2^-23, one float32 unit above 1.
- separating contacts: the accumulated normal impulse is clamped at 0, so bodies already
  moving apart are left alone (``resolves_separating`` False).
- time step: each variant's dt (1e-3, 1/60), fixed; damping 0 (``linearDamping`` default 0).
  ``b2_maxTranslation`` = 2 m per step (b2Island.cpp: after the velocity constraints are
  solved, a body whose step ``h v`` is longer has ``v`` scaled down to it, and keeps the
  scaled velocity): declared ``max_speed`` 2 / dt, 2000 m/s (tuned) or 120 m/s (default),
  acting at the end of every step (``max_speed_at`` "step").  The ``speed-cap`` cases of
  cases/response.toml exercise it (touching pairs at 200 to 3000 m/s: the contact is
  solved in the first step with the case's speeds, then the result is clipped).
- zero mass: refused (``zero_mass`` ""): ``SetMassData`` silently reads a mass <= 0 as 1
  (b2Body.cpp), so the adapter raises ``ValueError`` instead (recorded as ``error``).
- negative sizes: refused (``negative_extents`` ""): ``SetAsBox`` with a negative half-width
  builds an inside-out polygon (vertices clockwise, normals unchanged) that collides with
  nothing, not even overlapping (no manifold point), while ``b2Distance`` sees the magnitude
  (measured), and a negative circle radius sum is squared in the verdict but read literally
  in the distance.

Guarded inputs (``ValueError`` in ``prepare``, the reason in the message): non-finite
detection inputs (the collide functions take them unchecked: a NaN radius or centre reads
as contact, measured), non-finite radii, NaN or non-positive masses and a negative or NaN
restitution (``max(e, 0)`` would silently read 0).  An infinite mass is Box2D's own
immovable body (inverse mass 0) and is passed on.  Numbers beyond float32's range are
refused by pybox2d itself (``OverflowError`` / ``TypeError``).  ``CreateFixture`` with a
fixture definition without a shape (``b2FixtureDef()``) segfaults (pybox2d's keyword form
raises ``ValueError`` first); the adapter always passes a shape (the runner's worker
isolation covers any segfault).

Other facts measured (engine faults the report shows as ``error``, not hidden): a box edge
shorter than ``b2_epsilon`` gives a manifold normal that is not a unit vector (its length is
the edge's, 0 for a zero-size box: ``b2Vec2::Normalize`` leaves a vector shorter than
``b2_epsilon`` as it is, b2Math.h; reported as the engine gives it); a response at a 1e8
offset rounds 3-4-5 neighbours onto one float32 point, so the bodies collide along (1, 0);
the default variant's friction (0.2) changes every oblique response (declared:
``friction`` 0.2, judged by :mod:`crosscheck.truth.contact_model`).  Coincident circles
get normal (1, 0) (centres within ``b2_epsilon``); coincident boxes the first face of least
overlap, (0, -1).

(Longer than 400 lines: about 160 of them are this docstring, the conventions as measured with
their sources; the code is two short paths, detection and stepped response, and one guard.)

Times of impact (``sphere_toi``, 2-D): ``b2TimeOfImpact`` on two circle sweeps (no world nor
bullet body): the sweeps interpolate ``(1 - t) c0 + t c`` over Box2D's ``t`` in [0, 1]
(b2Math.h), from the start centre to ``center + velocity x duration`` (float64, then
float32 in the binding), so ``toi`` = ``t x duration``; the normal is the unit vector
between ``b2Distance``'s witness points (``useRadii=False``: the centres) at the sweeps'
transforms at ``t``, Undefined where they coincide.  States (b2TimeOfImpact.cpp):
``e_touching`` and ``e_overlapped`` a hit, ``e_separated`` no contact, ``e_failed`` and
``e_unknown`` an error.  Box2D does not look for the touching time: it advances until the
centre distance is within ``0.25 b2_linearSlop`` of ``max(b2_linearSlop, totalRadius - 3
b2_linearSlop)`` (``b2_linearSlop`` 0.005 m): the surfaces then overlap by 0.015 m.
Declared ``toi_target`` -0.015, ``toi_tolerance`` 0.00125 and, for a radius sum below 0.02,
``toi_min_centre_distance`` 0.005; a pair that never overlaps by that much reads as no
contact.  The calls, plain data in and out, are :mod:`adapters.box2d.calls`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any, ClassVar

from adapters.box2d.calls import engine
from adapters.box2d.scene import Variant, scene_settings, with_walls
from adapters.shared import toi_refusal
from adapters.stepping import SceneCallsAdapter, scene_inputs
from crosscheck.core.claims import APART, Claim
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
from crosscheck.core.schema import (
    AabbCase,
    AnyCase,
    PairCase,
    ResponseCase,
    SceneCase,
    SphereCase,
    ToiCase,
)

B2 = "https://github.com/pybox2d/pybox2d/blob/2.3.10/Box2D/"
SOURCES = (
    B2 + "Common/b2Settings.h",  # polygonRadius, velocityThreshold 1, maxTranslation 2, b2Assert
    B2 + "Box2D_shapes.i",  # box= property calls SetAsBox
    B2 + "Box2D_misc.i",  # b2Distance(shapeA, .., useRadii) wrapper
    B2 + "Collision/Shapes/b2PolygonShape.cpp",  # SetAsBox(hx, hy): vertices at +-hx, +-hy
    B2 + "Collision/b2CollideCircle.cpp",  # distSqr > radius^2 rejects: touching collides
    B2 + "Collision/b2CollidePolygon.cpp",  # separation > totalRadius rejects; clipping
    B2 + "Collision/b2Collision.cpp",  # b2WorldManifold: normal A to B, (1, 0) within eps
    B2 + "Collision/b2Collision.h",  # no separations in b2WorldManifold (2.3.0)
    B2 + "Collision/b2Distance.cpp",  # GJK; useRadii: overlap -> distance 0; b2_epsilon
    B2 + "Common/b2Math.h",  # b2Vec2::Normalize leaves vectors shorter than b2_epsilon
    B2 + "Dynamics/Contacts/b2Contact.h",  # b2MixRestitution: max
    B2 + "Dynamics/Contacts/b2ContactSolver.cpp",  # vRel < -b2_velocityThreshold; clamp >= 0
    B2 + "Dynamics/b2Island.cpp",  # b2_maxTranslation clips velocities
    B2 + "Dynamics/b2Body.cpp",  # SetMassData: mass <= 0 -> 1
    B2 + "Dynamics/b2World.cpp",  # Step: Collide, then Solve; SetAllowSleeping
    B2 + "Box2D_world.i",  # b2World.__init__: self.allowSleeping = doSleep (no such property)
    B2 + "Dynamics/b2Fixture.h",  # b2FixtureDef friction 0.2, restitution 0, density 0
    "https://github.com/pybox2d/pybox2d/blob/2.3.10/library/Box2D/examples/settings.py",
)
RTOL = 2.0**-21
"""8 float32 units (2^-24) of the case's size."""
THRESHOLD = 1.0 + 2.0**-23
"""b2_velocityThreshold (1 m/s), bounced only strictly above, compared in float32."""
MAX_TRANSLATION = 2.0
"""b2_maxTranslation: the longest step a body may take (m); faster velocities are scaled."""
B2_EPSILON = 2.0**-23
"""b2_epsilon (FLT_EPSILON): the absolute length below which Box2D's geometry gives up."""
SKIN = 0.02
"""Two boxes' b2_polygonRadius (0.01 each): the default variant's extra margin at boxes."""
MAX_STEPS = 100_000
"""Step cap of a response query (bodies still approaching without touching)."""
TOI_SOURCES = (
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


CAPABILITIES = frozenset({(Kind.AABB, 2), (Kind.SPHERE, 2), (Kind.SPHERE_RESPONSE, 2),
                          (Kind.SPHERE_SCENE, 2), (Kind.SPHERE_TOI, 2)})


def _finite(xs: Sequence[float]) -> bool:
    return all(math.isfinite(x) for x in xs)


def refusal(case: PairCase) -> str | None:
    """Why the adapter refuses ``case``: an input Box2D would silently mis-handle (or None)."""
    sizes = [*case.a.half, *case.b.half] if isinstance(case, AabbCase) else [
        case.a.radius, case.b.radius]
    if any(x < 0 for x in sizes):
        return ("negative size: Box2D builds an inside-out box or squares a negative radius "
                "sum (see the adapter's conventions)")
    if not isinstance(case, ResponseCase):
        if not _finite([*case.a.center, *case.b.center, *sizes]):
            return "non-finite input: Box2D's collide functions take it unchecked"
        return None
    if not _finite(sizes):
        return "non-finite radius: Box2D's circle collision takes it unchecked"
    if not all(m > 0 for m in (case.a.mass, case.b.mass)):
        return "mass NaN or <= 0: b2Body::SetMassData reads a mass <= 0 as 1"
    if not case.restitution >= 0:
        return "restitution negative or NaN: Box2D mixes restitutions by max(e, 0)"
    return None


DEFAULT_FRICTION = 0.2
"""b2FixtureDef's friction (Dynamics/b2Fixture.h); mixed as sqrt(fA fB) (b2MixFriction) = 0.2."""


def _conventions(variant: Variant, settings: str) -> Conventions:
    skin = variant.polygon_radius is None
    box_margin = B2_EPSILON + (SKIN if skin else 0.0)
    verdict = {"face": SKIN, "corner": SKIN} if skin else {}
    return with_walls(Conventions(
        box_extents="half (box=(hx, hy) calls b2PolygonShape::SetAsBox(hx, hy))",
        normal="A to B (b2WorldManifold.normal; apart: b2Distance pointA -> pointB); as is",
        touching={"sphere": True, "face": True, "corner": skin},
        margins={"sphere": B2_EPSILON, "face": box_margin, "corner": box_margin},
        verdict_margins=verdict,
        rtol=RTOL,
        restitution="max of the fixtures' restitutions (b2MixRestitution); A = e, B = 0",
        restitution_threshold=THRESHOLD,
        resolves_separating=False,
        time_step=variant.dt,
        damping=0.0,
        friction=DEFAULT_FRICTION if variant.friction is None else variant.friction,
        max_speed=MAX_TRANSLATION / variant.dt,
        max_speed_at="step",
        sampled_contacts=True,
        zero_mass="",
        negative_extents="",
        toi_target=TOI_TARGET,
        toi_tolerance=TOI_TOLERANCE,
        toi_min_centre_distance=LINEAR_SLOP,
        # b2Distance's witness points are the float32 centres at the reported time: none
        # where they coincide there (box2d_toi: the normal Undefined then)
        no_value=("float32-centre-line",),
        notes=_NOTES + TOI_NOTES + settings + _WALL_NOTES,
        sources=SOURCES + TOI_SOURCES + (B2 + "Dynamics/b2World.cpp",),
    ), variant)


_NOTES = ("float32 engine (inputs rounded to float32). Detection: b2CollidePolygons / "
          "b2CollideCircles manifold (hit, normal); apart: b2Distance (distance, normal). "
          "No penetration depth: the distance of a colliding pair is not reported (skip). "
          "Touching circles and face-touching boxes collide. Restitution threshold 1 m/s "
          "(b2_velocityThreshold, compiled in; bounce only when vRel < -1 in float32). "
          "Velocities above 2 m per step are clipped at the end of each step "
          "(b2_maxTranslation: declared max_speed 2 / dt). The verdict has no b2_epsilon: "
          "only the polygon skins (default) act on it. "
          "Refused (ValueError): negative sizes, mass <= 0 (Box2D reads it as 1), negative "
          "restitution, non-finite detection inputs and radii. Scenes (2-D): every fixture "
          "gets e; the threshold and the 2 m a step cap act there too, at the scene's dt. "
          "Contacts between two dynamic bodies are sampled at each step (sampled_contacts): "
          "b2World::SolveTOI sweeps a pair only if one is a bullet or not dynamic "
          "(b2World.cpp; the box2d-bullet variant sets bullet). ")

_WALL_NOTES = (
    " Gravity and walls (scenes): each wall a static body on its surface with a SetAsBox "
    "fixture 1000 x the largest radius thick, 1e4 x the scene's extent sideways, its face "
    "at exactly 0 in the body's frame (float32), the variant's polygon radius; restitution "
    "e (max), the variant's friction; rest band -b2_linearSlop to the polygon radius "
    "(b2ContactSolver.cpp position solver, b2Settings.h); sleeping as the variant sets it.")


_SLOP = ("b2Settings.h: b2_linearSlop 0.005, \"A small length used as a collision and "
         "constraint tolerance. Usually it is chosen to be numerically significant, but "
         "visually insignificant.\"")
_FLOAT32 = ("b2Settings.h: \"typedef float float32\", the type of every length, and b2_epsilon "
            "FLT_EPSILON: every input is rounded to float32 and every operation is float32; "
            "read here as 8 float32 units (2^-24) of the numbers the engine holds (2^-21 x the "
            "case's largest |coordinate|, radius or half-width, the adapter's rtol)")


_TUNED_SIZES = (
    " The manual (https://github.com/erincatto/box2d/blob/v2.3.0/Box2D/Documentation/"
    "manual.docx, Units): \"These tolerances have been tuned to work well with "
    "meters-kilogram-second (MKS) units. In particular, Box2D has been tuned to work well with "
    "moving shapes between 0.1 and 10 meters.\"")
SIZES = (0.1, 10.0)
"""The shapes' sizes Box2D's tolerances are tuned for (the manual's Units)."""


def box2d_claims(kinds: tuple[str, ...]) -> tuple[Claim, ...]:
    """Box2D's collision tolerance and float32 arithmetic on ``kinds`` (2-D), for the sizes
    its tolerances are tuned for: a verdict right on every pair farther than b2_linearSlop
    from touching, a distance (reported apart only) within b2_linearSlop, and within 2^-21 of
    the case's numbers."""
    source = B2 + "Common/b2Settings.h"
    return (
        Claim("hit", kinds, 0.0, _SLOP + "; read here as a verdict right on every pair "
              "farther than b2_linearSlop from touching." + _TUNED_SIZES, source,
              size=SIZES, clear_of_touching=LINEAR_SLOP, dims=(2,)),
        Claim("distance", kinds, LINEAR_SLOP, _SLOP + "; read here as a distance (b2Distance, "
              "pairs apart) within b2_linearSlop." + _TUNED_SIZES, source, size=SIZES,
              gap=APART, dims=(2,)),
        Claim("distance", kinds, RTOL, _FLOAT32 + "." + _TUNED_SIZES, source, size=SIZES,
              gap=APART, dims=(2,), relative=True, relative_to="length"),
    )


class Box2dTuned(SceneCallsAdapter):
    """Box2D set for accuracy: no polygon skin, small step, no friction, no rotation, no sleep."""

    name: ClassVar[str] = "box2d"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "pybox2d"
    package: ClassVar[str] = "box2d"
    variant: ClassVar[Variant] = Variant(polygon_radius=0.0, use_radii=False, dt=1e-3,
                                         friction=0.0, fixed_rotation=True, sleep=False)
    settings: ClassVar[str] = (
        "polygon radius 0, b2Distance useRadii=False for boxes; response: dt 1e-3 s, "
        "8 velocity / 3 position iterations, friction 0, fixedRotation, sleeping off, "
        "restitution A = e, B = 0")
    capabilities: ClassVar[frozenset[Capability]] = CAPABILITIES
    conventions: ClassVar[Conventions] = _conventions(variant, settings)
    claims: ClassVar[tuple[Claim, ...]] = box2d_claims(("sphere", "aabb"))
    scene_tuning: ClassVar[Variant | None] = variant
    """What scenes are built with (its dt replaced by the scene's; adapters/box2d/scene.py)."""

    calls: ClassVar[str] = "adapters.box2d.calls"

    def version(self) -> str:
        b2 = engine()
        v = b2.b2Globals.b2_version
        return f"{b2.__version__} (Box2D {v.major}.{v.minor}.{v.revision})"

    def available(self) -> str | None:
        return import_problem(engine, "Box2D")

    binding_objects: ClassVar[tuple[str, ...]] = ("_Box2D*.so",)
    """The engine's shared objects for the instruction timer: pybox2d's SWIG module, Box2D compiled
    in.
    """

    def binding_call(self) -> Callable[[], object]:
        """A zero ``b2Vec2``: one object made through pybox2d's SWIG binding."""
        return engine().b2Vec2  # type: ignore[no-any-return]

    def unsupported(self, case: AnyCase) -> str | None:
        if case.dim != 2:
            return f"box2d is a 2-D engine: no {case.kind} in {case.dim}-D"
        return super().unsupported(case)

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """The manifold, else ``b2Distance``; refused for inputs Box2D mis-handles."""
        v, why = self.variant, refused(refusal(case))
        if isinstance(case, AabbCase):
            return Call("boxes", "collide", {
                **pair_inputs(case), "polygon_radius": v.polygon_radius,
                "use_radii": v.use_radii}, refusal=why)
        return Call("circles", "collide", pair_inputs(case), refusal=why)

    def response_call(self, case: ResponseCase) -> Call:
        """Two discs stepped until the contact (sleeping: not doSleep=, see the docstring)."""
        v = self.variant
        return Call("world", "respond", {
            **response_inputs(case), "dt": v.dt,
            "velocity_iterations": v.velocity_iterations,
            "position_iterations": v.position_iterations, "friction": v.friction,
            "fixed_rotation": v.fixed_rotation, "sleep": v.sleep, "bullet": v.bullet,
            "max_steps": MAX_STEPS}, refusal=refused(refusal(case)))

    def toi_call(self, case: ToiCase) -> Call:
        """``b2TimeOfImpact``; refused for inputs Box2D would take unchecked."""
        a, b = case.a, case.b
        inputs: dict[str, Any] = {
            "a_center": a.center, "a_radius": a.radius, "a_velocity": a.velocity,
            "b_center": b.center, "b_radius": b.radius, "b_velocity": b.velocity,
            "duration": case.duration}
        return Call("sweeps", "time_of_impact", inputs, refusal=refused(toi_refusal(**inputs)))

    def scene_settings(self) -> dict[str, Any]:
        """The variant's inputs to the scene calls besides the scene (``scene_tuning``)."""
        return scene_settings(self.scene_tuning)

    def scene_call(self, case: SceneCase) -> Call:
        return Call("scene", "step_scene", {**scene_inputs(case), **self.scene_settings()},
                    release="release_scene")



class Box2dDefault(Box2dTuned):
    """Box2D out of the box: only geometry, masses, velocities and restitution are set."""

    name: ClassVar[str] = "box2d-default"
    variant: ClassVar[Variant] = Variant(polygon_radius=None, use_radii=True, dt=1.0 / 60.0,
                                         friction=None, fixed_rotation=False, sleep=True)
    settings: ClassVar[str] = (
        "polygon radius b2_polygonRadius (0.01), b2Distance useRadii=True; response: dt 1/60 s, "
        "8 velocity / 3 position iterations (pybox2d testbed), friction (0.2), rotation free "
        "(disc moment), sleeping allowed; restitution A = e, B = 0")
    conventions: ClassVar[Conventions] = _conventions(variant, settings)
    claims: ClassVar[tuple[Claim, ...]] = box2d_claims(("sphere",))
    """Circles only: its boxes keep the b2_polygonRadius skin, which the claims leave out."""
    scene_tuning: ClassVar[Variant | None] = None


BOX2D_BULLET_SOURCES = (
    B2 + "Dynamics/b2World.cpp",  # SolveTOI: collideA = IsBullet() || not dynamic
    B2 + "Dynamics/b2Body.h",  # b2BodyDef.bullet
)


class Box2dBullet(Box2dTuned):
    """Box2D tuned with every disc a bullet: continuous collision between dynamic bodies."""

    name: ClassVar[str] = "box2d-bullet"
    variant: ClassVar[Variant] = replace(Box2dTuned.variant, bullet=True)
    settings: ClassVar[str] = (
        "the box2d variant's settings (scenes: the scene's dt and iterations, friction 0, "
        "fixedRotation, sleeping off); every disc a bullet (b2BodyDef bullet=True)")
    capabilities: ClassVar[frozenset[Capability]] = frozenset({(Kind.SPHERE_SCENE, 2)})
    claims: ClassVar[tuple[Claim, ...]] = ()  # scenes only: no distance or verdict to claim
    scene_tuning: ClassVar[Variant | None] = variant
    conventions: ClassVar[Conventions] = replace(
        Box2dTuned.conventions,
        sampled_contacts=False,
        notes=("Scenes only (2-D).  Every disc a bullet: b2World::SolveTOI finds the time of "
               "impact of a contact between two dynamic bodies when one is a bullet, moves "
               "the pair there and solves it with restitution.  The speed cap stays: "
               "b2_maxTranslation, 2 m a step (declared max_speed 2 / dt at the declared "
               "time step: 2 m per step at any dt).  Walls as the box2d variant's (no skin, "
               "rest band -b2_linearSlop to 0, no sleeping); every variant's discs are swept "
               "against static walls, bullets or not.  Measured in adapters/box2d/scene.py"),
        sources=Box2dTuned.conventions.sources + BOX2D_BULLET_SOURCES,
    )
