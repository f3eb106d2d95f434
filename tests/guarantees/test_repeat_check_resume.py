"""The repeat check loses nothing: interrupted (Ctrl-C) in the middle, the run keeps every
verdict row and every second answer received; resumed, it asks the pairs not asked yet,
never one asked already, and drops a half-written last line of ``repeats.jsonl``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from crosscheck.cases.load import load_paths
from crosscheck.core.options import RunOptions
from crosscheck.results.repeats import FILE, read_repeats
from crosscheck.results.run import read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run import repeat
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.conftest import ROOT

CASES = load_paths([ROOT / "cases" / "sphere.toml"]).cases[:6]
ENGINES = [fakes.DriftsWithEachQuery(), fakes.OffByOne(), fakes.AlwaysRight()]
OPTIONS = RunOptions(quick=True, repeat_check=True)
ASKED = 2
"""Cases whose second answers come back before the interruption."""


@pytest.fixture(autouse=True)
def one_case_a_batch(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each case its own batch (a fresh worker each), so the check comes back case by case
    and is interrupted between two (a run's batches hold up to BATCH_CASES cases)."""
    monkeypatch.setattr(repeat, "BATCH_CASES", 1)


def interrupting(name: str, total: int) -> Callable[[int], None]:
    """A phase's progress that stops the run (as Ctrl-C does) once the repeat check has had
    :data:`ASKED` cases back."""
    received = []

    def progress(n: int) -> None:
        received.append(n)
        if name == "repeat check" and len(received) == ASKED:
            raise KeyboardInterrupt
    return progress


def test_an_interrupted_repeat_check_keeps_every_answer_and_resumes_the_rest(
        tmp_path: Path) -> None:
    folder = tmp_path / "run"
    with pytest.raises(KeyboardInterrupt):
        launch(ResultsStore(folder), CASES, ENGINES, OPTIONS,
               new_info(folder, "test", OPTIONS, ENGINES, CASES), phases=interrupting)
    stopped = read_run(folder)
    assert stopped.info.finished is None and stopped.info.repeat_check is None
    assert len(stopped.results.drop_duplicates(["case_id", "engine"])) == len(CASES) * 3
    kept = (folder / FILE).read_text().splitlines(keepends=True)
    assert len(kept) == 2 * ASKED  # two disagreeing engines per case: fake-drifts, fake-off
    with (folder / FILE).open("a") as handle:
        handle.write('{"case_id": "sphere-')  # a half-written last line of a killed run

    store = ResultsStore(folder, resume=True)
    assert len(store.repeated) == 2 * ASKED
    info = launch(store, CASES, ENGINES, stopped.info.options, stopped.info.resume()).info
    lines = (folder / FILE).read_text().splitlines(keepends=True)
    assert lines[:len(kept)] == kept  # the pairs asked before were not asked again
    assert len(lines) == len(read_repeats(folder)) == 2 * len(CASES)  # each pair once
    assert info.repeat_check is not None and info.repeat_check["pairs"] == 2 * len(CASES)
    final = read_run(folder).results
    asked = final[final["repeat_status"] != ""]
    assert set(asked["engine"]) == {"fake-drifts", "fake-off"}
    assert final[final["engine"] == "fake-drifts"]["nondeterministic"].sum() > 0
    assert not final[final["engine"] == "fake-off"]["nondeterministic"].any()


def test_a_resumed_run_that_finished_its_check_asks_nothing_again(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    info = launch(ResultsStore(folder), CASES, ENGINES, OPTIONS,
                  new_info(folder, "test", OPTIONS, ENGINES, CASES)).info
    before = (folder / FILE).read_text()
    again = launch(ResultsStore(folder, resume=True), CASES, ENGINES, OPTIONS,
                   info.resume()).info
    assert (folder / FILE).read_text() == before
    assert again.repeat_check is not None and info.repeat_check is not None
    assert again.repeat_check["pairs"] == info.repeat_check["pairs"]
    assert again.repeat_check["seconds"] >= info.repeat_check["seconds"]
