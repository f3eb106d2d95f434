"""Adapters for pymunk 7.3.1 (Munk2D 2.0.1, a Chipmunk2D fork): ``pymunk``, ``pymunk-default``.

pymunk is a 2-D engine: every 3-D case is skipped with the reason "2-D engine".  Detection
(``aabb``, ``sphere``): each body is a static ``pymunk.Body`` placed at the case's centre
carrying a ``pymunk.Poly.create_box`` (full width and height, so the adapter passes
``2 * half``; radius 0, no bevel) or a ``pymunk.Circle``.  ``prepare`` builds the shapes and calls
``cache_bb()`` (shapes outside a Space keep stale positions until then).  ``query`` is one
``a.shapes_collide(b)`` (the calls, plain data in and out, are :mod:`adapters.pymunk.calls`):
- points -> ``hit`` True; ``distance`` = the smallest ``ContactPoint.distance``
  (negative when penetrating); ``normal`` = ``ContactPointSet.normal``, which
  points from the first shape to the second (``cpShapesCollide`` flips it when
  the collision function swapped the pair), so it is used as is.
- no contact: pymunk raises ``AssertionError`` (it asserts ``count in (1, 2)``
  while building the ``ContactPointSet``).  Exactly that is caught and reported
  as ``hit`` False with distance and normal absent: pymunk gives no separation
  distance.  Because the signal is an assert, ``available()`` refuses ``python -O``.  pymunk 6
  returns an empty ``ContactPointSet`` instead (measured with 6.11.1), read the same way.
``Space.shape_query`` returns the same ``ContactPointSet`` after a bounding-box
pre-filter, and segment/point queries do not give a pair's distance, so the
direct pairwise call is used.

Response (``sphere_response``, 2-D): two dynamic circles (mass from the case,
moment ``MOMENT``, infinite) in a Space with gravity (0, 0) and damping 1.0 (no
damping).  Why not ``moment_for_circle(m, 0, r)``: the moment plays no part in the
answer (the contact normal of two circles passes through both centres and there is no
friction, so no impulse has a torque), while the radius-based one is 0 for r = 0 (pymunk
then refuses the body: AssertionError) and NaN for a NaN radius (Munk2D's
``cpBodySetMoment`` assert aborts the process).  pymunk documents an infinite moment as a
body that cannot rotate [body.py]: Munk2D's inverse moment is then exactly 0, so the
effective mass along the normal is exactly 1/ma + 1/mb, the textbook's, with no rounding
of a tiny r x n through the moment (measured on the suite's 77 finite 2-D responses: the
same answers as any finite moment such as 1.0, and as the radius-based moment except for
an ulp in 3 cases).  Restitution: Munk2D combines the shapes' elasticities as their
product, so A gets the case's ``e`` and B gets 1.0.  ``prepare`` builds the
Space, the bodies and the shapes.  ``query`` removes and re-adds the shapes
(dropping the cached arbiter: no contact persistence or warm-start impulse),
zeroes the bias velocity the last solve left in each body with
``Body.update_position(body, 0)`` (measured: without it a second query of a
deep overlap starts from other positions), resets centres and velocities, and
steps with the variant's ``dt`` until the first step in which the solver handled
the contact (seen by a ``pre_solve`` callback registered with
``Space.on_collision(pre_solve=f)``, ``f(arbiter, space, data)``), or until the
bodies no longer approach without having touched, or ``MAX_STEPS``.
Munk2D integrates positions first and then collides, so the centres read in
``pre_solve`` are where the resolving contact was computed: they are returned
as ``resolved_at`` (the truth is computed there, not at the case's centres).  The
first ``pre_solve`` of a query is the first step that reported the contact, and the
stepping ends with that step: the configuration recorded is the one the solver resolved.

Variants (Space settings; sources below):

- ``pymunk``: dt = 1e-3 s (1 kHz: the contact is resolved closer to the touching
  configuration), collision_slop 0, collision_bias 1.0 (no positional
  correction; bias impulses go to separate bias velocities, and v1/v2 were
  measured bit-identical with the default bias), iterations 10 stated
  explicitly (measured on 162 random and suite cases: one pass leaves up to
  8e-16 relative rounding, two or more reach the same fixed point, 4e-16 at
  most), friction 0.
- ``pymunk-default``: dt = 1/60 s (the usual game step); slop (0.1f, i.e.
  0.10000000149), bias ((1 - 0.1f)^60), iterations (10) and friction (0) left
  at their defaults.

Scenes (``sphere_scene``) are the calls ``scene``/``step_scene`` of :mod:`adapters.pymunk.calls`:
``pymunk`` passes its slop, bias and friction (``scene_tuned``), ``pymunk-default`` None for
each (pymunk's defaults).  Gravity and walls (static Poly boxes on ``space.static_body``):
each variant declares ``rest_gap`` = (-collision_slop, 0), i.e. (-0.1f, 0) default and (0, 0)
tuned, ``rest_sink_steps`` 1, no sleeping and the wall's restitution (sqrt(e), product e).

Scene conventions, measured with the scene calls (sources as in ``SOURCES``):

- restitution: Munk2D combines the shapes' elasticities by their product [cpArbiter.c];
  measured: shapes set to 0.5 and 0.8 bounce with 0.4 (not the min, mean or max).  Every
  shape gets sqrt(e), so every pair gets e (to an ulp; e = 0.25, 0.5, 0.81 measured
  exactly in both variants).  There is no restitution threshold.
- touching at the start (distance exactly 0) is not a contact (circles collide only when
  strictly overlapping [cpCollision.c]), but a step moves positions before it collides
  [cpSpaceStep.c]: two touching balls, one moving at 1 into the other, overlap after the
  move and exchange velocities in step 1; touching balls moving together stay untouched
  (a pair at 0.3 for 100 steps, velocities and gap exact).
- simultaneous contacts: in a chain of touching balls only the pair that overlaps after a
  step's move collides, so momentum passes one ball per step.  5-ball cradle (equal masses,
  e = 1, striker at 1): step k hands velocity 1 to ball k; after 4 steps only the last ball
  moves, at exactly 1, the others exactly 0 (the textbook cradle), whatever the iterations
  (1, 10, 50, 1000) and in both variants.
- energy at e = 1: kinetic energy and momentum kept to rounding (16 random discs, 3 s at dt
  1e-3: energy exactly, momentum within 9e-16; the cradle exactly); at dt 1/60 with speeds
  up to 7, energy lost up to 1.8e-7 of its value.  Both variants alike: slop and bias act
  on positions through separate bias velocities, and only on overlaps beyond the slop
  (0.1); at dt 1e-3 the variants' states were bit-identical in 20 random scenes of 2 to 30
  discs, at dt 1/60 and speeds x 5 in 4 of 5 (the fifth: same energy, other states).
- impacts are resolved in the first step whose move makes the discs overlap, so centres lag
  the exact run by up to the closing speed x dt (0.002 measured, dt 1e-3).

Gravity and walls (``surroundings``; declared per variant by :func:`with_walls`):

- a wall is what pymunk's users build for a ground: a static shape on ``space.static_body``,
  here a ``Poly`` box of radius 0 (no bevel), 1000 x the largest radius thick on the solid
  side and 1e4 x the scene's extent sideways (:mod:`adapters.shared.wall_boxes`), its surface at
  the wall's offset exactly (float64 corners).  A ``Segment`` would be thin (a disc faster
  than its radius a step tunnels) and, like a circle, collides only when strictly
  overlapping; walls never collide with each other (shapes of one static body).
- resting: a disc touching a ``Poly`` is a contact (``points.d <= circle->r + poly->r``,
  cpCollision.c ``CircleToPoly``), so a disc placed on the ground stays at gap 0 (measured:
  exactly 0 and speed exactly 0 over 10 s, both variants, dt 1e-3, 1/240, 1/60).  Touching
  discs are not a contact, so a disc on a disc first falls one step, ``|g| dt**2``
  (``REST_SINK_STEPS``); overlaps are corrected only beyond collision_slop
  (``con->bias = -bias * min(0, dist + slop) / dt``, cpArbiter.c), by bias velocities that
  the tuned variant's collision_bias 1.0 turns off (``1 - bias^dt`` = 0, cpSpaceStep.c):
  ``rest_gap`` is (-slop, 0), (-0.1f, 0) default and (0, 0) tuned.  The declared sink
  is that one contact's fall; in a column the falls add up and are never corrected (the
  lower discs are pushed down by the impulses from above, and a step moves before it
  collides).  Measured, columns of n discs (r 0.1) set touching on the ground for 5 s,
  both variants alike and in units of ``|g| dt**2`` the same at dt 1/60 and 1/240 (deepest
  gap during the run / at the end): e 0: n 2 and 3: -1.00 / -1.00, n 5: -2.0 / -1.9, n 10:
  -2.9 / -2.3, n 20: -5 / -5; e 0.5: n 2 -1.18 / -0.79, n 3 -1.04 / -0.71, n 10 -2.5 / -1.8;
  e 1: the column does not stay at rest (each step's fall is bounced back elastically):
  n 3 -7 to -10 / -2.4 to -2.9 with speeds up to 0.8 m/s after 4 s, n 10 down to -177
  with speeds up to 5 m/s.
- sleeping: off in both variants (``sleep_time_threshold`` INFINITY unless set, cpSpace.c).
- restitution with walls: a wall's shape gets sqrt(e) like the discs (product e).  The bounce
  velocity is taken in the prestep, before the step's gravity is added (cpSpaceStep.c), so
  an elastic drop keeps its height: measured, a disc dropped from 1 m (e 1) kept every
  apex at 1.000000 m for 10 s at dt 1e-3, 1/240 and 1/60, both variants; a disc at 3 m/s
  between two walls in zero gravity kept exactly 3 over 10 s, 17 bounces.
- friction of a wall: the variant's for the discs (tuned 0; default pymunk's 0), combined by
  product (``arb->u = a->u * b->u``, cpArbiter.c).
Measured outside the suite with the scene calls (the drop: a disc of radius 0.1 at 1.1 above
the ground, e 1, 10 s, every step recorded).

collision_slop is a Space setting: it only sets how much overlap the bias term
leaves uncorrected.  It does not apply to ``shapes_collide`` nor to the
velocity impulse, so both variants declare margin 0.  rtol 2^-49: float64
throughout (cpFloat is double); the worst distance error measured on 20 000
random 2-D box and circle pairs (offsets up to 1e6) was 7.6e-16 x the size.

Measured native behaviour (pinned in tests/adapters/test_pymunk.py): touching
boxes (edge, corner, face) collide with distance 0; touching circles do not
(``distsq < mindist^2``); coincident equal boxes and zero-size boxes report a
contact with a zero normal (0, -0) and distance 0, even 2^-30 apart, and
coincident crossed boxes report distance 0 instead of their overlap;
coincident circles get normal (1, 0); ``Body(mass < 0, nan, inf)`` aborts the
interpreter (SIGABRT, caught by the harness worker; not guarded here), a body of mass 0
is refused at the first step (``AssertionError``: "Dynamic bodies must have a mass > 0",
space.py), so a zero mass is not read as a static body (declared ``zero_mass=""``); the
impulse accumulator is clamped at 0, so bodies already separating are left
alone; there is no restitution threshold (``bounce = vrn * e``); a grazing
approach (normal speed 2^-10 against tangential 2) is never seen overlapping at
a step, so it is not resolved at all (at dt = 1e-3 and 1/60); a disc of NaN radius
builds (with the infinite moment) and never collides: velocities kept, resolved_at None.

Conventions (each backed by a file in ``SOURCES``, Munk2D and pymunk sources):
box size full (``create_box``); normal from the first shape to the second,
A to B (``cpShapesCollide`` in cpShape.c); touching boxes collide (``d <= 0`` in
cpCollision.c), touching circles do not (strict ``<``); elasticity combines as
the product (cpArbiter.c); no restitution threshold; collision_slop 0.1,
collision_bias and 10 iterations by default (space.py); no contact raises
AssertionError (contact_point_set.py).  Time step: each variant's ``dt`` (1e-3, 1/60),
fixed, one ``Space.step(dt)`` per step; damping 0 (``Space.damping`` 1.0 keeps all velocity,
space.py).  Negative half-widths are read as their magnitude: ``create_box`` passes the
corners +-w/2 to ``Poly``, which builds their convex hull (shapes.py; measured here: a box
of half-width -1 answers as one of 1), declared ``negative_extents="absolute"``.  Negative
circle radii are not (measured here: the distance is |d| - ra - rb as given, and a
contact is reported when |d| < |ra + rb|, ``distsq < mindist^2`` in cpCollision.c); the
suite has no finite negative 2-D radius, and the notes say so.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import ClassVar

import numpy as np

from adapters.stepping import SceneCallsAdapter, scene_inputs
from crosscheck.core.contract import (
    Call,
    Capability,
    Conventions,
    all_capabilities,
    pair_inputs,
    response_inputs,
)
from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SceneCase, SphereCase

MUNK2D = "https://github.com/viblo/Munk2D/blob/master/src/"
PYMUNK = "https://github.com/viblo/pymunk/blob/master/pymunk/"
SOURCES = (
    MUNK2D + "cpShape.c",  # cpShapesCollide: normal flipped to a->b, distance = (p2 - p1).n
    MUNK2D + "cpCollision.c",  # CircleToCircle strict <, PolyToPoly d <= 0, ContactPoints
    MUNK2D + "cpArbiter.c",  # e = a->e * b->e; bounce = vrn * e; jnAcc = max(.., 0)
    MUNK2D + "cpSpaceStep.c",  # positions, collide + pre_solve, prestep, velocities, solver
    MUNK2D + "cpSpace.c",  # collisionSlop 0.1f, sleepTimeThreshold INFINITY (no sleeping)
    PYMUNK + "contact_point_set.py",  # assert count in (1, 2): no contact raises
    PYMUNK + "body.py",  # moment float('inf'): a body that cannot rotate
    PYMUNK + "shapes.py",  # create_box(size=(width, height), radius=0), shapes_collide
    PYMUNK + "space.py",  # collision_slop 0.1, collision_bias, iterations 10, on_collision
)
MAX_STEPS = 100_000
"""Step cap of a response query (bodies still approaching without touching)."""
MOMENT = math.inf
"""Every response body's moment: no rotation (see the module docstring), whatever the radius."""

