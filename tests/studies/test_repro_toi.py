"""Repro scripts of times of impact (``sphere_toi``): they run and print the adapter's answer."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from adapters.box2d import Box2dTuned
from adapters.fcl import Fcl, FclCcdNaive, FclCcdRayShooting
from adapters.rapier import RapierDefault
from adapters.reference import ReferenceF32, ReferenceF64
from crosscheck.core.contract import Adapter
from crosscheck.core.model import Kind, Observation, Undefined, quantities_of
from crosscheck.core.schema import ToiCase
from crosscheck.core.values import encode
from crosscheck.studies.repro.script import engine_part, script_text

C = 1.0123456789


def case(dim: int, **over: object) -> ToiCase:
    a = {"center": [-C, 0.0, 0.0][:dim], "radius": 0.05, "velocity": [1.0, 0.0, 0.0][:dim]}
    b = {"center": [C, 0.0, 0.0][:dim], "radius": 0.05, "velocity": [-1.0, 0.0, 0.0][:dim]}
    fields = {"id": "toi-head-on", "kind": "sphere_toi", "description": "head-on", "dim": dim,
              "duration": 1.0, "a": a, "b": b, **over}
    return ToiCase.model_validate(fields)


MISS = {"b": {"center": [1.0, 0.5], "radius": 0.05, "velocity": [-1.0, 0.0]},
        "id": "toi-miss"}


def run(adapter: Adapter, c: ToiCase, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    info = {"name": adapter.name, "engine": adapter.engine, "settings": adapter.settings}
    text = script_text(c, engine_part(adapter, c), info, [], [], "test")
    path = tmp_path / "repro.py"
    path.write_text(text, encoding="utf-8")
    return subprocess.run([sys.executable, str(path)], capture_output=True, text=True,
                          timeout=60, check=False)


def printed(out: str) -> dict[str, object]:
    found = {}
    for line in out.splitlines():
        name, _, text = line.partition(" = ")
        if name in ("hit", "toi", "normal"):
            found[name] = json.loads(text)
    return found


def expected(observed: Observation) -> dict[str, object]:
    """The adapter's answer as the script prints it: JSON text, null without a value."""
    out: dict[str, object] = {}
    for q in quantities_of(Kind.SPHERE_TOI):
        value = observed.get(q)
        out[q] = None if isinstance(value, Undefined) else json.loads(encode(value))
    return out


@pytest.mark.parametrize(("adapter", "c"), [
    (Fcl(), case(3)), (Fcl(), case(2)), (FclCcdNaive(), case(3)), (Box2dTuned(), case(2)),
    (RapierDefault(), case(3)), (RapierDefault(), case(2)), (Fcl(), case(2, **MISS)),
    (Box2dTuned(), case(2, **MISS)), (RapierDefault(), case(2, **MISS)),
    (FclCcdRayShooting(), case(3)), (ReferenceF64(), case(3)), (ReferenceF32(), case(2)),
    (ReferenceF64(), case(2, duration=0.96))],
    ids=["fcl-3d", "fcl-2d", "naive-3d", "box2d-2d", "rapier-3d", "rapier-2d", "fcl-miss",
         "box2d-miss", "rapier-miss", "ray-shooting-undefined", "reference-3d", "reference-f32",
         "reference-end-sample-misses"])
def test_script_prints_the_adapters_answer(adapter: Adapter, c: ToiCase, tmp_path: Path) -> None:
    done = run(adapter, c, tmp_path)
    assert done.returncode == 0, done.stderr
    assert printed(done.stdout) == expected(adapter.observe(c))


def test_script_of_a_solver_that_does_not_compute_says_so(tmp_path: Path) -> None:
    done = run(FclCcdRayShooting(), case(3), tmp_path)
    assert done.returncode == 0, done.stderr
    assert "continuousCollide returned -1" in done.stdout
