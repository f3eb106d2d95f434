"""A disk that fills while results are written stops the run with a clear message; the rows
already written stay intact and loadable, and ``--resume`` finishes the run once there is
space.  The full disk is simulated in a subprocess: the store's results
file is opened through a writer that takes a budget of characters, writes what fits of the
write that exceeds it (a half line, as a real disk leaves) and raises ENOSPC."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.results.run import read_results
from tests.conftest import ROOT

pytestmark = pytest.mark.engine

TIMING = ["setup_s", "query_s", "query_iqr_s", "loops", "unstable"]
CLI = [sys.executable, "-m", "crosscheck.cli"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
FILES = [str(ROOT / "cases" / name) for name in ("aabb.toml", "sphere.toml")]

FULL_DISK = textwrap.dedent("""
    import errno
    import sys

    import crosscheck.results.store as store
    from crosscheck.cli import main

    class FullDisk:
        def __init__(self, handle, budget):
            self.handle, self.left = handle, budget

        def write(self, text):
            if len(text) > self.left:
                self.handle.write(text[: self.left])
                self.handle.flush()
                self.left = 0
                raise OSError(errno.ENOSPC, "No space left on device")
            self.left -= len(text)
            return self.handle.write(text)

        def flush(self):
            self.handle.flush()

        def close(self):
            self.handle.close()

    opened = store.open_append
    store.open_append = lambda path: FullDisk(opened(path), int(sys.argv[1]))
    sys.exit(main(sys.argv[2:]))
""")


def run_args(out: Path) -> list[str]:
    return ["run", *FILES, "--engine", "reference", "--engine", "pymunk", "--quick",
            "--jobs", "1", "--out", str(out)]


def rows(directory: Path) -> pd.DataFrame:
    return read_results(directory).drop(columns=TIMING).reset_index(drop=True)


@pytest.mark.slow
def test_a_full_disk_stops_the_run_keeps_the_rows_and_resume_finishes(tmp_path: Path) -> None:
    reference = tmp_path / "uninterrupted"
    subprocess.run([*CLI, *run_args(reference)], env=ENV, check=True, capture_output=True)
    expected = rows(reference)
    budget = len((reference / "results.jsonl").read_text(encoding="utf-8")) // 3
    out = tmp_path / "full"
    full = subprocess.run([sys.executable, "-c", FULL_DISK, str(budget), *run_args(out)],
                          env=ENV, capture_output=True, text=True, timeout=300)
    message = " ".join(full.stderr.split())
    assert full.returncode == 1, full.stderr
    assert "Traceback" not in full.stderr
    assert "No space left on device" in message and "results.jsonl" in message
    assert f"crosscheck run --resume {out}" in message
    lines = (out / "results.jsonl").read_text(encoding="utf-8").splitlines()
    assert json.loads(lines[0]) and not lines[-1].endswith("}")  # a half line at the end
    kept = rows(out)
    assert 0 < len(kept) < len(expected)
    keys = ["case_id", "engine", "quantity"]
    same = expected.set_index(keys).loc[kept.set_index(keys).index]  # intact and loadable
    pd.testing.assert_frame_equal(kept.set_index(keys), same)
    assert json.loads((out / "run.json").read_text())["finished"] is None

    resumed = subprocess.run([*CLI, "run", "--resume", str(out)], env=ENV, capture_output=True,
                             text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    pd.testing.assert_frame_equal(expected, rows(out))
