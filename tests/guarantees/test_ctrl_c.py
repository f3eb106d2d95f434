"""Ctrl-C stops an isolated run cleanly: the finished rows are kept, no worker's death is
taken for a crash, the resume hint is printed and ``--resume`` finishes the run.  (In-process
runs: tests/guarantees/test_inprocess_hangs.py.)"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

from crosscheck.cases.load import load_paths
from crosscheck.results.store import read_results
from tests.conftest import ROOT, wait_for_rows

CLI = [sys.executable, "-m", "crosscheck.cli"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


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
