"""Rapier (rapier3d 0.36.1) stepping a scene of N spheres, for comparison with an exact run.

What it is for: the scene runners step a whole scene (N spheres, one restitution, in open
space or under gravity between static walls) with a fixed ``dt`` and return the final state
(and, if asked, the states every k steps), to be scored against the exact event-driven
reference; :mod:`adapters.rapier` answers single pair cases.  Types and input checks
are shared with the other scene runners in :mod:`adapters.scene`.

Building (``prepare_scene``, untimed): a new ``PhysicsWorld`` per scene (gravity 0;
:func:`adapters.shared.rapier.new_world`) with the scene's ``dt`` and, if given,
``num_solver_iterations`` (else rapier's 4); one dynamic body per sphere at its centre with
its velocity (``in_plane``: a 2-D scene lies in z = 0 with z translation locked, as the
responses do: a 3-D build in the plane, 2-D walls are half-spaces with a normal in it)
carrying ``Collider.ball(r).mass(m)`` with restitution e; then the ``surroundings``' gravity
and walls (:mod:`adapters.rapier_walls`: one fixed body with a ``HalfSpace`` collider per
wall, the variant's material with restitution e; open space adds nothing, so its worlds are
unchanged).  The builders are the response adapter's (:mod:`adapters.shared.rapier`).
Numbers float32 cannot hold raise ``OverflowError`` (rapier would read them as infinite).
``run_scene`` times only ``PhysicsWorld.step`` (:func:`adapters.scene.step_and_record`,
reading ``translation`` / ``linvel`` untimed between runs of steps) and raises if rapier
quarantined a non-finite body; ``release_scene`` empties the world.  Resting contact,
sleeping and bounces on walls, with what was measured: :mod:`adapters.rapier_walls`.

Variants (``tuning``, passed in by the adapter: a :class:`Tuning` or None): tuned
(``rapier``) passes the pair adapter's ``IntegrationParameters`` (normalized prediction
distance 0, no speed cap: ``normalized_max_linear_velocity`` f32::MAX; its dt replaced by the
scene's) and gets its bodies (no sleeping, ``soft_ccd_prediction`` 1e30, rotations locked,
damping 0) and colliders (friction 0), restitution e on every collider combined by Max.
Default (``rapier-default``) passes None and sets only what the scene declares: dt,
iterations if given, masses, radii, velocities and restitution e on every collider (combined
by rapier's default Average); prediction distance 0.02, friction 0.5, free rotation,
sleeping and the speed cap 400 stay.

Conventions, measured with this module on rapier3d 0.36.1 (sources as cited in
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
  True (False tuned), sources in :mod:`adapters.rapier_walls`.
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
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from adapters.rapier_walls import add_surroundings
from adapters.rapier_walls import check_f32 as check_f32_surroundings
from adapters.scene import (
    Body,
    SceneRun,
    State,
    Surroundings,
    check_scene,
    check_surroundings,
    in_scene_dim,
    step_and_record,
)
from adapters.shared.rapier import (
    default_body,
    default_collider,
    in_plane,
    new_world,
    tuned_body,
    tuned_collider,
)
from crosscheck.core.geometry import to3

__all__ = ["Body", "SceneRun", "Tuning", "prepare_scene", "release_scene", "run_scene"]

F32_MAX = 3.4028234663852886e38
"""The largest finite float32 (rapier's ``Real``): a scene's numbers must fit in it."""


@dataclass(frozen=True)
class Tuning:
    """Settings a variant adds to a scene; ``None`` instead of a Tuning: rapier's defaults.

    ``parameters``: ``IntegrationParameters`` overrides (a ``dt`` among them is replaced by
    the scene's); with a Tuning every body and collider is the tuned variant's
    (:func:`adapters.shared.rapier.tuned_body`, ``tuned_collider`` with restitution e on
    every collider, combined by ``rule``); ``ccd``: every body also ``ccd_enabled``.
    """

    parameters: tuple[tuple[str, float], ...]
    rule: str = "MAX"
    ccd: bool = False
    """Every body ``ccd_enabled`` (``RigidBodyBuilder.ccd_enabled(True)``), the
    ``rapier-ccd`` variant's switch."""


@dataclass(frozen=True, eq=False)
class Prepared:
    """A built scene: its world, the body handles (scene order) and the dimension."""

    world: Any
    dim: int
    handles: tuple[Any, ...]


def parameters(dt: float, iterations: int | None,
               tuning: Tuning | None) -> tuple[tuple[str, float], ...]:
    """The ``IntegrationParameters`` a scene's world gets: the variant's, then dt and iterations.

    >>> parameters(1e-3, None, None)
    (('dt', 0.001),)
    >>> parameters(1e-3, 4, Tuning((("dt", 0.5), ("normalized_prediction_distance", 0.0))))
    (('normalized_prediction_distance', 0.0), ('dt', 0.001), ('num_solver_iterations', 4))
    """
    settings = [(k, v) for k, v in (tuning.parameters if tuning is not None else ()) if k != "dt"]
    settings.append(("dt", dt))
    if iterations is not None:
        settings.append(("num_solver_iterations", iterations))
    return tuple(settings)


def check_f32(bodies: Sequence[Body], restitution: float) -> None:
    """Raise ``OverflowError`` for a number float32 cannot hold (rapier would read it as inf)."""
    for i, (center, radius, mass, velocity) in enumerate(bodies):
        for x in (*center, radius, mass, *velocity):
            if abs(x) > F32_MAX:
                raise OverflowError(f"body {i}: {x!r} is beyond float32's largest finite value")
    if restitution > F32_MAX:
        raise OverflowError(f"restitution {restitution!r} is beyond float32's range")


def add_sphere(world: Any, body: Body, dim: int, restitution: float,
               tuning: Tuning | None) -> Any:
    """One sphere of the scene (restitution e on its collider); its handle in ``world``."""
    center, radius, mass, velocity = body
    if tuning is None:
        builder = default_body(to3(center), to3(velocity))
        collider = default_collider(radius, mass, restitution)
    else:
        builder = tuned_body(to3(center), to3(velocity))
        if tuning.ccd:
            builder = builder.ccd_enabled(True)
        collider = tuned_collider(radius, mass, restitution, tuning.rule)
    return world.add_body(in_plane(builder, dim), [collider])


def prepare_scene(bodies: Sequence[Body], dim: int, restitution: float, dt: float,
                  iterations: int | None, tuning: Tuning | None,
                  surroundings: Surroundings | None = None) -> Any:
    """Build the scene in a new ``PhysicsWorld`` (untimed).

    ``tuning``: the variant's settings (see :class:`Tuning`), or None for rapier's defaults;
    ``surroundings``: gravity and walls (:mod:`adapters.rapier_walls`), None for open space.
    """
    check_scene(bodies, dim, restitution, dt)
    around = check_surroundings(surroundings, dim)
    check_f32(bodies, restitution)
    check_f32_surroundings(around, F32_MAX)
    if iterations is not None and iterations < 1:
        raise ValueError(f"iterations must be >= 1, got {iterations}")
    world = new_world(parameters(dt, iterations, tuning))
    handles = tuple(add_sphere(world, body, dim, restitution, tuning) for body in bodies)
    add_surroundings(world, around, restitution, tuning is not None,
                     tuning.rule if tuning is not None else "AVERAGE")
    return Prepared(world, dim, handles)


def run_scene(prepared: Any, steps: int, clock: Callable[[], float] = time.perf_counter,
              record_every: int = 0) -> SceneRun:
    """Step the scene ``steps`` times (only the stepping is timed, read from ``clock`` just
    before and just after each run of steps) and read its final state; with ``record_every``
    > 0 also the state every that many steps (:func:`adapters.scene.step_and_record`)."""
    scene: Prepared = prepared
    world = scene.world

    def read() -> State:
        if not world.quarantine.is_empty():
            raise FloatingPointError(f"rapier quarantined a body whose state became "
                                     f"non-finite ({world.quarantine})")
        bodies = [world.rigid_bodies[h] for h in scene.handles]
        return (in_scene_dim(scene.dim, (b.translation.to_tuple() for b in bodies), "position"),
                in_scene_dim(scene.dim, (b.linvel.to_tuple() for b in bodies), "velocity"))

    wall, samples = step_and_record(world.step, read, steps, record_every, clock)
    positions, velocities = read()
    return SceneRun(tuple(map(tuple, positions)), tuple(map(tuple, velocities)), wall, steps,
                    samples)


def release_scene(prepared: Any) -> None:
    """Empty the scene's world (``PhysicsWorld.clear``: its bodies and colliders go)."""
    scene: Prepared = prepared
    scene.world.clear()

