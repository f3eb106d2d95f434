"""A crashing or hanging engine costs one case x engine, never the run: real engine faults
that happen today, not mocks (the mechanism, with fakes: tests/run/test_isolation.py).

- FCL signed distance on spheres whose centres coincide loops forever -> ``timeout`` of the
  distance (the verdict and normal come from ``collide``, which answers);
- FCL signed distance with NaN input segfaults -> ``crash`` (SIGSEGV);
- pymunk ``Body(mass=-1)`` aborts the interpreter -> ``crash`` (SIGABRT);
and in every case the next case on the same engine still runs.  The whole bad-input suite
(NaN, inf, negative and zero sizes and masses, coincident centres) through every engine
ends in a recorded status for every case x engine.
"""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
import pytest

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.core.model import Status, Undefined
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.run import read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.runner import run
from crosscheck.truth import oracle
from tests.conftest import ROOT, response, sphere

pytestmark = pytest.mark.engine

BAD = ["bad-input"]
ENDINGS = {str(s) for s in Status}


def run_engine(tmp_path: Path, engine: str, cases: list[AnyCase],
               timeout_s: float = 3.0) -> pd.DataFrame:
    store = ResultsStore(tmp_path / engine)
    run(cases, [adapters.get(engine)], store, RunOptions(quick=True, timeout_s=timeout_s))
    store.close()
    return read_results(tmp_path / engine)


def status_of(frame: pd.DataFrame, case_id: str) -> set[str]:
    return set(frame[frame["case_id"] == case_id]["status"])


def test_fcl_hang_on_coincident_spheres_is_a_timeout_of_the_distance_alone(
        tmp_path: Path) -> None:
    # Only the signed distance loops: collide still answers the verdict and the normal,
    # scored as any other answer (the oracle: a hit; no defined normal for coincident centres).
    case = sphere(0.0, 0.0, id="coincident")
    cases = [case, sphere(0.0, 2.0, id="after")]
    frame = run_engine(tmp_path, "fcl", cases, timeout_s=2.0)
    rows = frame[frame["case_id"] == "coincident"].set_index("quantity")
    assert rows.loc["distance", "status"] == "timeout"
    assert rows.loc["distance", "reason"] == (
        "no answer within 0.25 s (declared known hang: fcl's signed distance "
        "loops on coincident sphere centres (fcl issue 346))")
    truth = oracle.truth(case)
    assert truth.hit is True and isinstance(truth.normal, Undefined)
    assert (rows.loc["hit", "status"], rows.loc["hit", "value"]) == ("agree", "true")
    assert rows.loc["normal", "status"] == "undefined"
    assert status_of(frame, "after") == {"agree"}


def test_fcl_segfault_on_nan_is_a_crash(tmp_path: Path) -> None:
    cases = [sphere(math.nan, 1.0, id="nan", tags=BAD), sphere(0.0, 2.0, id="after")]
    frame = run_engine(tmp_path, "fcl", cases)
    nan_rows = frame[frame["case_id"] == "nan"]
    assert set(nan_rows["status"]) == {"crash"}
    assert set(nan_rows["reason"]) == {"worker killed by SIGSEGV"}
    assert status_of(frame, "after") == {"agree"}


def test_pymunk_abort_on_negative_mass_is_a_crash(tmp_path: Path) -> None:
    negative = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], ma=-1.0, mb=3.0,
                        id="negative-mass", tags=BAD)
    after = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], id="after")
    frame = run_engine(tmp_path, "pymunk", [negative, after])
    rows = frame[frame["case_id"] == "negative-mass"]
    assert set(rows["status"]) == {"crash"}
    assert set(rows["reason"]) == {"worker killed by SIGABRT"}
    assert status_of(frame, "after") == {"agree"}


def test_bad_input_ends_in_a_recorded_status_on_every_engine(tmp_path: Path) -> None:
    loaded = load_paths([ROOT / "cases" / "bad_input.toml"])
    assert loaded.errors == [] and loaded.blocks >= 30
    engines = [adapters.get(name) for name in adapters.names()]
    store = ResultsStore(tmp_path / "run")
    run(loaded.cases, engines, store, RunOptions(quick=True, timeout_s=2.0, jobs=2))
    store.close()
    frame = read_results(tmp_path / "run")
    pairs = frame.drop_duplicates(["case_id", "engine"])
    assert len(pairs) == len(loaded.cases) * len(engines)  # nothing lost, the run went on
    assert set(frame["status"]) <= ENDINGS
    faults = set(zip(pairs["engine"], pairs["status"], pairs["reason"], strict=True))
    assert ("fcl", "crash", "worker killed by SIGSEGV") in faults  # NaN into signed distance
    assert ("pymunk", "crash", "worker killed by SIGABRT") in faults  # Body(mass < 0)
    assert {"error", "undefined"} <= set(pairs["status"])
