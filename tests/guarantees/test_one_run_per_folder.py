"""One run per folder: a second run into a folder in use is refused (a lock), in the library
and from the command line, with a clear error and no harm to the first."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from crosscheck.results.store import ResultsStore, StoreError
from tests.conftest import ROOT, wait_for_rows

CLI = [sys.executable, "-m", "crosscheck.cli"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def test_a_second_run_into_the_same_directory_is_refused(tmp_path: Path) -> None:
    first = ResultsStore(tmp_path / "run")
    with pytest.raises(StoreError, match="another crosscheck run"):
        ResultsStore(tmp_path / "run", resume=True)
    first.close()
    assert not (tmp_path / "run" / ".lock").exists()  # a closed run leaves no lock file
    ResultsStore(tmp_path / "run", resume=True).close()  # free once the first is done


def test_a_lock_file_removed_by_a_finishing_run_is_taken_again_on_the_new_file(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # the run that held the lock finishes (and removes the file) between this run's open and
    # its flock: this run must end up holding the file at the path, not the removed one
    import fcntl

    import crosscheck.results.store as store

    real, calls = fcntl.flock, []

    def finishing_holder(handle: object, operation: int) -> None:
        calls.append(operation)
        if len(calls) == 1:
            (tmp_path / "run" / ".lock").unlink()
        real(handle, operation)  # type: ignore[arg-type]

    (tmp_path / "run").mkdir()
    monkeypatch.setattr(store.fcntl, "flock", finishing_holder)
    held = ResultsStore(tmp_path / "run")
    try:
        assert len(calls) == 2  # locked again, on the new file
        assert (tmp_path / "run" / ".lock").read_text() == f"pid {os.getpid()}"
        monkeypatch.setattr(store.fcntl, "flock", real)
        with pytest.raises(StoreError, match="another crosscheck run"):
            ResultsStore(tmp_path / "run", resume=True)
    finally:
        held.close()


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
