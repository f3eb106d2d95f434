"""The measurement tools: the report page from a relative path, set-up records merged."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from tools import measure_report, measure_setup


def test_a_relative_run_folder_gives_an_absolute_page_a_browser_can_open(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "reports" / "r1").mkdir(parents=True)
    (tmp_path / "reports" / "r1" / "report.html").write_text("<html></html>")
    monkeypatch.chdir(tmp_path)
    for given in (Path("reports/r1"), Path("reports/r1/report.html")):
        page = measure_report.page_of(given)
        assert page.is_absolute() and page.as_uri().endswith("/reports/r1/report.html")
    with pytest.raises(SystemExit, match="does not exist"):
        measure_report.page_of(Path("reports/r2"))


def test_set_up_records_are_merged_into_the_file(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    output = tmp_path / "setup.json"
    output.write_text(json.dumps({"make test": {"seconds": 300.0}}))

    def measured(steps: list[str], pip_cache: bool) -> dict[str, dict[str, Any]]:
        return {step: {"seconds": 90.0, "pip_cache": pip_cache} for step in steps}

    monkeypatch.setattr(measure_setup, "measure", measured)
    assert measure_setup.main(["--output", str(output)]) == 0
    assert json.loads(output.read_text()) == {
        "make test": {"seconds": 300.0}, "make venv": {"seconds": 90.0, "pip_cache": False}}


def test_a_failed_step_is_not_recorded(tmp_path: Path) -> None:
    readings: list[float] = []

    def clock() -> float:  # injected time: 1.5 s between the readings around each command
        readings.append(1.5 * len(readings))
        return readings[-1]

    assert measure_setup.timed(["false"], tmp_path, {}, clock) is None
    readings.clear()
    seconds = measure_setup.timed(["true"], tmp_path, {"PATH": "/usr/bin:/bin"}, clock)
    assert seconds == 1.5 and len(readings) == 2
