"""Reliability: bad input through every engine, locks, Ctrl-C, long runs with flat memory."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.core.model import Kind, Status
from crosscheck.core.options import RunOptions
from crosscheck.results.store import ResultsStore, StoreError, read_results
from crosscheck.run.runner import run
from crosscheck.studies.bench import rss_mb
from crosscheck.studies.fuzzgen import generate
from tests.conftest import ROOT

CLI = [sys.executable, "-m", "crosscheck.cli"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
ENDINGS = {str(s) for s in Status}


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


def test_a_second_run_into_the_same_directory_is_refused(tmp_path: Path) -> None:
    first = ResultsStore(tmp_path / "run")
    with pytest.raises(StoreError, match="another crosscheck run"):
        ResultsStore(tmp_path / "run", resume=True)
    first.close()
    ResultsStore(tmp_path / "run", resume=True).close()  # free once the first is done


def wait_for_rows(path: Path, rows: int = 1) -> None:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if path.exists() and path.read_text().count("\n") >= rows:
            return
        time.sleep(0.05)
    raise AssertionError(f"{path} never reached {rows} rows")


def test_concurrent_cli_run_is_refused_with_a_clear_error(tmp_path: Path) -> None:
    out = tmp_path / "run"
    args = [*CLI, "run", str(ROOT / "cases" / "sphere.toml"), "--engine", "reference",
            "--min-sample", "0.01", "--timing-cases", "1000", "--jobs", "1", "--out", str(out)]
    first = subprocess.Popen(args, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        wait_for_rows(out / "results.jsonl")
        second = subprocess.run([*CLI, "run", "--resume", str(out)], env=ENV,
                                capture_output=True, text=True, timeout=60)
        assert second.returncode == 2
        assert "another crosscheck run (pid" in second.stderr
    finally:
        first.kill()
        first.wait()


def test_ctrl_c_stops_cleanly_keeps_rows_and_prints_the_resume_hint(tmp_path: Path) -> None:
    out = tmp_path / "run"
    args = [*CLI, "run", str(ROOT / "cases" / "sphere.toml"), str(ROOT / "cases" / "aabb.toml"),
            "--engine", "reference", "--engine", "pymunk", "--min-sample", "0.01",
            "--out", str(out)]
    process = subprocess.Popen(args, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, start_new_session=True)
    wait_for_rows(out / "results.jsonl", rows=20)
    os.killpg(process.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole group
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130
    assert f"crosscheck run --resume {out}" in stderr.replace("\n", "")
    kept = read_results(out)
    assert len(kept) >= 20
    assert not (kept["status"] == "crash").any(), "a worker's Ctrl-C was taken for a crash"
    resumed = subprocess.run([*CLI, "run", "--resume", str(out)], env=ENV,
                             capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    final = read_results(out)
    cases = len(load_paths([ROOT / "cases" / "sphere.toml", ROOT / "cases" / "aabb.toml"]).cases)
    assert len(final.drop_duplicates(["case_id", "engine"])) == cases * 2


@pytest.mark.slow
def test_a_100k_case_run_keeps_memory_flat(tmp_path: Path) -> None:
    cases = [g.case for g in generate(Kind.SPHERE, 100_000, seed=3)]
    store = ResultsStore(tmp_path / "run")
    samples: list[float] = []
    done = 0

    def progress(n: int) -> None:
        nonlocal done
        done += 1
        if done % 10_000 == 0:
            samples.append(rss_mb())

    run(cases, [adapters.get("reference")], store, RunOptions(quick=True, jobs=2),
        progress=progress)
    store.close()
    assert len(read_results(tmp_path / "run")) == 300_000
    assert len(samples) == 10
    growth = samples[-1] - samples[1]
    assert growth < 50, f"resident memory grew {growth:.0f} MB from 20k to 100k cases: {samples}"
