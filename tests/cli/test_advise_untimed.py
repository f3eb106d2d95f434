"""``crosscheck advise`` on a run that timed nothing (``--quick``) orders its passing engines
by no cost, and says so: never "cheapest first"."""

from __future__ import annotations

from pathlib import Path

import pytest

from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests.conftest import sphere
from tests.fakes import AlwaysRight, OffByOne


@pytest.fixture(scope="module")
def untimed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A quick run (no timing phase) of an engine always right and one always off."""
    folder = tmp_path_factory.mktemp("untimed") / "run"
    cases = [sphere(0.0, 2.0 + i / 4, id=f"s{i}") for i in range(3)]
    options, engines = RunOptions(quick=True, isolate=False), [OffByOne(), AlwaysRight()]
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    return folder


def test_passing_engines_of_an_untimed_run_are_not_said_cheapest_first(
        untimed: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(untimed)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "passing: fake-right (none timed: in run order)" in out
    assert "cheapest first" not in out
