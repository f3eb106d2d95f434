"""Scenes as calls, the adapter side: a ``sphere_scene`` case's inputs and its answer read back.

Every stepping engine's scenes are calls of its calls module (``adapters/<engine>/calls.py``:
``scene`` builds the world, ``step_scene`` steps it and answers, ``release_scene`` frees it;
the stepping, recording and answer are :mod:`adapters.shared.scene`, the measures
:mod:`reference_impl.scene_measures`, both plain, so a repro script holds them as source).
An engine's ``scene_call`` passes :func:`scene_inputs` and its variant's settings;
:class:`SceneCallsAdapter` reads the answer (:func:`scene_observation`): the final state,
momentum, kinetic energy and the measures, with the recorded trajectory (states every
:func:`~crosscheck.truth.scene_measures.record_every` steps in a scene with gravity or walls)
and the wall time of the stepping loop alone.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from crosscheck.core.contract import Answer, CallsAdapter, observation_of
from crosscheck.core.model import Observation, Trajectory
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import scene_measures


def scene_inputs(case: SceneCase) -> dict[str, Any]:
    """A scene's inputs for an engine's scene call: the bodies ``(centre, radius, mass,
    velocity)``, dim, restitution, dt, iterations, gravity, walls ``(normal, offset)``, the
    step count and the recording stride (0: none, open space)."""
    return {"bodies": tuple((tuple(b.center), b.radius, b.mass, tuple(b.velocity))
                            for b in case.bodies),
            "dim": case.dim, "restitution": case.restitution, "dt": case.dt or DEFAULT_DT,
            "iterations": case.iterations, "gravity": tuple(scene_measures.gravity(case)),
            "walls": tuple((tuple(w.normal), w.offset) for w in case.walls),
            "steps": case.step_count, "record_every": scene_measures.record_every(case)}


def scene_observation(answer: Answer) -> Observation:
    """An observation of a scene call's answer (its ``trajectory`` and ``wall_s`` too); any
    other answer as :func:`~crosscheck.core.contract.observation_of` reads it."""
    if "wall_s" not in answer:
        return observation_of(answer)
    rest = {q: v for q, v in answer.items() if q not in ("trajectory", "wall_s")}
    track = answer["trajectory"]
    return replace(observation_of(rest), wall_s=answer["wall_s"],
                   trajectory=None if track is None else Trajectory(*track))


class SceneCallsAdapter(CallsAdapter):
    """A calls adapter whose scene call answers as :func:`scene_observation` reads."""

    def observation(self, answer: Answer) -> Observation:
        return scene_observation(answer)
