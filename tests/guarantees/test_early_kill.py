"""A run killed at any moment, even before run.json exists, is resumed, or ``--resume`` says
clearly how to restart it; no state leaves the folder unusable."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterable
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.run import read_results
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.conftest import ROOT, sphere, wait_until

TIMING = ["setup_s", "query_s", "query_iqr_s", "loops", "unstable"]
CLI = [sys.executable, "-m", "crosscheck.cli"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
FILES = [str(ROOT / "cases" / name) for name in ("aabb.toml", "sphere.toml")]


def command(out: Path) -> list[str]:
    return [*CLI, "run", *FILES, "--engine", "reference", "--engine", "pymunk", "--quick",
            "--jobs", "1", "--out", str(out)]


def rows(directory: Path) -> pd.DataFrame:
    return read_results(directory).drop(columns=TIMING).reset_index(drop=True)


def resume_or_restart(out: Path) -> str:
    """``--resume``; if it says the run never started, start it again as it advises."""
    resumed = subprocess.run([*CLI, "run", "--resume", str(out)], env=ENV, capture_output=True,
                             text=True, timeout=300)
    if resumed.returncode == 0:
        return "resumed"
    message = " ".join(resumed.stderr.split())
    assert resumed.returncode == 2 and "Traceback" not in resumed.stderr, resumed.stderr
    assert "start it again with the same command and --out" in message, message
    subprocess.run(command(out), env=ENV, check=True, capture_output=True, timeout=300)
    return "restarted"


def wait_for(moment: float | str, out: Path) -> None:
    """Sleep ``moment`` seconds, or until the run has made ``moment`` (a file in ``out``;
    results.jsonl: with some rows in it)."""
    if isinstance(moment, float):
        time.sleep(moment)
        return
    path = out if moment == "folder" else out / moment
    wait_until(lambda: path.exists() and (moment != "results.jsonl" or path.stat().st_size > 0),
               f"the run never made {moment}", poll_s=0.001)


def state(out: Path) -> str:
    """What a kill left: no folder, a folder without run.json, an unfinished or finished run."""
    if not out.exists():
        return "no folder"
    if not (out / "run.json").exists():
        return "no run.json"
    return "finished" if json.loads((out / "run.json").read_text())["finished"] else "unfinished"


@pytest.mark.slow
@pytest.mark.engine
def test_sigkill_at_any_moment_then_resume_gives_the_uninterrupted_rows(tmp_path: Path) -> None:
    reference = tmp_path / "uninterrupted"
    subprocess.run(command(reference), env=ENV, check=True, capture_output=True, timeout=300)
    expected = rows(reference)
    assert len(expected) > 100
    ways, states = [], []
    for i, moment in enumerate([0.0, 0.05, 0.1, 0.5, "folder", "run.json", "results.jsonl"]):
        out = tmp_path / f"killed-{i}"
        process = subprocess.Popen(command(out), env=ENV, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        wait_for(moment, out)
        process.send_signal(signal.SIGKILL)
        process.wait()
        states.append(state(out))
        ways.append(resume_or_restart(out))
        pd.testing.assert_frame_equal(expected, rows(out))
        assert json.loads((out / "run.json").read_text())["finished"]
    assert ways[0] == "restarted"  # killed within 100 ms: nothing but perhaps the folder
    assert "unfinished" in states, states  # and at least once in the middle of the run


def test_resume_of_a_folder_killed_before_run_json_says_how_to_restart(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    out.mkdir()
    (out / ".lock").write_text("pid 1")  # all that a run killed at its start leaves
    assert main(["run", "--resume", str(out)]) == 2
    message = " ".join(capsys.readouterr().err.split())
    assert "no run.json" in message and "killed before it started" in message
    assert f"--out {out}" in message and "Errno" not in message
    case_file = str(ROOT / "cases" / "sphere.toml")
    assert main(["run", case_file, "--quick", "--engine", "reference", "--out", str(out)]) == 0
    assert len(read_results(out)) > 0  # the folder was reused: a restart, as advised


def test_resume_of_a_folder_never_made_says_how_to_start(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--resume", str(tmp_path / "never")]) == 2
    message = " ".join(capsys.readouterr().err.split())
    assert "no such folder" in message and "start it again" in message
    assert f"{tmp_path / 'never'} does not exist; check the path" in message


class Recording(ResultsStore):
    """A store that notes which of its files are written, in order."""

    def __init__(self, directory: Path) -> None:
        super().__init__(directory)
        self.writes: list[str] = []

    def add_cases(self, cases: Iterable[AnyCase]) -> None:
        self.writes.append("cases.jsonl")
        super().add_cases(cases)

    def write_run_info(self, info: RunInfo) -> None:
        self.writes.append("run.json")
        super().write_run_info(info)


def test_run_json_is_written_after_the_cases(tmp_path: Path) -> None:
    """A folder with a run.json always holds the cases to resume (a kill between the two)."""
    out = tmp_path / "run"
    cases = [sphere(0.0, 2.0, id="apart"), sphere(0.0, 0.5, id="overlap")]
    engines = [fakes.AlwaysRight()]
    options = RunOptions(quick=True, isolate=False)
    store = Recording(out)
    launch(store, cases, engines, options, new_info(out, "test", options, engines, cases))
    assert store.writes[0] == "cases.jsonl" and "run.json" in store.writes
