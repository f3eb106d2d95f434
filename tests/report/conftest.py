"""The one real full run the page tests read: the whole suite on every engine, rendered."""

from __future__ import annotations

from pathlib import Path

import pytest

from crosscheck.cli import main
from tests.report.browser import needs_chromium

SUITE_RUN = ["--timing-cases", "5", "--samples", "3", "--min-sample", "0.0005"]
"""A small timing phase: every kind's speed chart and time columns exist, in a minute."""


@pytest.fixture(scope="session")
def suite_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The whole suite (every case file) on every available engine, with a small timing
    phase, rendered: made once per session for the tests marked ``suite``."""
    needs_chromium()
    out = tmp_path_factory.mktemp("suite") / "run"
    assert main(["run", *SUITE_RUN, "--out", str(out)]) == 0
    return out
