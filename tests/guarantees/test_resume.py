"""Nothing computed is lost: resuming a stopped run (SIGKILL at random moments, a half-written
last line) and running in parallel lose, duplicate and reorder no row, and a new run never
writes over a folder that holds results."""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.results.run import read_results, read_run_info
from crosscheck.results.store import ResultsStore, StoreError
from crosscheck.run.runner import run
from tests import fakes
from tests.conftest import ROOT, wait_for_rows

pytestmark = pytest.mark.engine

TIMING = ["setup_s", "query_s", "query_iqr_s", "loops", "unstable"]
SUITE = load_paths([ROOT / "cases"]).cases
CLI = [sys.executable, "-m", "crosscheck.cli"]


def without_timing(frame: pd.DataFrame) -> pd.DataFrame:
    return frame.drop(columns=TIMING).reset_index(drop=True)


def run_into(directory: Path, jobs: int = 1, resume: bool = False) -> pd.DataFrame:
    engines = [adapters.get("reference"), adapters.get("pymunk"), fakes.OffByOne()]
    store = ResultsStore(directory, resume=resume)
    run(SUITE[:40], engines, store, RunOptions(quick=True, jobs=jobs))
    store.close()
    return read_results(directory)


def test_jobs_do_not_change_results(tmp_path: Path) -> None:
    serial = run_into(tmp_path / "serial", jobs=1)
    parallel = run_into(tmp_path / "parallel", jobs=2)
    assert len(serial) > 200
    pd.testing.assert_frame_equal(without_timing(serial), without_timing(parallel))


def test_resume_drops_unfinished_pairs_and_half_lines(tmp_path: Path) -> None:
    full = run_into(tmp_path / "full")
    cut = tmp_path / "cut"
    run_into(cut)
    lines = (cut / "results.jsonl").read_text().splitlines(keepends=True)
    keep = len(lines) // 2 + 1  # ends in the middle of a case x engine pair
    (cut / "results.jsonl").write_text("".join(lines[:keep]) + lines[keep][:25])
    store = ResultsStore(cut, resume=True)
    assert 0 < len(store.done) < len(full) // 2
    store.close()
    resumed = run_into(cut, resume=True)
    pd.testing.assert_frame_equal(without_timing(full), without_timing(resumed))


def test_new_run_refuses_a_directory_with_results(tmp_path: Path) -> None:
    run_into(tmp_path / "run")
    with pytest.raises(StoreError, match="--resume"):
        ResultsStore(tmp_path / "run")


THREE_FILES = ("aabb.toml", "sphere.toml", "response.toml")
SMALL_TIMING = ("--samples", "3", "--timing-cases", "2")
"""A timing phase of two seconds or so, after the rows are written: the window the fast kill
lands in."""


def run_args(out: Path, files: tuple[str, ...], *extra: str) -> list[str]:
    return ["run", *(str(ROOT / "cases" / name) for name in files),
            "--engine", "reference", "--engine", "pymunk", "--engine", "pybullet",
            "--min-sample", "0.005", "--jobs", "1", "--out", str(out), *extra]


def sigkill_and_resume(tmp_path: Path, files: tuple[str, ...], extra: tuple[str, ...],
                       kills: int, pause: tuple[float, float], in_process: bool) -> None:
    """Run ``files`` uninterrupted; run them again, SIGKILL the run ``kills`` times, each a
    random ``pause`` after rows are there, and resume it each time: the rows must be the
    uninterrupted run's apart from timing.  With ``in_process`` the uninterrupted run and
    the last resume run in this process (the killed runs are always processes of their own)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    reference, killed = tmp_path / "uninterrupted", tmp_path / "killed"
    if in_process:
        assert main(run_args(reference, files, *extra)) == 0
    else:
        subprocess.run([*CLI, *run_args(reference, files, *extra)], env=env, check=True,
                       capture_output=True)
    rng = random.Random(7)
    process = subprocess.Popen([*CLI, *run_args(killed, files, *extra)], env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for kill in range(kills):
        wait_for_rows(killed / "results.jsonl")
        time.sleep(rng.uniform(*pause))
        process.send_signal(signal.SIGKILL)
        process.wait()
        assert read_run_info(killed).finished is None, "the run finished before it was killed"
        if in_process and kill == kills - 1:
            assert main(["run", "--resume", str(killed)]) == 0
            break
        process = subprocess.Popen([*CLI, "run", "--resume", str(killed)], env=env,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    else:
        assert process.wait(timeout=300) == 0
    pd.testing.assert_frame_equal(without_timing(read_results(reference)),
                                  without_timing(read_results(killed)))
    info = json.loads((killed / "run.json").read_text())
    assert info["resumed"] and info["finished"]


def test_sigkill_and_resume_loses_and_duplicates_nothing(tmp_path: Path) -> None:
    sigkill_and_resume(tmp_path, ("sphere.toml",), SMALL_TIMING, kills=1, pause=(0.0, 0.2),
                       in_process=True)


@pytest.mark.slow
def test_three_sigkills_on_three_files_and_resume_lose_and_duplicate_nothing(
        tmp_path: Path) -> None:
    sigkill_and_resume(tmp_path, THREE_FILES, (), kills=3, pause=(0.3, 1.2), in_process=False)
