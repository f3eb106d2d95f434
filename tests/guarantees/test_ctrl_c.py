"""Ctrl-C stops an isolated run cleanly: the finished rows are kept, no worker's death is
taken for a crash, the resume hint is printed and ``--resume`` finishes the run; also while
instructions are counted (the counts so far kept, no counting worker left behind).  (In-process
runs: tests/guarantees/test_inprocess_hangs.py.)"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.results.counts import FILE as COUNTS
from crosscheck.results.counts import read_counts
from crosscheck.results.run import read_results
from crosscheck.run import callgrind
from tests.conftest import ROOT, ctrl_c_delivered, wait_for_rows

pytestmark = pytest.mark.engine

CLI = [sys.executable, "-m", "crosscheck.cli"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def ctrl_c_and_resume(tmp_path: Path, files: tuple[str, ...], extra: tuple[str, ...],
                      in_process: bool) -> None:
    """Ctrl-C a run of ``files`` (reference and pymunk) once 20 rows are written, then resume
    it: from the command line, or with ``in_process`` in this process."""
    out = tmp_path / "run"
    paths = [ROOT / "cases" / name for name in files]
    args = [*CLI, "run", *map(str, paths), "--engine", "reference", "--engine", "pymunk",
            "--min-sample", "0.01", "--out", str(out), *extra]
    process = subprocess.Popen(args, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, start_new_session=True,
                               preexec_fn=ctrl_c_delivered)
    wait_for_rows(out / "results.jsonl", rows=20)
    os.killpg(process.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole group
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130
    assert f"crosscheck run --resume {out}" in stderr.replace("\n", "")
    kept = read_results(out)
    assert len(kept) >= 20
    assert not (kept["status"] == "crash").any(), "a worker's Ctrl-C was taken for a crash"
    if in_process:
        assert main(["run", "--resume", str(out)]) == 0
    else:
        resumed = subprocess.run([*CLI, "run", "--resume", str(out)], env=ENV,
                                 capture_output=True, text=True, timeout=300)
        assert resumed.returncode == 0, resumed.stderr
    final = read_results(out)
    cases = len(load_paths(paths).cases)
    assert len(final.drop_duplicates(["case_id", "engine"])) == cases * 2


def test_ctrl_c_stops_cleanly_keeps_rows_and_prints_the_resume_hint(tmp_path: Path) -> None:
    ctrl_c_and_resume(tmp_path, ("sphere.toml",), ("--samples", "3", "--timing-cases", "2"),
                      in_process=True)


@pytest.mark.slow
def test_ctrl_c_of_a_timed_two_file_run_and_a_resume_from_the_command_line(
        tmp_path: Path) -> None:
    ctrl_c_and_resume(tmp_path, ("sphere.toml", "aabb.toml"), (), in_process=False)


def test_ctrl_c_after_the_last_row_exits_130_and_a_resume_renders_the_report(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """A Ctrl-C that lands after the last row (while the report is written) is still a clean
    stop: exit 130 with the resume hint, never a traceback; the resume then has no row left
    to run and writes the report."""
    import crosscheck.report.render as report

    out = tmp_path / "run"
    real = report.render

    def interrupted(directory: Path, progress: object = None) -> dict[str, Path]:
        raise KeyboardInterrupt

    monkeypatch.setattr(report, "render", interrupted)
    args = ["run", str(ROOT / "cases" / "sphere.toml"), "--engine", "reference", "--quick",
            "--out", str(out)]
    assert main(args) == 130
    assert f"crosscheck run --resume {out}" in capsys.readouterr().err.replace("\n", "")
    rows = len(read_results(out))
    assert not (out / "report.html").exists()
    monkeypatch.setattr(report, "render", real)
    assert main(["run", "--resume", str(out)]) == 0
    assert len(read_results(out)) == rows
    assert (out / "report.html").exists()


def counting_workers(group: int) -> list[str]:
    """The command lines of the processes of process group ``group`` running valgrind."""
    found = []
    for proc in Path("/proc").iterdir():
        try:
            if proc.name.isdigit() and os.getpgid(int(proc.name)) == group:
                line = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode()
                found += [line] if "valgrind" in line or "cost_worker" in line else []
        except (OSError, ProcessLookupError):
            continue  # gone meanwhile
    return found


@pytest.mark.skipif(callgrind.missing() is not None, reason=str(callgrind.missing()))
def test_ctrl_c_while_counting_keeps_the_counts_stops_valgrind_and_resume_counts_the_rest(
        tmp_path: Path) -> None:
    out = tmp_path / "run"
    args = [*CLI, "run", str(ROOT / "cases" / "sphere.toml"), "--engine", "reference",
            "--engine", "pymunk", "--samples", "3", "--min-sample", "0.001",
            "--timing-cases", "3", "--timer", "instructions", "--out", str(out)]
    process = subprocess.Popen(args, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, start_new_session=True,
                               preexec_fn=ctrl_c_delivered)
    wait_for_rows(out / COUNTS, rows=1)
    os.killpg(process.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole group
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert not counting_workers(process.pid), "a counting worker outlived the run"
    kept = len(read_counts(out))
    assert kept >= 1
    resumed = subprocess.run([*CLI, "run", "--resume", str(out)], env=ENV,
                             capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    cost = json.loads((out / "run.json").read_text())["timing"]["cost"]
    assert cost["failed"] == 0 and len(read_counts(out)) == cost["sampled"] > kept
    assert cost["counted"] == len(read_counts(out))  # this run's and the stopped one's