_NOTES = ("Detection uses Shape.shapes_collide (independent of any Space: collision_slop "
          "does not apply, so no margin); no contact raises AssertionError and is reported "
          "as hit False with distance and normal absent.  Response: first step in which "
          "the solver handled the contact; resolved_at = centres in pre_solve; moment "
          "infinite (no rotation; independent of the radius).  Touching boxes collide, "
          "touching circles do not (textbook rule of each kind).  Mass 0 is refused "
          "(AssertionError at the first step), not static.  Negative half-widths read as "
          "their magnitude (create_box: convex hull of +-w/2); negative circle radii do "
          "not (distance |d| - ra - rb as given, contact when |d| < |ra + rb|; measured "
          "here).  ")

_WALL_NOTES = (
    " Gravity and walls (scenes): each wall a static Poly box on space.static_body, 1000 x "
    "the largest radius thick, 1e4 x the scene's extent sideways (adapters/shared/wall_boxes.py); "
    "a disc touching a Poly is a contact (d <= r, cpCollision.c CircleToPoly), so a disc "
    "resting on a wall stays at gap 0; touching discs are not (strict <), so a disc on a "
    "disc falls one step, |g| dt^2, first; overlaps within collision_slop are never "
    "corrected (the tuned variant's bias 1.0 corrects none).  No sleeping.")


