"""A Dask worker lost in the middle of ``crosscheck run --scheduler`` costs nothing: the run
completes with every row present once.  Losing the scheduler fails the run cleanly with a
resume hint, and the rows written so far stay."""

from __future__ import annotations

import json
import logging
import os
import signal
import subprocess
import sys
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pytest

pytest.importorskip("distributed")

import dask
from distributed import Client, LocalCluster

from crosscheck.results.run import read_results
from tests.conftest import ROOT, wait_until

TIMING = ["setup_s", "query_s", "query_iqr_s", "loops", "unstable"]
CLI = [sys.executable, "-m", "crosscheck.cli"]
DASK = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
WORKER = [sys.executable, "-m", "distributed.cli.dask_worker"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT), "DASK_DISTRIBUTED__WORKER__DAEMON": "False"}
FILES = [str(ROOT / "cases" / f"{name}.toml")
         for name in ("aabb", "sphere", "response", "touching", "near_touching", "offset")]

pytestmark = [pytest.mark.engine, pytest.mark.slow]


def run_args(out: Path, *extra: str) -> list[str]:
    return [*CLI, "run", *FILES, "--engine", "reference", "--engine", "pymunk", "--quick",
            "--out", str(out), *extra]


def rows(directory: Path) -> pd.DataFrame:
    return read_results(directory).drop(columns=TIMING).reset_index(drop=True)


def wait_for_rows(path: Path, process: subprocess.Popen[bytes]) -> None:
    def written() -> bool:
        if path.exists() and path.stat().st_size:
            return True
        assert process.poll() is None, "the run ended before it wrote a row"
        return False

    wait_until(written, f"{path} got no row", timeout_s=120, poll_s=0.01)


def raw_keys(directory: Path) -> Counter[tuple[str, str, str]]:
    """How often each (case, engine, quantity) row is in results.jsonl, as written."""
    lines = (directory / "results.jsonl").read_text(encoding="utf-8").splitlines()
    return Counter((r["case_id"], r["engine"], r["quantity"]) for r in map(json.loads, lines))


@pytest.fixture
def cluster() -> Iterator[LocalCluster]:
    with (dask.config.set({"distributed.worker.daemon": False}),
          LocalCluster(n_workers=2, processes=True, threads_per_worker=1,  # type: ignore[no-untyped-call]
                       dashboard_address=None, silence_logs=logging.CRITICAL) as local):
        yield local


def worker_pids(cluster: LocalCluster) -> list[int]:
    """The process ids of the cluster's Dask worker processes (not their nannies)."""
    with Client(cluster, set_as_default=False) as client:  # type: ignore[no-untyped-call]
        pids: dict[str, int] = client.run(os.getpid)  # type: ignore[no-untyped-call]
    return sorted(pids.values())


def test_a_worker_killed_mid_run_loses_and_duplicates_nothing(cluster: LocalCluster,
                                                              tmp_path: Path) -> None:
    local = tmp_path / "local"
    subprocess.run(run_args(local, "--jobs", "1"), env=ENV, check=True, capture_output=True)
    out = tmp_path / "cluster"
    process = subprocess.Popen(run_args(out, "--scheduler", cluster.scheduler_address),
                               env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wait_for_rows(out / "results.jsonl", process)
    os.kill(worker_pids(cluster)[0], signal.SIGKILL)
    assert json.loads((out / "run.json").read_text())["finished"] is None, "killed too late"
    _, stderr = process.communicate(timeout=300)
    assert process.returncode == 0, stderr.decode()
    assert set(raw_keys(out).values()) == {1}  # a retried case is not written twice
    pd.testing.assert_frame_equal(rows(local), rows(out))


def test_losing_the_scheduler_fails_cleanly_with_a_resume_hint(tmp_path: Path) -> None:
    address_file = tmp_path / "scheduler.json"
    scheduler = subprocess.Popen([*DASK, "--scheduler-file", str(address_file), "--port", "0",
                                  "--dashboard-address", ":0", "--no-dashboard"],
                                 env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = None
    try:
        wait_until(address_file.exists, "the scheduler wrote no address file")
        address = json.loads(address_file.read_text())["address"]
        worker = subprocess.Popen([*WORKER, address, "--nthreads", "1", "--no-nanny"],
                                  env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        out = tmp_path / "run"
        process = subprocess.Popen(run_args(out, "--scheduler", address),
                                   env={**ENV, "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "2s"},
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        wait_for_rows(out / "results.jsonl", process)
        scheduler.send_signal(signal.SIGKILL)
        _, stderr = process.communicate(timeout=120)
    finally:
        for child in (scheduler, worker):
            if child is not None and child.poll() is None:
                child.send_signal(signal.SIGKILL)
                child.wait()
    message = " ".join(stderr.decode().split())
    assert process.returncode == 1, message
    assert "Traceback" not in message, stderr.decode()
    assert "Dask" in message and f"crosscheck run --resume {out}" in message
    assert len(read_results(out)) > 0  # the rows written before it are kept
    assert json.loads((out / "run.json").read_text())["finished"] is None
