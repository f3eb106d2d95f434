"""pymunk 7.3.1 (Munk2D) stepping a 2-D scene of N discs, for comparison with an exact run.

What it is for: the scene runners step a whole scene (N discs, one restitution, in open
space or with gravity and static walls, :class:`adapters.scene.Surroundings`) with a fixed
``dt`` and return the final state, to be scored against the exact event-driven reference;
:mod:`adapters.pymunk` answers single pair cases instead.  Types and input checks are
shared with :mod:`adapters.pybullet_scene` in :mod:`adapters.scene`.  pymunk is 2-D: a 3-D
scene raises ``ValueError``.

Building (``prepare_scene``, untimed): a new ``pymunk.Space`` per scene with the scene's
gravity ((0, 0) in open space) and damping 1.0 (velocities kept), ``iterations`` if given
(else pymunk's 10); per disc a dynamic ``pymunk.Body(m, moment_for_circle(m, 0, r))`` at its
centre with its velocity and a ``pymunk.Circle(body, r)`` (radii are positive and finite
here, ``check_scene``; the pair adapter ``adapters.pymunk`` gives its response bodies an
infinite moment instead, as it must take radius 0 and NaN); per wall a ``pymunk.Poly`` box
(radius 0) on ``space.static_body`` (below); only the declared bodies and walls.
``run_scene`` times only ``space.step(dt)`` (``adapters.scene.step_and_record``, a
``functools.partial`` step: ~2 us for 0 steps) and reads ``Body.position`` /
``Body.velocity`` after it (and every ``record_every`` steps, untimed); ``release_scene``
empties the Space.

Variants (``tuning``, passed in by the adapter: a :class:`Tuning` or None): tuned
(``pymunk``, from ``PymunkTuned`` in ``adapters.pymunk``) passes collision_slop 0 and
collision_bias 1.0 (no positional correction) and friction 0 for every shape (pymunk's
default is 0 too); the adapter's dt and iterations do not apply (the scene gives them).
Default (``pymunk-default``) passes None and sets only what the scene declares: dt,
iterations if given, masses, elasticity; slop (0.1f) and bias stay.

Conventions, measured with this module (sources as cited in ``adapters.pymunk.SOURCES``):

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
  side and 1e4 x the scene's extent sideways (:mod:`adapters.wall_boxes`), its surface at
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
Measured outside the suite with this module: ``prepare_scene([((0, 0.1), 0.1, 1, (0, 0))], 2,
e, dt, None, tuning, Surroundings((0, -9.81), (Wall((0, 1), 0),)))`` (the drop: centre at
1.1, e 1), then ``run_scene(p, round(10 / dt), record_every=1)`` and its samples.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import partial
from typing import Any

import numpy as np

from adapters.scene import (
    Body,
    SceneRun,
    State,
    Surroundings,
    check_scene,
    check_surroundings,
    step_and_record,
)
from adapters.wall_boxes import Slab, slabs
from crosscheck.core.contract import Conventions

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

__all__ = ["Body", "SceneRun", "Tuning", "prepare_scene", "release_scene", "run_scene"]


@dataclass(frozen=True)
class Tuning:
    """Settings a variant adds to a scene; ``None`` instead of a Tuning: pymunk's defaults.

    ``slop`` and ``bias``: the Space's collision_slop and collision_bias; ``friction``: every
    shape's.  A field that is None is left at pymunk's default too.
    """

    slop: float | None
    bias: float | None
    friction: float | None


@dataclass(frozen=True, eq=False)
class Prepared:
    """A built scene: its Space, the step, the bodies and shapes in scene order, and the
    walls' shapes (on the Space's static body)."""

    space: Any
    dt: float
    bodies: tuple[Any, ...]
    shapes: tuple[Any, ...]
    walls: tuple[Any, ...] = ()


def make_space(iterations: int | None, tuning: Tuning | None,
               gravity: tuple[float, ...] = (0.0, 0.0)) -> Any:
    """A Space with ``gravity`` and no damping (1.0 keeps all velocity), set per variant."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (gravity[0], gravity[1])
    space.damping = 1.0
    if iterations is not None:
        space.iterations = iterations
    if tuning is not None and tuning.slop is not None:
        space.collision_slop = tuning.slop
    if tuning is not None and tuning.bias is not None:
        space.collision_bias = tuning.bias
    return space


