"""The speed section of a run without its timing phase (``crosscheck run --quick``): one line
saying why nothing is drawn, not an open fold under a long paragraph per kind."""

from __future__ import annotations

from pathlib import Path

import pytest

from crosscheck.core.options import RunOptions
from crosscheck.report.render import render
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests.conftest import aabb, sphere
from tests.fakes import AlwaysRight, OffByOne


@pytest.fixture(scope="module")
def untimed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A quick run (no timing phase) of two fakes on spheres and boxes, rendered."""
    folder = tmp_path_factory.mktemp("untimed") / "run"
    cases = [sphere(0.0, 2.0 + i / 4, id=f"s{i}") for i in range(3)]
    cases += [aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.5, 0.0, 0.0], [1.0, 1.0, 1.0], id="b")]
    options, engines = RunOptions(quick=True, isolate=False), [AlwaysRight(), OffByOne()]
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    render(folder)
    return folder


def test_the_speed_section_of_an_untimed_run_is_one_line(untimed: Path) -> None:
    html = (untimed / "report.html").read_text(encoding="utf-8")
    start = html.index("<h2>Speed against error</h2>")
    section = html[start:html.index("<h2", start + 1)]
    assert section.count("<p") == 1, section
    assert "<details" not in section and "<table" not in section
    assert "Timing was off for this run (--quick)" in section
    assert "cheapest" not in section and "fastest first" not in section
