"""A scene module's interface (``prepare_scene``, ``run_scene``, ``release_scene``) over an
engine's scene calls, so that the physical scene tests drive both alike.

:class:`SceneCalls` takes an adapter class whose scenes are calls (``scene``, ``step_scene``
and ``release_scene`` in its calls module, settings from ``scene_settings()``) and builds
with the given bodies, gravity and walls; ``run_scene`` steps the built scene a given number
of times and returns an :class:`adapters.scene.SceneRun` (samples as arrays).  Any other
name is the calls module's (``scene_state``, ``idle_scene_clients``, ...).
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from adapters.scene import Body, Samples, SceneRun, Surroundings


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

    def run_scene(self, built: Any, steps: int,
                  clock: Callable[[], float] = time.perf_counter,
                  record_every: int = 0) -> SceneRun:
        built["steps"], built["record_every"] = steps, record_every
        answer = self.calls.step_scene(built, clock)
        track = answer["trajectory"]
        samples = None if track is None else Samples(
            record_every, np.array(track[1], dtype=np.float64),
            np.array(track[2], dtype=np.float64))
        return SceneRun(answer["positions"], answer["velocities"], answer["wall_s"], steps,
                        samples)

    def release_scene(self, built: Any) -> None:
        self.calls.release_scene(built)