def make_disc(body: Body, elasticity: float, tuning: Tuning | None) -> tuple[Any, Any]:
    """One disc of the scene: a dynamic body with its velocity, and its circle shape."""
    import pymunk

    center, radius, mass, velocity = body
    disc = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0.0, radius))
    disc.position = (center[0], center[1])
    disc.velocity = (velocity[0], velocity[1])
    shape = pymunk.Circle(disc, radius)
    shape.elasticity = elasticity
    if tuning is not None and tuning.friction is not None:
        shape.friction = tuning.friction
    return disc, shape


def make_wall(static_body: Any, slab: Slab, elasticity: float, tuning: Tuning | None) -> Any:
    """One wall: a ``Poly`` box (radius 0) on the Space's static body, its corners in world
    coordinates (the static body is at the origin), its surface at the wall's offset."""
    import pymunk

    (x0, y0), (x1, y1) = slab.corners()
    shape = pymunk.Poly(static_body, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)], radius=0.0)
    shape.elasticity = elasticity
    if tuning is not None and tuning.friction is not None:
        shape.friction = tuning.friction
    return shape


def prepare_scene(bodies: Sequence[Body], dim: int, restitution: float, dt: float,
                  iterations: int | None, tuning: Tuning | None,
                  surroundings: Surroundings | None = None) -> Any:
    """Build the scene in a new Space (untimed).  pymunk is 2-D: ``dim`` 3 raises.

    ``tuning``: the variant's settings (see :class:`Tuning`), or None for pymunk's defaults;
    ``surroundings``: gravity and walls, None for open space (gravity 0, no walls).
    """
    if dim != 2:
        raise ValueError(f"pymunk is a 2-D engine: no {dim}-D scenes")
    check_scene(bodies, dim, restitution, dt)  # before pymunk.Body: mass <= 0 aborts
    around = check_surroundings(surroundings, dim)
    space = make_space(iterations, tuning, around.gravity)
    elasticity = math.sqrt(restitution)  # the product of two shapes' is e
    discs = [make_disc(body, elasticity, tuning) for body in bodies]
    walls = tuple(make_wall(space.static_body, slab, elasticity, tuning)
                  for slab in slabs(bodies, around.walls))
    made = Prepared(space, dt, tuple(d for d, _ in discs), tuple(s for _, s in discs), walls)
    space.add(*made.bodies, *made.shapes, *walls)
    return made


def run_scene(prepared: Any, steps: int, clock: Callable[[], float] = time.perf_counter,
              record_every: int = 0) -> SceneRun:
    """Step the scene ``steps`` times (only the stepping is timed, read from ``clock`` just
    before and just after each run of steps) and read its final state; with ``record_every``
    > 0 also the state every that many steps (:func:`adapters.scene.step_and_record`)."""
    scene: Prepared = prepared

    def read() -> State:
        return ([(float(b.position.x), float(b.position.y)) for b in scene.bodies],
                [(float(b.velocity.x), float(b.velocity.y)) for b in scene.bodies])

    wall, samples = step_and_record(partial(scene.space.step, scene.dt), read, steps,
                                    record_every, clock)
    positions, velocities = read()
    return SceneRun(tuple(map(tuple, positions)), tuple(map(tuple, velocities)), wall, steps,
                    samples)


def with_walls(conventions: Conventions, slop: float) -> Conventions:
    """``conventions`` with a variant's gravity-and-walls fields (``slop``: its
    collision_slop): resting contacts held from ``-slop`` to touching, one step's sink,
    no sleeping (Munk2D's sleep_time_threshold is INFINITY unless set, cpSpace.c)."""
    return replace(conventions, rest_gap=(-slop if slop else 0.0, 0.0),
                   rest_sink_steps=REST_SINK_STEPS, rest_sink_s2=0.0, sleeps=False,
                   wall_restitution=WALL_RESTITUTION)


def release_scene(prepared: Any) -> None:
    """Remove the scene's bodies, shapes and walls from its Space."""
    scene: Prepared = prepared
    scene.space.remove(*scene.bodies, *scene.shapes, *scene.walls)
