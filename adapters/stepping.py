"""Running a ``sphere_scene`` case on an engine module (``pybullet_scene``, ``pymunk_scene``).

An adapter that steps scenes hands its scene module here, with its settings value for
that module (the module's ``Tuning``, or None for the engine's defaults), which
``prepare`` passes through: ``prepare`` builds the world (untimed), ``query`` steps
``round(duration / dt)`` times (the module times the stepping loop alone) and reports
the final state, momentum and kinetic energy with the wall time of the loop,
``release`` frees the world.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from types import ModuleType
from typing import Any

from crosscheck.core.model import Observation
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import scenes


@dataclass(frozen=True)
class PreparedScene:
    """A built scene: the engine module, its world, the step count and the masses."""

    module: ModuleType
    world: Any
    steps: int
    masses: tuple[float, ...]


def prepare(module: ModuleType, case: SceneCase, tuning: object) -> PreparedScene:
    """Build the scene's world in ``module`` (only its bodies: no ground, no gravity).

    ``tuning`` goes to ``module.prepare_scene`` as it is: the module's ``Tuning`` or None.
    """
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    world = module.prepare_scene(bodies, case.dim, case.restitution, case.dt or DEFAULT_DT,
                                 case.iterations, tuning)
    return PreparedScene(module, world, case.step_count, tuple(b.mass for b in case.bodies))


def query(p: PreparedScene) -> Observation:
    """Step the scene to its end and observe it (wall time of the loop in ``wall_s``)."""
    run = p.module.run_scene(p.world, p.steps)
    return replace(scenes.observation(run.positions, run.velocities, p.masses),
                   wall_s=run.wall_s)


def release(p: PreparedScene) -> None:
    """Free the scene's world."""
    p.module.release_scene(p.world)
