"""Box2D 2.3.0 (pybox2d 2.3.10) stepping a 2-D scene of N discs: the variants' settings, measured.

What it is for: a scene (N discs, one restitution, in open space or with gravity and static
walls) is stepped with a fixed ``dt`` by the scene calls of :mod:`adapters.box2d.calls`
(``scene``, ``step_scene``, ``release_scene``; worlds and discs built as responses are, by
:mod:`adapters.box2d.calls`).  Here: what a variant sets (:class:`Variant`), its inputs to
the scene calls (:func:`scene_settings`), its gravity-and-walls conventions
(:func:`with_walls`) and what was measured with those calls.  Box2D is 2-D: a 3-D scene
raises ``ValueError``.

Building (``scene``, untimed): a new ``b2World`` per scene (the scene's gravity, 0 in
open space; sleeping as the variant says, with ``SetAllowSleeping``); per wall a static body
with a box fixture (below); per disc a dynamic body at its centre with its
velocity and one circle fixture of restitution e, its mass set exactly through ``massData``
(``disc``); only the declared bodies and walls.  ``step_scene`` times only ``world.Step(dt,
velocity_iterations, position_iterations)`` in a loop (``adapters.shared.scene.step_and_record``, a
``functools.partial`` step) and reads ``body.position`` / ``body.linearVelocity`` after it
(and every ``record_every`` steps, untimed; float32 values, widened); ``release_scene`` destroys the
bodies.  Velocity iterations: the scene's ``iterations`` if given, else the variant's 8;
position iterations 3 (``Step`` has no defaults: the pybox2d testbed's values).

Variants (``tuning``, passed in by the adapter: a :class:`Variant` or None): tuned
(``box2d``) passes the pair adapter's variant (its dt replaced by the scene's): friction 0,
``fixedRotation``, sleeping off.  Default (``box2d-default``) passes None: friction (0.2),
rotation free with the disc's moment, sleeping allowed; only dt, masses, radii, velocities,
restitution and iterations come from the scene.  Neither sets damping (Box2D's default is
0) nor bullets: Box2D 2.3.0's continuous collision (``b2World::SolveTOI``) acts on a contact
only when one of its bodies is static, kinematic or a bullet (``collideA = bA->IsBullet() ||
typeA != b2_dynamicBody``, b2World.cpp), so between two dynamic discs contacts are found at
step starts only.  Bullets (``box2d-bullet``, :mod:`adapters.box2d`) passes the tuned
variant with ``bullet`` True: every disc is a bullet (``b2BodyDef.bullet``), and a contact
between two of them gets a time of impact, a sub-step to it and a velocity solve with
restitution.  Compiled-in constants no variant can change: ``b2_velocityThreshold`` (1 m/s),
``b2_maxTranslation`` (2 m a step), ``b2_linearSlop`` (0.005 m) and the position solver.

Conventions, measured with the scene calls (sources as cited in ``adapters.box2d.SOURCES``):

- restitution: Box2D mixes the fixtures' restitutions by ``max`` [b2Contact.h]; every
  fixture gets e, so every pair gets e.  Measured: masses 1 and 2 head-on at 1 and -1 with e
  = 0.5 end at exactly -1 and 0 (the textbook's) in both variants.
- threshold: an approach at a relative normal speed of at most ``b2_velocityThreshold`` (1
  m/s, compiled in) is perfectly inelastic [b2ContactSolver.cpp].  Measured: two discs
  approaching at a relative speed of exactly 1 stop dead (both 0), one float32 unit faster
  (1 + 2^-23) they bounce; the tuned variant cannot lower it, so slow impacts are inelastic
  in both variants (the cradle below, and random scenes: one of three 16-disc scenes lost
  0.5% of its energy).
- speed cap: a body moving more than ``b2_maxTranslation`` (2 m) in a step has its velocity
  scaled down to 2 / dt [b2Island.cpp].  Measured: a free disc at 30 m/s with dt 0.1 moves 2
  m and leaves the step at 20 m/s; at 19 m/s it is untouched; a free disc at 1000 m/s moves
  exactly 2 m in its first step and leaves it at 120 (float32 119.99999) at dt 1/60, at 480
  at dt 1/240, untouched at dt 1e-3 (2000): the cap is 2 / dt of the scene's dt, and it acts
  before the step's positions are integrated, so a scene starting above it moves as if it
  started at the cap.  Bullets, two discs r = 0.05, e = 1, head-on at +-v from 0.6 apart:
  at dt 1/60 v = 200 and 1000 end at -120 and 120 (capped, then exchanged), at 1/240 v =
  1000 at -480 and 480.
- fast bodies (same pair): without bullets they pass through each other at dt 1/240 from
  v = 50 (step travel |vb - va| dt / 2(ra + rb) = 2.08; 20, travel 0.83, is caught) and at
  1/60 from v = 20 (travel 3.3; 5 is caught), tuned and default alike; with bullets every v
  measured (5 to 1000, both dt) exchanges the velocities, capped as above.
- sleeping: off in the tuned variant; in the default one a body slower than 0.01 m/s for 0.5
  s sleeps with its velocity zeroed (measured: a disc at rest in a default scene was still
  awake after 1 s and, hit at 2, took the striker's velocity exactly).
- soft contact / margins: contacts are found at the start of a step (the narrow phase at the
  positions the step starts from), solved as velocity constraints, then positions are
  integrated and a position solver pushes overlaps deeper than ``b2_linearSlop`` apart (up
  to ``b2_maxLinearCorrection`` a step) by moving positions only.  Touching at the start
  (distance exactly 0) is a contact (``distSqr > radius * radius`` is the only reject,
  b2CollideCircle.cpp): two touching discs, one moving at 2 into the other, exchange
  velocities in step 1 (0 and 2 exactly); touching discs moving together at 0.3 get no
  impulse (100 steps, velocities kept).
- simultaneous contacts: the solver handles every touching contact of a step together by
  sequential impulses, so a chain of touching discs is neither the textbook cradle nor a
  rigid block unless the iterations converge.  5-disc cradle (equal masses, e = 1): at speed
  1 (exactly the threshold) every contact is inelastic and all five end near 0.2 (with 50
  velocity iterations exactly 0.2: one block); at speed 2 with 50 iterations the striker
  ends at -1.2 and the four at 0.8 (an elastic hit on a mass-4 block), with 8 iterations
  near it (energy 5% low), with 1 iteration the last disc leaves at 3 and the energy more
  than doubles.  Momentum is kept in all of them.
- energy at e = 1: a head-on pair exchanges its velocities exactly (1 and -1, momentum and
  energy exact, at dt 1e-3, 1/60 and 0.1, both variants); 16 random discs over 3 s at dt
  1e-3 keep momentum to float32 rounding (2e-8 of sum m|v|) and, tuned, energy to 4e-8
  unless a slow impact falls under the threshold; the default variant loses 4% to 6% there
  (friction 0.2 on oblique contacts, rotation free, and the threshold).
- float32 throughout: positions and velocities are float32.  Measured: a free disc at 1 m/s
  for 1000 steps of 1e-3 ends at 0.99999070 (float32 sums of dt v), so position errors of
  Box2D are of float32 size or more, far above the float64 tolerance the scenes are scored
  with.

Gravity and walls (``surroundings``; declared per variant by :func:`with_walls`):

- a wall is what Box2D's users build for a ground (the manual's "Hello Box2D": a static body
  with a ``SetAsBox`` polygon): a static body with one box fixture (``_wall`` of the calls),
  1000 x the largest radius thick on the solid side and 1e4 x the scene's extent sideways
  (:mod:`adapters.shared.wall_boxes`).  Float32: the body sits on the wall's surface sideways at the
  scene's centre and the box is ``SetAsBox(hx, hy, centre, 0)`` in its frame, so the face a
  disc touches is at exactly 0 there and the face's separation (``b2Dot(normal, cLocal -
  v)`` with an axis normal, b2CollideCircle.cpp) does not involve the box's size; a box
  centred elsewhere would put its surface at a float32 sum.  An edge (``b2EdgeShape``) would
  do too but is two-sided: a disc pushed past it is pushed out below.  Static bodies never
  collide with each other, and Box2D's time of impact sweeps every dynamic body against
  static ones in every variant (``SolveTOI``: a static body is ``collideB``, b2World.cpp),
  so discs do not tunnel through walls.
- margins: the variant's polygon radius applies to the walls: none in ``box2d`` and
  ``box2d-bullet``, ``b2_polygonRadius`` (2 ``b2_linearSlop`` = 0.01) in ``box2d-default``;
  a contact is made at separation <= the radii (``s > radius`` rejects, b2CollideCircle.cpp)
  and the position solver pushes only overlaps deeper than ``b2_linearSlop`` (0.005) back,
  by ``b2_baumgarte`` (0.2) of the excess per iteration (b2ContactSolver.cpp).  A disc
  rests at a gap from -0.005 to 0 on a disc or a skinless wall and from 0.005 to 0.01 on a
  skinned one: ``rest_gap`` (-0.005f, 0) tuned, (-0.005f, 0.01f) default.  Measured
  (one disc r 0.1 placed on the ground, 10 s): tuned gap 1.5e-9 (float32(0.1) - 0.1), speed
  exactly 0, at dt 1e-3, 1/240 and 1/60; default 0.0050000 at 1/240, 0.0049938 at 1/60 (the
  disc falls asleep after ``b2_timeToSleep`` = 30 steps, before the position solver has
  lifted it all the way: 0.005 x 0.8^30 short).
- sink: the step adds gravity to the velocities before the velocity constraints
  (b2Island.cpp), which cancel it as far as the sequential impulses converge: one disc on
  the ground sinks nothing (above); a column sinks until the position solver balances it,
  declared at most one step's fall, ``|g| dt**2``, below the band (``REST_SINK_STEPS``).
  The bound is per contact: in a tall column the sequential impulses leave more.
  Measured, columns of n discs (r 0.1) set touching on the ground for 5 s, any e (slow
  impacts are inelastic below the threshold), deepest gap during the run / at the end in
  units of ``|g| dt**2`` below the band's -0.005: tuned at dt 1/60, n 3 and 5 within the
  band, n 10 0.68 / within, n 20 9.7 / 0.97; at 1/240 (where the band is 29 ``|g| dt**2``
  deep) within it up to n 20.  Default (asleep at the end, speed exactly 0), at 1/60: n 2
  and 3 0.5 / 0.1, n 5 0.6 / 0.1, n 10 1.3 / 0.1, n 20 9.7 to 16.9 / 0.8 to 1.3 (by e);
  at 1/240: n 5 0.5 / within, n 10 1.0 / within, n 20 2.3 / within.
- sleeping: as the variant says: off in ``box2d`` and ``box2d-bullet``, on in
  ``box2d-default`` (a body slower than 0.01 m/s for 0.5 s sleeps with its velocity zeroed:
  measured, the resting disc and the column end with speed exactly 0).
- restitution with walls: a wall's fixture gets e like the discs (``max``, so e); the 1 m/s
  threshold applies.  The approach speed is read after the step's gravity is added
  (``vRel`` in ``InitializeVelocityConstraints`` from the integrated velocities,
  b2Island.cpp, b2ContactSolver.cpp), so a bounce leaves about ``|g| dt`` faster than it
  arrived: measured, a disc dropped from 1 m (e 1, 10 s, 11 bounces) has apexes growing from
  1.0044 to 1.045 m at dt 1e-3 (1 + 2 |g| dt / 4.43 m/s = 1.0044 a bounce), 1.0186 to
  1.1933 m at 1/240, both variants; at 1/60 they alternate between about 1.000 and 0.966
  (tuned) or 0.986 (default).  A disc at 3 m/s between two walls in zero gravity kept
  exactly 3 over 10 s (17 bounces), every variant.
- friction of a wall: the variant's for the discs (tuned 0; default ``b2FixtureDef``'s 0.2),
  mixed as ``sqrt(fA fB)`` (b2MixFriction).
Measured outside the suite with the scene calls (the drop: a disc of radius 0.1 at 1.1 above
the ground, e 1, 10 s, every step recorded).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from crosscheck.core.contract import Conventions

LINEAR_SLOP = float(np.float32(0.005))
"""``b2_linearSlop`` (0.005f, b2Settings.h): overlap the position solver leaves."""
POLYGON_RADIUS = float(np.float32(0.01))
"""``b2_polygonRadius`` (2 b2_linearSlop, b2Settings.h): the default variant's wall skin."""
REST_SINK_STEPS = 1.0
"""How far below the rest band a resting disc may sink, in ``|g| dt**2``: one step's gravity
not cancelled by unconverged velocity iterations (a column), before the position solver."""
WALL_RESTITUTION = (
    "max of the fixtures' restitutions (b2MixRestitution, b2Contact.h): a wall's fixture gets "
    "e like every disc, so a disc-wall contact bounces with e above b2_velocityThreshold (1 "
    "m/s; slower approaches are inelastic); the approach speed is read after the step's "
    "gravity (b2Island.cpp), so a bounce leaves up to |g| dt faster than it arrived")

