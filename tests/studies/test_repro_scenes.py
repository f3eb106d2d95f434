"""Repro scripts of scenes with gravity and walls: they print the adapter's measures.

A scene's script holds the engine's scene call (its calls module's source), which rebuilds
the gravity and walls with the engine alone, records the states as the adapter does and
computes the measures with the harness's own functions, held as source
(:mod:`reference_impl.scene_measures`).  Here each script runs in a fresh process and its
printed values are compared with the adapter's own observation of the same case (the
engine's output against the engine's output: no value is written down), and the harness's
measures (:mod:`crosscheck.truth.scene_measures`) with the plain functions a script holds,
on hand-made trajectories.
"""

from __future__ import annotations

import json
import random
import subprocess
import sys
from functools import cache
from pathlib import Path
from typing import Any

import pytest

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.core.model import Trajectory, Undefined
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.core.values import encode
from crosscheck.studies.repro.script import MEASURED, engine_part, printed, script_text
from crosscheck.truth import scene_measures
from reference_impl import scene_measures as plain
from tests.conftest import ROOT

DROP, REST = "drop-2d-elastic.dt=0.0166667", "rest-3d-sphere.dt=0.0166667"
DIVERGENCE = {"quantity": "divergence", "value": "0.25", "truth": "10.0", "status": "disagree",
              "category": "error", "error": 0.975, "tolerance": 0.5, "reason": "left early",
              "kind": "sphere_scene", "nondeterministic": False, "repeat_value": None,
              "repeat_status": ""}
"""A run's row of divergence (made up: the script only shows it)."""


@cache
def gravity_case(case_id: str) -> SceneCase:
    """A case of ``cases/gravity.toml``, expanded."""
    loaded = load_paths([ROOT / "cases" / "gravity.toml"])
    case = next(c for c in loaded.cases if c.id == case_id)
    assert isinstance(case, SceneCase)
    return case


def scene(**over: Any) -> SceneCase:
    """A small 2-D scene: a disc at 3 m/s between two walls 1.8 apart, no gravity, 2 s."""
    fields = {"id": "between-walls", "description": "d", "kind": "sphere_scene", "dim": 2,
              "duration": 2.0, "dt": 1.0 / 60.0, "restitution": 1.0,
              "walls": [{"normal": [1.0, 0.0], "offset": -0.9},
                        {"normal": [-1.0, 0.0], "offset": -0.9}],
              "bodies": [{"center": [0.0, 0.0], "radius": 0.1, "mass": 1.0,
                          "velocity": [3.0, 0.0]}], **over}
    case = CASE_ADAPTER.validate_python(fields)
    assert isinstance(case, SceneCase)
    return case


