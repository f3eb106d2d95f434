"""Nothing computed is lost when the report fails: a run whose report cannot be rendered
keeps every result row, exits 1 and names ``crosscheck report DIR`` to retry, never a
traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

import crosscheck.cli.run as cli_run
import crosscheck.report.render as report_render
from crosscheck.cli import main
from crosscheck.results.run import read_results
from tests.conftest import ROOT

SPHERES = str(ROOT / "cases" / "sphere.toml")


def test_a_report_that_fails_to_render_keeps_the_results(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(directory: Path, progress: object = None) -> dict[str, Path]:
        raise ValueError("a fault in the report")

    monkeypatch.setattr(cli_run, "render", broken, raising=False)
    monkeypatch.setattr(report_render, "render", broken)
    out = tmp_path / "run"
    assert main(["run", SPHERES, "--quick", "--engine", "reference", "--out", str(out)]) == 1
    message = capsys.readouterr().err
    assert "a fault in the report" in message and f"crosscheck report {out}" in message
    assert "Traceback" not in message
    assert len(read_results(out)) > 0
