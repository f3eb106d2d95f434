"""Worker lifetimes.  Leaking engines: a worker over ``--worker-memory`` is recycled between
cases, and a case that passes the limit on its own is a ``crash`` ("memory limit") while the
run goes on.  Warm workers: the variants of one engine share its worker, and a crash in one
still costs only that case x variant.

The fakes allocate real, touched memory (a few hundred MB at most: the limit here is
400 MB and the watchdog stops the runaway one within a few of its 25 MB chunks).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd

from crosscheck.core.options import RunOptions
from crosscheck.results.run import read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.runner import run
from crosscheck.run.worker import WorkerPool
from tests import fakes
from tests.conftest import ROOT, sphere

LIMIT_MB = 400.0
"""Over a fresh worker's ~65 MB; Leaks passes it after four of its 100 MB cases."""


def statuses(frame: pd.DataFrame) -> dict[str, set[str]]:
    return {str(k): set(v) for k, v in frame.groupby("case_id")["status"]}


def test_a_leaking_worker_is_recycled_between_cases_and_every_case_answers() -> None:
    options = RunOptions(quick=True, timeout_s=30.0, worker_memory_mb=LIMIT_MB)
    pool = WorkerPool(options)
    try:
        outcomes = [pool.execute(fakes.Leaks(), sphere(0.0, 2.0, id=f"c{i}"), options)
                    for i in range(8)]  # 800 MB leaked in all: twice the limit
    finally:
        pool.close()
    assert [o.reason for o in outcomes] == [""] * 8  # no case blamed for the leak
    assert all(o.observation is not None for o in outcomes)
    assert pool.recycled >= 1


def test_a_case_over_the_limit_on_its_own_is_a_crash_and_the_run_goes_on(
        tmp_path: Path) -> None:
    cases = [sphere(0.0, 2.0, id="before"), sphere(0.0, 1.5, id="hog"),
             sphere(0.0, 3.0, id="after")]
    store = ResultsStore(tmp_path / "run")
    run(cases, [fakes.Hogs()], store,
        RunOptions(quick=True, timeout_s=30.0, worker_memory_mb=LIMIT_MB))
    store.close()
    frame = read_results(tmp_path / "run")
    assert statuses(frame) == {"before": {"agree"}, "hog": {"crash"}, "after": {"agree"}}
    (reason,) = set(frame[frame["case_id"] == "hog"]["reason"])
    assert reason.startswith("memory limit: this case alone grew the worker from ")
    assert reason.endswith(" MB), past --worker-memory 400 MB")


def test_an_engine_over_the_limit_once_loaded_is_a_crash_saying_so(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path / "run")
    run([sphere(0.0, 2.0, id="a")], [fakes.AlwaysRight()], store,
        RunOptions(quick=True, worker_memory_mb=10.0))
    store.close()
    frame = read_results(tmp_path / "run")
    assert set(frame["status"]) == {"crash"}
    (reason,) = set(frame["reason"])
    assert reason.startswith("memory limit: ") and "its engine" in reason  # loading or loaded


def test_worker_memory_is_an_option_of_run_recorded_in_run_json(tmp_path: Path) -> None:
    out = tmp_path / "run"
    cli = [sys.executable, "-m", "crosscheck.cli", "run"]
    helped = subprocess.run([*cli, "--help"], capture_output=True, text=True, cwd=ROOT,
                            timeout=120)
    assert "--worker-memory" in helped.stdout
    done = subprocess.run([*cli, str(ROOT / "cases" / "sphere.toml"), "--engine", "reference",
                           "--quick", "--worker-memory", "300", "--out", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert done.returncode == 0, done.stderr
    options = json.loads((out / "run.json").read_text(encoding="utf-8"))["options"]
    assert options["worker_memory_mb"] == 300
    assert RunOptions().worker_memory_mb == 2048  # the default, on the CLI page (docs/cli.md)


def test_variants_of_one_engine_share_a_warm_worker_and_a_crash_costs_one_variant() -> None:
    options = RunOptions(quick=True)
    pool = WorkerPool(options)
    boom, after = sphere(0.0, 1.5, id="boom"), sphere(0.0, 3.0, id="after")
    right, off, crashes = fakes.AlwaysRight(), fakes.OffByOne(), fakes.CrashesOnSpheresAt()
    assert right.engine == off.engine == crashes.engine  # variants of one engine, "fake"
    try:
        answers = [pool.execute(a, after, options) for a in (right, off, crashes)]
        assert pool.started == 1  # one process for the three variants
        crashed = pool.execute(crashes, boom, options)
        again = [pool.execute(a, boom, options) for a in (right, off)]
    finally:
        pool.close()
    assert all(o.observation is not None for o in answers)
    assert crashed.status == "crash" and crashed.reason == "worker killed by SIGSEGV"
    assert [o.observation is not None for o in again] == [True, True]  # warmed up anew
    assert pool.started == 2  # one restart, after the crash
