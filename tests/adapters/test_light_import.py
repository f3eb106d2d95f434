"""Adapters that declare ``light_import`` are imported in the forkserver every engine worker is
forked from (:func:`crosscheck.run.worker_process.preload`), so their modules must load no
engine library: otherwise every worker would hold every engine, and isolation would be gone."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import adapters
from tests.conftest import ROOT

ENGINE_MODULES = {"pybullet", "pymunk", "mujoco", "fcl", "coal", "Box2D", "pyb2d3", "rapier3d",
                  "pydrake"}
"""The engine libraries the built-in adapters import (each in its own worker)."""

LIGHT = sorted({type(adapters.get(name)).__module__ for name in adapters.names()
                if adapters.get(name).light_import})


def test_every_built_in_engine_declares_a_light_import() -> None:
    assert {"adapters.reference", "adapters.fcl", "adapters.pybullet",
            "adapters.pymunk", "adapters.mujoco", "adapters.coal",
            "adapters.box2d", "adapters.rapier"} <= set(LIGHT)


@pytest.mark.parametrize("module", LIGHT)
def test_a_light_import_loads_no_engine_library(module: str) -> None:
    probe = (f"import sys, json, {module}\n"
             f"print(json.dumps(sorted(m for m in {sorted(ENGINE_MODULES)!r} "
             f"if m in sys.modules)))")
    done = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True,
                          text=True, check=True)
    assert json.loads(done.stdout.strip().splitlines()[-1]) == []
