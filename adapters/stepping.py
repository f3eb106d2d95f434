"""Running a ``sphere_scene`` case on an engine module (``pybullet_scene``, ``pymunk_scene``, ...).

An adapter that steps scenes hands its scene module here, with its settings value for
that module (the module's ``Tuning``, or None for the engine's defaults), which
``prepare`` passes through: ``prepare`` builds the world (untimed), with the scene's gravity
and walls when it has them (:class:`~adapters.scene.Surroundings`); ``query`` steps
``round(duration / dt)`` times (the module times the stepping loop alone), recording the
states every :func:`~crosscheck.truth.scene_measures.record_every` steps in such a scene, and
reports the final state, momentum, kinetic energy and the measures
(:mod:`crosscheck.truth.scene_measures`) with the wall time of the loop; ``release`` frees
the world.

:class:`SceneSteppingAdapter` is the base of the engines whose pairs are calls
(:class:`~crosscheck.core.contract.CallsAdapter`) and whose scenes are still a scene module
of this kind (until they are calls too): a scene goes here, every other kind to the calls.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from types import ModuleType
from typing import Any, ClassVar

from adapters.scene import Samples, Surroundings, Wall
from crosscheck.core.contract import CallsAdapter
from crosscheck.core.model import Observation, Trajectory
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import scene_measures, scenes


@dataclass(frozen=True)
class PreparedScene:
    """A built scene: the engine module, its world, the step count and the case."""

    module: ModuleType
    world: Any
    steps: int
    masses: tuple[float, ...]
    case: SceneCase


def surroundings(case: SceneCase) -> Surroundings | None:
    """The scene's gravity and walls for an engine module (None: open space)."""
    if not scene_measures.surrounded(case):
        return None
    return Surroundings(scene_measures.gravity(case),
                        tuple(Wall(tuple(w.normal), w.offset) for w in case.walls))


def prepare(module: ModuleType, case: SceneCase, tuning: object) -> PreparedScene:
    """Build the scene's world in ``module``: its bodies, and its gravity and walls if any.

    ``tuning`` goes to ``module.prepare_scene`` as it is: the module's ``Tuning`` or None.
    """
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    around = surroundings(case)
    extra = {} if around is None else {"surroundings": around}
    world = module.prepare_scene(bodies, case.dim, case.restitution, case.dt or DEFAULT_DT,
                                 case.iterations, tuning, **extra)
    return PreparedScene(module, world, case.step_count, tuple(b.mass for b in case.bodies),
                         case)


def trajectory(case: SceneCase, samples: Samples) -> Trajectory:
    """The recorded states as a :class:`~crosscheck.core.model.Trajectory` (times k dt)."""
    dt = case.dt or DEFAULT_DT
    steps = scene_measures.sample_steps(case)
    positions = tuple(tuple(tuple(map(float, p)) for p in frame) for frame in samples.positions)
    velocities = tuple(tuple(tuple(map(float, v)) for v in frame)
                       for frame in samples.velocities)
    return Trajectory(tuple(k * dt for k in steps[:len(positions)]), positions, velocities,
                      tuple(scene_measures.total_energy(case, p, v)
                            for p, v in zip(positions, velocities, strict=True)))


def query(p: PreparedScene) -> Observation:
    """Step the scene to its end and observe it (wall time of the loop in ``wall_s``)."""
    every = scene_measures.record_every(p.case)
    run = (p.module.run_scene(p.world, p.steps, record_every=every) if every
           else p.module.run_scene(p.world, p.steps))
    track = trajectory(p.case, run.samples) if run.samples is not None else None
    measures = scene_measures.engine_measures(p.case, run.positions, run.velocities, track)
    return replace(scenes.observation(run.positions, run.velocities, p.masses),
                   wall_s=run.wall_s, trajectory=track, **measures)  # type: ignore[arg-type]


def release(p: PreparedScene) -> None:
    """Free the scene's world."""
    p.module.release_scene(p.world)


class SceneSteppingAdapter(CallsAdapter):
    """A calls adapter whose scenes are stepped by ``scene_module`` with ``scene_tuning``."""

    scene_module: ClassVar[ModuleType]
    """The engine's scene module (``prepare_scene``, ``run_scene``, ``release_scene``)."""
    scene_tuning: ClassVar[Any] = None
    """What scenes are built with (the module's ``Tuning``); None: the engine's defaults."""

    def prepare(self, case: Any) -> Any:
        if isinstance(case, SceneCase):
            return prepare(self.scene_module, case, self.scene_tuning)
        return super().prepare(case)

    def query(self, prepared: Any) -> Observation:
        if isinstance(prepared, PreparedScene):
            return query(prepared)
        return super().query(prepared)

    def release(self, prepared: Any) -> None:
        if isinstance(prepared, PreparedScene):
            release(prepared)
            return
        super().release(prepared)
