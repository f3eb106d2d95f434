"""Rendering tells its progress step by step: exactly ``STEPS`` of them, one per file written
and per section built, so a progress bar ends at 100% and never past it."""

from __future__ import annotations

import shutil
from pathlib import Path

from crosscheck.report.render import STEPS, render
from tests.conftest import ROOT


def test_render_counts_exactly_its_steps(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    shutil.copytree(ROOT / "tests" / "data" / "format4-run", folder)
    told: list[int] = []
    render(folder, told.append)
    assert told == [1] * STEPS
