"""A run is an object: the :class:`~crosscheck.results.run.Run` that ``launch`` builds is the
folder read back, the rows of ``results.jsonl`` are parsed once per launch (and once per
``crosscheck run``, report and check included), every JSON-lines file of a run goes through
the one reader, and the CLI's summary is printed from the object, not from ``summary.csv``."""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from crosscheck.cli import main
from crosscheck.cli.console import print_summary
from crosscheck.core.options import RunOptions
from crosscheck.core.values import decode
from crosscheck.report import render as render_module
from crosscheck.results import counts, jsonlines, repeats, scene_facts, series, timings
from crosscheck.results import run as run_module
from crosscheck.results.run import DECODED, Run, read_results, read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.conftest import sphere
from tests.results.parsing import counting

CASES = [sphere(0.0, 1.0 + i / 4, id=f"s{i}") for i in range(4)]
ENGINES = [fakes.AlwaysRight(), fakes.OffByOne(), fakes.DriftsWithEachQuery()]
OPTIONS = RunOptions(quick=False, isolate=False, pin=False, repeat_check=True, timing_cases=1,
                     samples=2, min_sample_s=1e-4)
"""Every phase that appends after the verdicts: the repeat check (fake-off and fake-drifts
disagree) and the timing phase (one case per engine, two samples)."""


@pytest.fixture(scope="module")
def launched(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Run, Counter[str]]]:
    """One launch of every phase, and the reader's calls during it."""
    folder = tmp_path_factory.mktemp("run") / "run"
    with pytest.MonkeyPatch.context() as patch:
        calls = counting(patch)
        run = launch(ResultsStore(folder), CASES, ENGINES, OPTIONS,
                     new_info(folder, "test", OPTIONS, ENGINES, CASES))
        assert len(run.results)  # asked for inside the count, as render and the summary do
    yield run, calls


def test_the_run_launch_builds_is_the_folder_read_back(
        launched: tuple[Run, Counter[str]]) -> None:
    run, _ = launched
    stored = read_run(run.directory)
    assert run.info == stored.info and run.info.finished is not None
    assert run.cases == stored.cases and list(run.cases) == [c.id for c in CASES]
    assert run.format_version == stored.format_version
    pd.testing.assert_frame_equal(run.results, stored.results)
    pd.testing.assert_frame_equal(run.results, read_results(run.directory))
    assert run.results["nondeterministic"].any()  # the repeat check's columns were joined
    timed = run.results.merge(timings.read_timings(run.directory), on=["case_id", "engine"])
    assert len(timed) and (timed["query_s"] == timed["median_s"]).all()  # and the timings


def test_a_launch_parses_results_jsonl_once(launched: tuple[Run, Counter[str]]) -> None:
    calls = launched[1]
    assert calls["results.jsonl"] == 1
    assert calls["cases.jsonl"] == 0  # the cases were in memory: none validated again
    assert calls["repeats.jsonl"] >= 1 and calls["timings.jsonl"] >= 1  # joined again


def test_the_values_are_decoded_once_into_columns(
        launched: tuple[Run, Counter[str]], monkeypatch: pytest.MonkeyPatch) -> None:
    run = launched[0]
    again = read_run(run.directory)
    once = Counter(t for column in DECODED for t in set(again.results[column]))
    calls: Counter[str] = Counter()
    monkeypatch.setattr(run_module, "decode", lambda text: calls.update([text]) or decode(text))
    values = again.decoded
    assert values is again.decoded and calls == once  # each distinct text of a column once
    for text, column in DECODED.items():
        assert [json.dumps(v) for v in values[column]] == [
            json.dumps(decode(t)) for t in again.results[text]]
    assert values.index.equals(again.results.index)


