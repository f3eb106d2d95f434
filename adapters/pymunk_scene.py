"""pymunk 7.3.1 (Munk2D) stepping a 2-D scene of N discs, for comparison with an exact run.

What it is for: the scene runners step a whole scene (N discs, one restitution, no gravity,
no ground) with a fixed ``dt`` and return the final state, to be scored against the exact
event-driven reference; :mod:`adapters.pymunk_engine` answers single pair cases instead.
Types and input checks are shared with :mod:`adapters.pybullet_scene` in
:mod:`adapters.scene`.  pymunk is 2-D: a 3-D scene raises ``ValueError``.

Building (``prepare_scene``, untimed): a new ``pymunk.Space`` per scene with gravity (0, 0)
and damping 1.0 (velocities kept), ``iterations`` if given (else pymunk's 10); per disc a
dynamic ``pymunk.Body(m, moment_for_circle(m, 0, r))`` at its centre with its velocity and a
``pymunk.Circle(body, r)`` (radii are positive and finite here, ``check_scene``; the pair
adapter ``pymunk_engine`` gives its response bodies an infinite moment instead, as it must
take radius 0 and NaN); only the declared bodies.
``run_scene`` times only ``space.step(dt)`` in a loop (~2 us for 0 steps) and reads
``Body.position`` / ``Body.velocity`` after it; ``release_scene`` empties the Space.

Variants (``tuning``, passed in by the adapter: a :class:`Tuning` or None): tuned
(``pymunk``, from ``PymunkTuned`` in ``pymunk_engine``) passes collision_slop 0 and
collision_bias 1.0 (no positional correction) and friction 0 for every shape (pymunk's
default is 0 too); the adapter's dt and iterations do not apply (the scene gives them).
Default (``pymunk-default``) passes None and sets only what the scene declares: dt,
iterations if given, masses, elasticity; slop (0.1f) and bias stay.

Conventions, measured with this module (sources as cited in ``pymunk_engine.SOURCES``):

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
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from adapters.scene import Body, SceneRun, check_scene, check_steps

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
    """A built scene: its Space, the step, and the bodies and shapes in scene order."""

    space: Any
    dt: float
    bodies: tuple[Any, ...]
    shapes: tuple[Any, ...]


def make_space(iterations: int | None, tuning: Tuning | None) -> Any:
    """A Space with no gravity and no damping (1.0 keeps all velocity), set per variant."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, 0.0)
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


def prepare_scene(bodies: Sequence[Body], dim: int, restitution: float, dt: float,
                  iterations: int | None, tuning: Tuning | None) -> Any:
    """Build the scene in a new Space (untimed).  pymunk is 2-D: ``dim`` 3 raises.

    ``tuning``: the variant's settings (see :class:`Tuning`), or None for pymunk's defaults.
    """
    if dim != 2:
        raise ValueError(f"pymunk is a 2-D engine: no {dim}-D scenes")
    check_scene(bodies, dim, restitution, dt)  # before pymunk.Body: mass <= 0 aborts
    space = make_space(iterations, tuning)
    discs = [make_disc(body, math.sqrt(restitution), tuning) for body in bodies]
    made = Prepared(space, dt, tuple(d for d, _ in discs), tuple(s for _, s in discs))
    space.add(*made.bodies, *made.shapes)
    return made


def run_scene(prepared: Any, steps: int,
              clock: Callable[[], float] = time.perf_counter) -> SceneRun:
    """Step the scene ``steps`` times (only this loop is timed, read from ``clock``
    just before and just after it) and read its final state."""
    scene: Prepared = prepared
    check_steps(steps)
    step, dt = scene.space.step, scene.dt
    start = clock()
    for _ in range(steps):
        step(dt)
    wall = clock() - start
    positions = tuple((float(b.position.x), float(b.position.y)) for b in scene.bodies)
    velocities = tuple((float(b.velocity.x), float(b.velocity.y)) for b in scene.bodies)
    return SceneRun(positions, velocities, wall, steps)


def release_scene(prepared: Any) -> None:
    """Remove the scene's bodies and shapes from its Space."""
    scene: Prepared = prepared
    scene.space.remove(*scene.bodies, *scene.shapes)
