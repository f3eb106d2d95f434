"""Every command's output reads whole at 80 columns in a file: piped (not a terminal) with
COLUMNS=80, no line is wider than 80 characters and no header or cell is cut with an
ellipsis; a bare ``--out`` name goes under reports/; fuzz says its progress on stderr.

The help of every command and ``engines --settings`` are checked in ``test_help.py``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from crosscheck.cli.fuzz import GROUP_COLUMNS
from crosscheck.report.advise.recommend import Envelope, advise
from crosscheck.report.advise.table import worst_text
from crosscheck.results.run import read_results, read_run
from crosscheck.studies.fuzz import CHUNK
from tests.conftest import ROOT

ELLIPSIS = "\u2026"
SPHERES = str(ROOT / "cases" / "sphere.toml")


def piped(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    """``crosscheck ARGS`` run in ``cwd`` with its stdout and stderr pipes, at COLUMNS=80."""
    env = {**os.environ, "COLUMNS": "80", "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "crosscheck.cli", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, check=True)


def unreadable(text: str) -> list[str]:
    """The lines of ``text`` wider than 80 characters or cut with an ellipsis."""
    return [line for line in text.splitlines() if len(line) > 80 or ELLIPSIS in line]


def flat(text: str) -> str:
    """``text`` with its line breaks undone (lines wrap at spaces)."""
    return " ".join(text.split())


@pytest.fixture(scope="module")
def small_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """A quick run of the sphere cases on two engines, ``--out small`` from an empty folder:
    that folder and the run's stdout."""
    here = tmp_path_factory.mktemp("here")
    done = piped(["run", SPHERES, "--quick", "--engine", "reference", "--engine", "pymunk",
                  "--out", "small"], here)
    return here, done.stdout


@pytest.mark.engine
def test_a_run_reads_at_80_columns_and_a_bare_out_name_goes_under_reports(
        small_run: tuple[Path, str]) -> None:
    here, printed = small_run
    assert unreadable(printed) == []
    assert (here / "reports" / "small" / "results.jsonl").is_file()
    assert sorted(p.name for p in here.iterdir()) == ["reports"]
    assert "reports/small" in printed.splitlines()[0]  # the first line says where it went


@pytest.mark.engine
def test_advise_reads_at_80_columns_with_every_worst_answer_whole(
        small_run: tuple[Path, str]) -> None:
    here, _ = small_run
    printed = piped(["advise", "reports/small", "--tolerance", "1e-12"], here).stdout
    assert unreadable(printed) == []
    advice = advise(read_run(here / "reports" / "small"), Envelope(tolerance=1e-12))
    for engine in advice.ranking + advice.baselines:
        assert engine.engine in printed.split()
        assert worst_text(engine) in flat(printed) or worst_text(engine) == "-"


@pytest.mark.engine
def test_compare_and_repro_read_at_80_columns(small_run: tuple[Path, str]) -> None:
    here, _ = small_run
    compared = piped(["compare", "reports/small", "reports/small", "--out", "cmp"], here)
    assert unreadable(compared.stdout) == [] and unreadable(compared.stderr) == []
    assert (here / "reports" / "cmp" / "compare.html").is_file()
    case_id = str(read_results(here / "reports" / "small")["case_id"].iloc[0])
    scripts = piped(["repro", "reports/small", case_id, "--out", "./r.py"], here).stdout
    assert unreadable(scripts) == [] and (here / "r.py").is_file()


def test_validate_reads_at_80_columns() -> None:
    assert unreadable(piped(["validate"], ROOT).stdout) == []


def test_fuzz_reads_at_80_columns_and_says_its_progress_on_stderr(tmp_path: Path) -> None:
    done = piped(["fuzz", "--kind", "sphere", "--n", str(2 * CHUNK), "--seed", "1",
                  "--engine", "reference", "--engine", "reference-f32", "--out", "fz"],
                 tmp_path)
    assert unreadable(done.stdout) == []
    header = next(line for line in done.stdout.splitlines() if line.startswith("engine"))
    assert header.split() == list(GROUP_COLUMNS)
    assert (tmp_path / "reports" / "fz" / "findings.csv").is_file()
    # piped: a plain line at the start, then at each tenth passed (two chunks: half, all),
    # and where the machine is slow a line after every ten quiet seconds (no new count)
    progress = [line for line in done.stderr.splitlines() if line.startswith("fuzz case")]
    assert progress[0] == f"fuzz case x engine: {4 * CHUNK} to go"
    counts = [line.split(" (")[0] for line in progress[1:]]
    assert list(dict.fromkeys(c for c in counts if not c.endswith(f" 0/{4 * CHUNK}"))) == [
        f"fuzz case x engine: {2 * CHUNK}/{4 * CHUNK}",
        f"fuzz case x engine: {4 * CHUNK}/{4 * CHUNK}"]
