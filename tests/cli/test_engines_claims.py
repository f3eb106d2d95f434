"""``crosscheck engines --claims [RUN_DIR]``: the declared claims, then their check on a stored run
(its recorded claims, the variants it did not run untested); a folder that is not a run is
refused by name."""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import ClassVar

import pytest

import adapters
from crosscheck.cli import main
from crosscheck.cli.engines import declared_claims
from crosscheck.core.claims import Claim
from crosscheck.core.kinds import spec
from crosscheck.core.options import RunOptions
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests.conftest import ROOT, sphere
from tests.fakes import OffByOne


class Claiming(OffByOne):
    """Off by 1 in distance: its distance claim fails, its verdict claim holds."""

    name: ClassVar[str] = "fake-claiming"
    claims: ClassVar[tuple[Claim, ...]] = (
        Claim("distance", ("sphere",), 1e-6, "distance within a micron", "https://example.org/d"),
        Claim("hit", ("sphere",), 0.0, "verdicts right clear of touching",
              "https://example.org/h", clear_of_touching=0.01),
        Claim("distance", ("aabb",), 1e-6, "boxes too", "https://example.org/b"))


@pytest.fixture
def claiming_run(tmp_path: Path) -> Path:
    folder = tmp_path / "run"
    cases = [sphere(0.0, 2.0 + i / 4, id=f"s{i}") for i in range(3)]
    options, engines = RunOptions(quick=True, isolate=False), [Claiming()]
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    return folder


def piped(args: list[str], columns: int = 200) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "COLUMNS": str(columns), "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "crosscheck.cli", *args], env=env,
                          capture_output=True, text=True, check=False)


def test_claims_lists_each_variants_declared_claims_with_their_sources() -> None:
    declared = declared_claims()
    assert {"fcl", "coal", "coal-default", "rapier", "box2d", "mujoco-default"} <= set(declared)
    assert "mujoco" not in declared  # detection is scored under mujoco-default only
    done = piped(["engines", "--claims"])
    assert done.returncode == 0, done.stderr
    for name, claims in declared.items():
        for claim in claims:
            assert claim.source in done.stdout.replace("\n", ""), (name, claim.source)


def test_claims_on_a_run_adds_the_measurement_and_the_verdict(claiming_run: Path) -> None:
    done = piped(["engines", "--claims", str(claiming_run)])
    assert done.returncode == 0, done.stderr
    lines = [line for line in done.stdout.splitlines() if "fake-claiming" in line]
    assert len(lines) == 3
    distance, hit, boxes = lines
    assert "fails: error 1 > 1e-06" in distance, distance
    assert re.search(r"3 rows, worst 1 \(s\d\)", distance), distance
    assert "holds" in hit
    assert "untested: no row of fake-claiming answers distance on aabb" in boxes
    # the variants the run did not run: their declared claims, untested
    assert any("fcl" in line and "untested: engine not in the run" in line
               for line in done.stdout.splitlines())


def test_claims_read_whole_at_80_columns(claiming_run: Path) -> None:
    for args in (["engines", "--claims"], ["engines", "--claims", str(claiming_run)]):
        done = piped(args, columns=80)
        assert done.returncode == 0, done.stderr
        wide = [line for line in done.stdout.splitlines() if len(line) > 80 or "\u2026" in line]
        assert not wide, wide


def test_claims_refuses_a_folder_that_is_not_a_run(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["engines", "--claims", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert str(tmp_path) in err and "no run.json" in err
    missing = tmp_path / "nowhere"
    assert main(["engines", "--claims", str(missing)]) == 2
    assert str(missing) in capsys.readouterr().err


CHECKED = {"fcl", "coal", "rapier", "box2d", "mujoco"}
"""The engines' packages whose declarations this test holds to (adapters/<engine>/)."""


def test_declared_claims_are_checkable_on_the_suite() -> None:
    """Every declaration names a quantity its kinds score, kinds its variant runs in the claim's
    dimensions, and a source URL; a relative bound is below 1 and an absolute one finite."""
    for name, claims in declared_claims().items():
        cls = adapters.find(name).load()
        if cls.__module__.split(".")[1] not in CHECKED:
            continue
        capabilities = cls.capabilities
        for claim in claims:
            assert claim.source.startswith("https://"), name
            assert math.isfinite(claim.bound) and (claim.bound < 1 or not claim.relative)
            for kind in claim.kinds:
                assert claim.quantity in spec(kind).names, (name, claim)
                assert any((kind, d) in {(str(k), dd) for k, dd in capabilities}
                           for d in claim.dims), (name, kind)