def test_the_summary_is_printed_from_the_run_without_summary_csv(
        launched: tuple[Run, Counter[str]], capsys: pytest.CaptureFixture[str]) -> None:
    run, _ = launched
    assert not (run.directory / "summary.csv").exists()  # launch renders nothing
    print_summary(run)
    out = "".join(capsys.readouterr().out.split())  # the terminal wraps the long path
    assert f"summaryof{run.directory}" in out
    assert all(engine.name in out for engine in ENGINES)


def test_the_one_reader_leaves_out_a_half_written_last_line(tmp_path: Path) -> None:
    path = tmp_path / "rows.jsonl"
    path.write_text('{"a": 1}\n\n{"a": [2, 3]}\n{"a": 4, "b', encoding="utf-8")
    assert jsonlines.read_lines(path) == [('{"a": 1}', {"a": 1}), ('{"a": [2, 3]}', {"a": [2, 3]})]
    assert jsonlines.parse_lines(path) == [{"a": 1}, {"a": [2, 3]}]
    assert jsonlines.read_lines(tmp_path / "none.jsonl") == []


def copied(run: Run, folder: Path) -> Path:
    """A copy of the run's files in ``folder`` (a new path: no reader's cache knows it)."""
    folder.mkdir()
    for path in run.directory.iterdir():
        if path.is_file():
            (folder / path.name).write_bytes(path.read_bytes())
    return folder


def test_every_file_of_a_run_is_read_by_the_one_reader(
        launched: tuple[Run, Counter[str]], monkeypatch: pytest.MonkeyPatch,
        tmp_path: Path) -> None:
    folder = copied(launched[0], tmp_path / "copy")
    calls = counting(monkeypatch)
    assert len(read_run(folder).results)
    for read in (repeats.read_repeats, counts.read_counts, series.read_series,
                 scene_facts.read_facts, timings.read_timings):
        read(folder)
    assert {"results.jsonl", "cases.jsonl", repeats.FILE, counts.FILE, series.FILE,
            scene_facts.FILE, timings.FILE} <= set(calls)


def test_a_half_written_last_line_is_left_out_by_every_reader(
        launched: tuple[Run, Counter[str]], tmp_path: Path) -> None:
    run = launched[0]
    folder = copied(run, tmp_path / "killed")
    for name in ("results.jsonl", "cases.jsonl", repeats.FILE, timings.FILE):
        with (folder / name).open("a", encoding="utf-8") as handle:
            handle.write('{"case_id": "s')
    stored = read_run(folder)
    assert stored.cases == run.cases
    pd.testing.assert_frame_equal(stored.results, run.results)
    assert set(repeats.read_repeats(folder)) == set(repeats.read_repeats(run.directory))


def test_crosscheck_run_reads_its_rows_once_and_summarises_without_summary_csv(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    cases = tmp_path / "c.toml"
    cases.write_text("".join(
        f'[[case]]\nid = "c{i}"\ndescription = "d"\nkind = "sphere"\ndim = 2\n'
        f'a = {{ center = [0.0, 0.0], radius = 0.5 }}\n'
        f'b = {{ center = [{1 + i}.0, 0.0], radius = 0.5 }}\n\n' for i in range(2)))
    out = tmp_path / "out"
    calls = counting(monkeypatch)
    render = render_module.render

    def render_then_drop_summary(run: Any, progress: Any = None) -> dict[str, Path]:
        paths = render(run, progress)
        paths["summary"].unlink()  # the CLI's summary must not need the file
        return paths

    monkeypatch.setattr(render_module, "render", render_then_drop_summary)
    assert main(["run", str(cases), "--quick", "--engine", "reference", "--out", str(out),
                 "--junit", str(tmp_path / "junit.xml")]) == 0
    assert calls["results.jsonl"] == 1  # launch, report, summary and check share one read
    assert not (out / "summary.csv").exists() and (tmp_path / "junit.xml").exists()
    said = "".join(capsys.readouterr().out.split())  # the terminal wraps the long path
    assert f"summaryof{out}" in said and "reference" in said
    assert json.loads((out / "run.json").read_text())["finished"]