def _conventions(settings: str, dt: float, slop: float) -> Conventions:
    return with_walls(Conventions(
        box_extents="full (Poly.create_box takes width and height; the adapter passes 2*half)",
        normal="A to B (ContactPointSet.normal points from the first shape to the second); "
               "used as is",
        rtol=2.0**-49,
        restitution="product of the shapes' elasticities; A = e, B = 1.0 gives e exactly",
        restitution_threshold=0.0,
        resolves_separating=False,
        time_step=dt,
        damping=0.0,
        zero_mass="",
        negative_extents="absolute",
        sampled_contacts=True,
        notes=_NOTES + settings + (
            " No continuous collision detection: each step moves the bodies, then looks for "
            "overlapping shapes (sampled_contacts); pymunk's Body.velocity_func docs suggest "
            "limiting velocity 'to prevent tunneling'." + _WALL_NOTES),
        sources=SOURCES,
    ), slop)


DEFAULT_SLOP = float(np.float32(0.1))
"""Munk2D's default collision_slop, ``0.1f`` (cpSpace.c), as a double: 0.10000000149011612."""
REST_SINK_STEPS = 1.0
"""A disc resting on a disc sinks one step's fall, ``|g| dt**2``, below the rest band: touching
circles are no contact (strict ``<``, cpCollision.c) and a step moves before it collides
(cpSpaceStep.c), so the upper disc falls for one step before the contact holds it."""
WALL_RESTITUTION = (
    "product of the shapes' elasticities (cpArbiter.c): a wall's Poly gets sqrt(e) like every "
    "disc, so a disc-wall contact bounces with e; the bounce is read from the approach "
    "velocity before the step's gravity (cpSpaceStep.c: prestep, then velocities), so an "
    "elastic drop keeps its apex; no threshold")


