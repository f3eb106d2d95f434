"""Scale-out on a Dask cluster gives the same results as a local run."""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

pytest.importorskip("distributed")

import dask
from distributed import LocalCluster, SchedulerPlugin

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.core.contract import Adapter
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.run import read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.casework import ITEM_CASES
from crosscheck.run.runner import run
from tests import fakes
from tests.conftest import ROOT, sphere

TIMING = ["setup_s", "query_s", "query_iqr_s", "loops", "unstable"]
CASE_FILES = [ROOT / "cases" / "sphere.toml", ROOT / "cases" / "response.toml"]


@pytest.fixture(scope="module")
def cluster() -> Iterator[LocalCluster]:
    # Dask workers must not be daemonic, or they cannot start engine worker processes.
    with (dask.config.set({"distributed.worker.daemon": False}),
          LocalCluster(n_workers=2, processes=True, threads_per_worker=1,  # type: ignore[no-untyped-call]
                       dashboard_address=None, silence_logs=logging.ERROR) as local):
        _tasks(local)
        yield local


def _run(directory: Path, cases: list[AnyCase], engines: Sequence[Adapter],
         options: RunOptions) -> pd.DataFrame:
    store = ResultsStore(directory)
    try:
        run(cases, engines, store, options)
    finally:
        store.close()
    return read_results(directory)


class _Finished(SchedulerPlugin):
    """Counts the distributed lanes' tasks that finished on the scheduler."""

    def __init__(self) -> None:
        self.count = 0

    def transition(self, key: Any, start: str, finish: str, *args: Any, **kwargs: Any) -> None:
        if finish == "memory" and str(key).startswith("_remote-"):
            self.count += 1


def _tasks(cluster: LocalCluster) -> int:
    """Tasks the cluster's scheduler has run through the distributed lanes, so far."""
    scheduler = cluster.scheduler
    assert scheduler is not None
    plugin = scheduler.plugins.get("crosscheck-test-count")
    if plugin is None:
        plugin = _Finished()
        scheduler.add_plugin(plugin, name="crosscheck-test-count")
    assert isinstance(plugin, _Finished)
    return plugin.count


@pytest.mark.engine
def test_cluster_results_match_local(cluster: LocalCluster, tmp_path: Path) -> None:
    cases = load_paths(CASE_FILES).cases
    engines = [adapters.get("reference"), adapters.get("pymunk")]
    local = _run(tmp_path / "local", cases, engines, RunOptions(quick=True, jobs=2))
    before = _tasks(cluster)
    remote = _run(tmp_path / "remote", cases, engines,
                  RunOptions(quick=True, jobs=2, scheduler=cluster.scheduler_address))
    assert _tasks(cluster) - before == math.ceil(len(cases) / ITEM_CASES)  # a task per item
    assert len(local) > 0
    pd.testing.assert_frame_equal(local.drop(columns=TIMING), remote.drop(columns=TIMING))


def test_engine_crash_and_hang_are_caught_on_the_workers(cluster: LocalCluster,
                                                         tmp_path: Path) -> None:
    cases = [sphere(0.0, 2.0, id="boom"), sphere(0.0, 2.0, id="fine")]
    engines = [fakes.CrashesOnSpheresAt(), fakes.SleepsForever(), fakes.AlwaysRight()]
    frame = _run(tmp_path / "run", cases, engines,
                 RunOptions(quick=True, timeout_s=1.0, scheduler=cluster.scheduler_address))
    status = frame.groupby(["case_id", "engine"])["status"].agg(set).to_dict()
    assert status[("boom", "fake-boom")] == {"crash"}
    assert status[("fine", "fake-boom")] <= {"agree", "undefined"}
    assert status[("boom", "fake-hangs")] == status[("fine", "fake-hangs")] == {"timeout"}
    assert status[("boom", "fake-right")] <= {"agree", "undefined"}


@pytest.mark.engine
def test_resumed_run_on_cluster_skips_done_pairs(cluster: LocalCluster, tmp_path: Path) -> None:
    cases = load_paths(CASE_FILES[:1]).cases
    engines = [adapters.get("reference"), adapters.get("pymunk")]
    options = RunOptions(quick=True, scheduler=cluster.scheduler_address)
    full = _run(tmp_path / "full", cases, engines, options)
    partial = _run(tmp_path / "part", cases[:3], engines[:1], options)
    store = ResultsStore(tmp_path / "part", resume=True)
    try:
        run(cases, engines, store, options)
    finally:
        store.close()
    resumed = read_results(tmp_path / "part")
    assert len(partial) < len(resumed) == len(full)
    pd.testing.assert_frame_equal(full.drop(columns=TIMING), resumed.drop(columns=TIMING))


def test_cli_scheduler_reaches_the_run(cluster: LocalCluster, tmp_path: Path) -> None:
    address = cluster.scheduler_address
    before = _tasks(cluster)
    out = tmp_path / "cli"
    assert main(["run", str(CASE_FILES[0]), "--engine", "reference", "--quick",
                 "--out", str(out), "--scheduler", address]) == 0
    info = json.loads((out / "run.json").read_text(encoding="utf-8"))
    assert info["options"]["scheduler"] == address
    frame = read_results(out)
    assert set(frame["engine"]) == {"reference"} and len(frame) > 0
    assert _tasks(cluster) - before == math.ceil(len(load_paths(CASE_FILES[:1]).cases) / ITEM_CASES)

    before = _tasks(cluster)
    fuzz_out = tmp_path / "fuzz"
    assert main(["fuzz", "--kind", "sphere", "--n", "4", "--seed", "1", "--engine", "reference",
                 "--out", str(fuzz_out), "--scheduler", address]) == 0
    info = json.loads((fuzz_out / "fuzz.json").read_text(encoding="utf-8"))
    assert info["options"]["scheduler"] == address
    assert _tasks(cluster) - before == 1  # a fuzz task is a chunk of up to 1,000 cases