def run_script(name: str, case: SceneCase, tmp_path: Path,
               rows: list[dict[str, object]] | None = None) -> str:
    """The script of ``case`` on engine ``name``, run in a fresh process: its stdout."""
    adapter = adapters.get(name)
    info = {"name": adapter.name, "engine": adapter.engine, "settings": adapter.settings}
    text = script_text(case, engine_part(adapter, case), info, rows or [], [], "test")
    path = tmp_path / "repro.py"
    path.write_text(text, encoding="utf-8")
    done = subprocess.run([sys.executable, str(path)], capture_output=True, text=True,
                          timeout=120, check=False, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def values(out: str, case: SceneCase) -> dict[str, object]:
    """The script's ``<quantity> = <JSON>`` lines, decoded."""
    found: dict[str, object] = {}
    for line in out.splitlines():
        name, sep, text = line.partition(" = ")
        if sep and name in printed(case):
            assert name not in found, f"{name} printed twice"
            found[name] = json.loads(text)
    return found


def observed(name: str, case: SceneCase) -> dict[str, object]:
    """The adapter's observation of ``case`` as the script prints it (JSON, null: none)."""
    seen = adapters.get(name).observe(case)
    return {q: json.loads(encode(seen.get(q))) for q in printed(case)}


@pytest.mark.engine
@pytest.mark.parametrize(("name", "case_id"), [
    ("pymunk", DROP), ("box2d", DROP), ("pybullet", REST), ("mujoco", REST), ("rapier", REST),
    ("pymunk-default", DROP), ("box2d-default", DROP), ("pybullet", DROP), ("mujoco", DROP),
    ("rapier-default", DROP)])
def test_a_gravity_scene_prints_the_adapters_measures(name: str, case_id: str,
                                                      tmp_path: Path) -> None:
    case = gravity_case(case_id)
    out = run_script(name, case, tmp_path, [DIVERGENCE])
    got, want = values(out, case), observed(name, case)
    assert set(got) == {"positions", "velocities", "momentum", "energy", "settle", "jitter",
                        "energy_drift", "apex", "bounce_time"}
    assert got == want
    if case_id == DROP:  # the drop bounces: the comparison above saw apexes and bounce times
        assert want["apex"] and want["bounce_time"]
    assert any(line.startswith("# divergence: computed by crosscheck against the exact run")
               and line.endswith("the run recorded 0.25") for line in out.splitlines())


@pytest.mark.engine
@pytest.mark.parametrize("name", ["pymunk", "box2d", "pybullet", "mujoco", "rapier"])
def test_walls_without_gravity_have_no_ground_and_open_space_only_energy_drift(
        name: str, tmp_path: Path) -> None:
    walled = scene()
    got = values(run_script(name, walled, tmp_path), walled)
    assert got == observed(name, walled)
    assert got["settle"] is None and got["apex"] is None and got["bounce_time"] is None
    open_space = scene(walls=[], duration=0.5)
    out = run_script(name, open_space, tmp_path)
    got = values(out, open_space)
    assert set(got) == {"positions", "velocities", "momentum", "energy", "energy_drift"}
    assert got == observed(name, open_space)
    assert "# settle, jitter, apex, bounce_time, divergence: none in open space" in out


def _trajectory(case: SceneCase, rng: random.Random, samples: int) -> Trajectory:
    """A made-up bouncing trajectory of the scene's bodies (body 0 goes up and down through
    the ground's normal speed 0, sometimes resting on a record of exactly 0)."""
    end = case.step_count * (case.dt or 1.0)
    speeds = [rng.choice((-1.0, 0.0, 1.0, -2.5, 2.5, rng.uniform(-3, 3))) for _ in range(samples)]
    dim, n = case.dim, len(case.bodies)
    positions = tuple(tuple(tuple(rng.uniform(0.0, 2.0) for _ in range(dim)) for _ in range(n))
                      for _ in range(samples))
    velocities = tuple(tuple((*(0.0,) * (dim - 1), speeds[k]) if i == 0 else
                             tuple(rng.uniform(-1, 1) for _ in range(dim)) for i in range(n))
                       for k in range(samples))
    return Trajectory(tuple(end * k / (samples - 1) for k in range(samples)), positions, velocities,
                      (0.0,) * samples)


@pytest.mark.parametrize("which", ["drop", "column", "walls", "open", "ceiling-only"])
def test_the_scripts_measures_are_the_harnesss(which: str) -> None:
    case = {"drop": gravity_case(DROP), "column": gravity_case("rest-3d-column.dt=0.0166667"),
            "walls": scene(), "open": scene(walls=[]),
            "ceiling-only": scene(gravity=[0.0, -9.81],
                                  walls=[{"normal": [0.0, -1.0], "offset": -2.0}])}[which]
    gravity = tuple(scene_measures.gravity(case))
    walls = [(tuple(w.normal), w.offset) for w in case.walls]
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    duration = case.step_count * (case.dt or 1.0)
    rng = random.Random(which)
    for _ in range(50):
        track = _trajectory(case, rng, 60)
        final_p, final_v = track.positions[-1], track.velocities[-1]
        recorded = track if scene_measures.surrounded(case) else None
        mine = plain.engine_measures(
            gravity, walls, bodies, duration, final_p, final_v,
            None if recorded is None else (track.times, track.positions, track.velocities))
        theirs = scene_measures.engine_measures(case, final_p, final_v, recorded)
        for q in MEASURED:  # a measure without a value: its reason (the harness's Undefined)
            got, want = mine[q], theirs[q]
            if isinstance(got, str):
                assert want == Undefined(got), q
            else:
                assert encode(got) == encode(want), q
