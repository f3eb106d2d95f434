"""A scene module's interface (``prepare_scene``, ``run_scene``, ``release_scene``) over an
engine's scene calls, so that the physical scene tests drive both alike.

:class:`SceneCalls` takes an adapter class whose scenes are calls (``scene``, ``step_scene``
and ``release_scene`` in its calls module, settings from ``scene_settings()``) and builds
with the given bodies, gravity and walls; ``run_scene`` steps the built scene a given number
of times and returns a :class:`SceneRun` (samples as arrays).  Any other name is the calls
module's (``scene_state``, ``idle_scene_clients``, ...).  The tests' scene types are here too:
:data:`Body`, :class:`Surroundings` (gravity and :class:`~reference_impl.events.Wall` s),
:class:`Samples` and :class:`SceneRun`.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from reference_impl.events import Wall

__all__ = ["Body", "MujocoSceneCalls", "Samples", "SceneCalls", "SceneRun", "Surroundings", "Wall"]

Body = tuple[tuple[float, ...], float, float, tuple[float, ...]]
"""A sphere of a scene: (centre, radius, mass, velocity), vectors of the scene's dim."""


@dataclass(frozen=True)
class Surroundings:
    """A scene's uniform gravity and static walls; ``Surroundings.none(dim)`` is open space."""

    gravity: tuple[float, ...]
    walls: tuple[Wall, ...] = ()

    @classmethod
    def none(cls, dim: int) -> Surroundings:
        """Open space: no gravity, no walls."""
        return cls((0.0,) * dim, ())


@dataclass(frozen=True)
class Samples:
    """The recorded states, ``(samples, bodies, dim)`` arrays, every ``every`` steps."""

    every: int
    positions: np.ndarray = field(repr=False)
    velocities: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class SceneRun:
    """A stepped scene's final state, the wall time of its stepping, its steps and samples."""

    positions: tuple[tuple[float, ...], ...]
    velocities: tuple[tuple[float, ...], ...]
    wall_s: float
    steps: int
    samples: Samples | None = None


class SceneCalls:
    """An adapter's scene calls with a scene module's interface (see the module docstring)."""

    def __init__(self, adapter: Any) -> None:
        self.adapter = adapter
        self.calls = importlib.import_module(adapter.calls)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.calls, name)

    def settings(self) -> dict[str, Any]:
        """What the adapter passes to its scene calls besides the scene."""
        return dict(self.adapter.scene_settings())

    def prepare_scene(self, bodies: Sequence[Body], dim: int, restitution: float, dt: float,
                      iterations: int | None, settings: dict[str, Any],
                      surroundings: Surroundings | None = None) -> Any:
        around = surroundings or Surroundings.none(dim)
        return self.calls.scene(
            tuple(bodies), dim, restitution, dt, iterations, gravity=around.gravity,
            walls=tuple((w.normal, w.offset) for w in around.walls), steps=0,
            record_every=0, **settings)

    def run_scene(self, built: Any, steps: int, clock: Callable[[], float] | None = None,
                  record_every: int = 0) -> SceneRun:
        """Step ``steps`` times, recording every ``record_every`` steps; ``clock``: the
        time injected into the stepping (None: the calls' own)."""
        built["steps"], built["record_every"] = steps, record_every
        extra = {} if clock is None else {"clock": clock}
        answer = self.calls.step_scene(built, **extra)
        track = answer["trajectory"]
        samples = None if track is None else Samples(
            record_every, np.array(track[1], dtype=np.float64),
            np.array(track[2], dtype=np.float64))
        return SceneRun(answer["positions"], answer["velocities"], answer["wall_s"], steps,
                        samples)

    def release_scene(self, built: Any) -> None:
        self.calls.release_scene(built)


class MujocoSceneCalls(SceneCalls):
    """MuJoCo's scene calls: the settings are a ``Tuning`` (or None), the model is the
    scene's MJCF (:func:`adapters.mujoco.scene.scene_model`)."""

    def prepare_scene(self, bodies: Sequence[Body], dim: int, restitution: float, dt: float,
                      iterations: int | None, settings: Any,
                      surroundings: Surroundings | None = None) -> Any:
        from adapters.mujoco.scene import scene_model, scene_settings

        around = surroundings or Surroundings.none(dim)
        walls = tuple((w.normal, w.offset) for w in around.walls)
        return self.calls.scene(
            scene_model(bodies, walls, settings), tuple(bodies), dim, restitution, dt,
            iterations, gravity=around.gravity, walls=walls, steps=0, record_every=0,
            **scene_settings(surroundings is not None, restitution, dt, settings))

    def release_scene(self, built: Any) -> None:
        """Nothing to free: the model and data go with the last reference to them."""
