"""The one small real run the repro tests read: a slice of the suite on every engine variant.

The cases are chosen so that every variant disagrees on every kind it runs (scenes
included) and every way a script can end shows up: an answer, an engine's exception, an
adapter's guard, a crash and a declared hang.  Made once per session, with ``--quick``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.core.options import RunOptions
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests.conftest import ROOT

FILES = ("aabb", "touching", "float_traps", "scale", "sphere", "degenerate", "response",
         "impacts", "bad_input", "mass_ratio", "scenes", "gravity")
CASES = (
    # boxes: corner touches (margins, touching rules, undefined normals), crossed boxes
    "aabb-2d-corner-touch-unequal", "aabb-3d-corner-touch-mixed-signs",
    "aabb-2d-coincident-cross",
    # spheres: a float trap, a small diagonal touch, coincident centres (FCL's known hang)
    "sphere-2d-trap-12-35-37", "sphere-3d-scale-1e-3-touch-122", "sphere-3d-coincident",
    # responses: separating bodies, oblique impacts, default settings, coincident centres
    "resp-2d-separating-head-on", "resp-2d-oblique-345-mass-2-1", "resp-3d-oblique-345",
    "resp-2d-coincident-centres", "resp-2d-slow-0.19",
    # bad input: NaN literals (guards), a segfault, an abort, engines that raise, MuJoCo's
    # warning of a bad acceleration, Rapier's quarantine of a non-finite body
    "bad-sphere-2d-nan-centre", "bad-sphere-2d-nan-radius", "bad-resp-2d-negative-mass",
    "bad-resp-2d-zero-mass-a", "bad-resp-2d-inf-mass-a", "bad-resp-3d-inf-velocity",
    # a scene with a coarse step: PyBullet and pymunk both miss the exact state
    "scene-2d-head-on.dt=0.1",
    # gravity and a ground: a resting sphere (3-D engines) and an elastic drop (every one)
    "rest-3d-sphere.dt=0.0166667", "drop-2d-elastic.dt=0.0166667",
)


@pytest.fixture(scope="session")
def repro_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A ``--quick`` run of :data:`CASES` on every built-in engine variant."""
    loaded = load_paths([ROOT / "cases" / f"{name}.toml" for name in FILES])
    chosen = [case for case in loaded.cases if case.id in CASES]
    assert sorted(case.id for case in chosen) == sorted(CASES)
    engines = [adapters.get(name) for name in adapters.names()]
    directory = tmp_path_factory.mktemp("repro") / "run"
    options = RunOptions(quick=True, jobs=2)
    launch(ResultsStore(directory), chosen, engines, options,
           new_info(directory, "test_repro", options, engines, chosen))
    return directory