@dataclass(frozen=True, slots=True)
class Variant:
    """What a variant sets (None: Box2D's default)."""

    polygon_radius: float | None
    use_radii: bool
    dt: float
    friction: float | None
    fixed_rotation: bool
    sleep: bool
    velocity_iterations: int = 8
    position_iterations: int = 3
    bullet: bool = False
    """Every disc a bullet (``b2BodyDef.bullet``): Box2D's continuous collision (time of
    impact) then acts between it and other dynamic bodies too, not only static ones."""


DEFAULTS = Variant(polygon_radius=None, use_radii=True, dt=0.0, friction=None,
                   fixed_rotation=False, sleep=True)
"""What a scene of the default variant is built with: Box2D's defaults (dt: the scene's)."""


def scene_settings(tuning: Variant | None) -> dict[str, Any]:
    """A variant's inputs to the scene calls besides the scene (None: Box2D's defaults, as
    :data:`DEFAULTS`); a scene's ``iterations``, if given, replace the velocity iterations.

    >>> s = scene_settings(None)
    >>> s["velocity_iterations"], s["position_iterations"], s["sleep"], s["friction"]
    (8, 3, True, None)
    """
    v = DEFAULTS if tuning is None else tuning
    return {"polygon_radius": v.polygon_radius, "friction": v.friction,
            "fixed_rotation": v.fixed_rotation, "sleep": v.sleep,
            "velocity_iterations": v.velocity_iterations,
            "position_iterations": v.position_iterations, "bullet": v.bullet}


def with_walls(conventions: Conventions, variant: Variant) -> Conventions:
    """``conventions`` with the gravity-and-walls fields of ``variant``: resting contacts held
    from -b2_linearSlop to touching on discs and skinless walls, up to the skin on skinned
    ones (polygon radius None: ``b2_polygonRadius``), one step's sink, sleeping as set."""
    skin = POLYGON_RADIUS if variant.polygon_radius is None else variant.polygon_radius
    return replace(conventions, rest_gap=(-LINEAR_SLOP, skin), rest_sink_steps=REST_SINK_STEPS,
                   rest_sink_s2=0.0, sleeps=variant.sleep, wall_restitution=WALL_RESTITUTION)
