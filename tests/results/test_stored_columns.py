"""A rendered run is read back from its stored columns (``results.parquet``) while they are up to
date with ``results.jsonl`` and the side files: the same table, in the same types, without
parsing a row; a run that grew since, a side file written after them, or a Parquet file
without the stamp (an older harness's) is read from ``results.jsonl`` as before."""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.core.options import RunOptions
from crosscheck.report.render import render
from crosscheck.results import stored, timings
from crosscheck.results.run import Run, read_results, read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.conftest import sphere
from tests.results.parsing import counting

CASES = [sphere(0.0, 1.0 + i / 4, id=f"s{i}") for i in range(3)]
ENGINES = [fakes.AlwaysRight(), fakes.OffByOne(), fakes.DriftsWithEachQuery()]
OPTIONS = RunOptions(quick=False, isolate=False, pin=False, repeat_check=True, timing_cases=1,
                     samples=2, min_sample_s=1e-4)
"""Every side file: the repeat check's columns (object text) and the timing phase's."""


@pytest.fixture(scope="module")
def rendered(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Run]:
    """A launched and rendered run (its table as parsed from ``results.jsonl``)."""
    folder = tmp_path_factory.mktemp("run") / "run"
    run = launch(ResultsStore(folder), CASES, ENGINES, OPTIONS,
                 new_info(folder, "test", OPTIONS, ENGINES, CASES))
    render(run)
    yield run


def copy(run: Run, folder: Path) -> Path:
    """The run folder copied with its files' times (a new path: no reader's cache knows it)."""
    shutil.copytree(run.directory, folder, copy_function=shutil.copy2)
    return folder


def test_an_up_to_date_parquet_gives_the_same_table_without_parsing_a_row(
        rendered: Run, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = copy(rendered, tmp_path / "copy")
    calls = counting(monkeypatch)
    again = read_run(folder)
    pd.testing.assert_frame_equal(again.results, rendered.results)  # values and dtypes
    pd.testing.assert_frame_equal(read_results(folder), rendered.results)
    assert again.from_stored and calls["results.jsonl"] == 0
    assert rendered.results["repeat_value"].map(type).eq(str).any()  # objects kept objects
    assert not rendered.from_stored  # the run that wrote the rows parsed them


def test_rows_appended_since_are_read_from_results_jsonl(
        rendered: Run, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = copy(rendered, tmp_path / "copy")
    lines = (folder / "results.jsonl").read_text(encoding="utf-8").splitlines(keepends=True)
    (folder / "results.jsonl").write_text("".join(lines[:-3]), encoding="utf-8")
    os.utime(folder / stored.FILE)  # written later, yet it counts more rows than the file
    calls = counting(monkeypatch)
    again = read_run(folder)
    assert len(again.results) == len(rendered.results) - 3
    assert not again.from_stored and calls["results.jsonl"] == 1


@pytest.mark.parametrize("name", ["run.json", "cases.jsonl", timings.FILE, "repeats.jsonl"])
def test_a_file_written_after_the_parquet_makes_it_stale(
        rendered: Run, tmp_path: Path, name: str) -> None:
    folder = copy(rendered, tmp_path / "copy")
    assert stored.read_results(folder) is not None
    later = (folder / stored.FILE).stat().st_mtime_ns + 1_000_000_000
    os.utime(folder / name, ns=(later, later))
    assert stored.read_results(folder) is None
    assert not read_run(folder).from_stored


def test_a_parquet_without_the_stamp_is_not_read_back(rendered: Run, tmp_path: Path) -> None:
    folder = copy(rendered, tmp_path / "copy")
    pd.read_parquet(folder / stored.FILE).to_parquet(folder / stored.FILE, index=False)
    assert stored.read_results(folder) is None
    (folder / stored.FILE).write_bytes(b"PAR1 cut short")
    assert stored.read_results(folder) is None
    pd.testing.assert_frame_equal(read_run(folder).results, rendered.results)


def test_render_rewrites_results_csv_only_when_missing_or_stale(
        rendered: Run, tmp_path: Path) -> None:
    folder = copy(rendered, tmp_path / "copy")
    csv, parquet = folder / "results.csv", folder / stored.FILE
    written = {path: path.stat().st_mtime_ns for path in (csv, parquet)}
    render(folder)
    assert {path: path.stat().st_mtime_ns for path in written} == written  # nothing changed
    csv.unlink()
    render(folder)
    assert csv.read_bytes() == (rendered.directory / "results.csv").read_bytes()
    earlier = (folder / timings.FILE).stat().st_mtime_ns - 1_000_000_000
    for path in (csv, parquet):  # both older than the timings: a side file changed since
        os.utime(path, ns=(earlier, earlier))
    render(folder)
    assert csv.stat().st_mtime_ns > earlier and parquet.stat().st_mtime_ns > earlier
    assert csv.read_bytes() == (rendered.directory / "results.csv").read_bytes()