def with_walls(conventions: Conventions, slop: float) -> Conventions:
    """``conventions`` with a variant's gravity-and-walls fields (``slop``: its
    collision_slop): resting contacts held from ``-slop`` to touching, one step's sink,
    no sleeping (Munk2D's sleep_time_threshold is INFINITY unless set, cpSpace.c)."""
    return replace(conventions, rest_gap=(-slop if slop else 0.0, 0.0),
                   rest_sink_steps=REST_SINK_STEPS, rest_sink_s2=0.0, sleeps=False,
                   wall_restitution=WALL_RESTITUTION)


class PymunkTuned(SceneCallsAdapter):
    """pymunk set for accuracy: small step, no slop, no positional correction, no friction."""

    name: ClassVar[str] = "pymunk"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "pymunk"
    package: ClassVar[str] = "pymunk"
    settings: ClassVar[str] = ("dt 1e-3 s, collision_slop 0, collision_bias 1.0 (no positional "
                               "correction), iterations 10, friction 0, elasticity A = e, B = 1")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(
        *(k for k in Kind if k is not Kind.SPHERE_TOI), dims=(2,))
    slop: ClassVar[float | None] = 0.0
    conventions: ClassVar[Conventions] = _conventions(settings, 1e-3, 0.0)
    dt: ClassVar[float] = 1e-3
    bias: ClassVar[float | None] = 1.0
    iterations: ClassVar[int | None] = 10
    friction: ClassVar[float | None] = 0.0
    scene_tuned: ClassVar[bool] = True
    """Scenes get the variant's slop, bias and friction (False: pymunk's defaults)."""

    def version(self) -> str:
        import pymunk

        core = "Munk2D" if int(pymunk.version.split(".")[0]) >= 7 else "Chipmunk2D"  # 7: fork
        return f"{pymunk.version} ({core} {pymunk.chipmunk_version.partition('-')[0]})"

    def available(self) -> str | None:
        try:
            import pymunk  # noqa: F401
        except ImportError as exc:
            return str(exc)
        if not __debug__:
            return "pymunk signals 'no contact' with an assert, which python -O strips"
        return None

    calls: ClassVar[str] = "adapters.pymunk.calls"
    binding_objects: ClassVar[tuple[str, ...]] = ("_chipmunk*.so",)
    """The engine's shared objects for the instruction timer: pymunk's cffi module, Chipmunk2D
    compiled in.
    """

    def binding_call(self) -> Callable[[], object]:
        """``Shape.cache_bb()`` of one static circle: one call through pymunk's cffi binding."""
        import pymunk

        circle = pymunk.Circle(pymunk.Body(body_type=pymunk.Body.STATIC), 1.0)
        return circle.cache_bb

    def unsupported(self, case: AnyCase) -> str | None:
        if case.dim != 2:
            return f"pymunk is a 2-D engine: no {case.kind} in {case.dim}-D"
        return super().unsupported(case)

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        return Call("boxes" if isinstance(case, AabbCase) else "discs", "collide",
                    pair_inputs(case))

    def response_call(self, case: ResponseCase) -> Call:
        return Call("world", "respond", {
            **response_inputs(case), "dt": self.dt, "slop": self.slop, "bias": self.bias,
            "iterations": self.iterations,
            "friction": self.friction, "moment": MOMENT, "max_steps": MAX_STEPS},
            release="release_world")

    def scene_settings(self) -> dict[str, float | None]:
        """What the variant sets in a scene: its slop, bias and friction, or None for each
        (pymunk's defaults) when ``scene_tuned`` is False."""
        tuned = self.scene_tuned
        return {"slop": self.slop if tuned else None, "bias": self.bias if tuned else None,
                "friction": self.friction if tuned else None}

    def scene_call(self, case: SceneCase) -> Call:
        return Call("scene", "step_scene", {**scene_inputs(case), **self.scene_settings()},
                    release="release_scene")



class PymunkDefault(PymunkTuned):
    """pymunk out of the box: only geometry, mass, velocity and elasticity are set."""

    name: ClassVar[str] = "pymunk-default"
    settings: ClassVar[str] = ("dt 1/60 s; collision_slop (0.1f), collision_bias ((1-0.1f)^60), "
                               "iterations (10), friction (0) at defaults; elasticity A = e, B = 1")
    conventions: ClassVar[Conventions] = _conventions(settings, 1.0 / 60.0,
                                                      DEFAULT_SLOP)
    dt: ClassVar[float] = 1.0 / 60.0
    slop: ClassVar[float | None] = None
    bias: ClassVar[float | None] = None
    iterations: ClassVar[int | None] = None
    friction: ClassVar[float | None] = None
    scene_tuned: ClassVar[bool] = False
