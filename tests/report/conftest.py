"""The runs the page tests read: the whole suite on every engine, and a small run of two fakes,
rendered."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from crosscheck.cases.tiers import STANDARD
from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.report.render import render
from crosscheck.results.run import read_run_info
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests.conftest import ROOT, sphere
from tests.fakes import AlwaysRight, OffByOne
from tests.report.browser import needs_chromium

SUITE_RUN = ["--timing-cases", "5", "--samples", "3", "--min-sample", "0.0005"]
"""A small timing phase: every kind's speed chart and time columns exist, in a minute."""


@pytest.fixture(scope="session")
def suite_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The standard suite (every case file of cases/, as ``crosscheck run`` and ``make run``
    run it) on every available engine, with a small timing phase, rendered: made once per
    session for the tests marked ``suite``.  The folder is named by its full path, so the run
    is the standard tier wherever pytest was started (``crosscheck run``'s default is
    ``cases/`` relative to where it runs)."""
    needs_chromium()
    out = tmp_path_factory.mktemp("suite") / "run"
    assert main(["run", str(ROOT / STANDARD), *SUITE_RUN, "--out", str(out)]) == 0
    assert read_run_info(out).tier == "standard"
    return out


@pytest.fixture(scope="module")
def fakes_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run of two fakes with known behaviour: one always right, one off by 1.0 in distance
    (an unexplained disagree); with a bad-input case of NaN and infinite inputs (judged
    apart, never a thrown error; placed in no cell of the configuration space)."""
    needs_chromium()
    folder = tmp_path_factory.mktemp("fakes") / "run"
    cases = [sphere(0.0, 2.0 + i / 4, id=f"s{i}") for i in range(4)]
    cases += [sphere(math.nan, math.inf, ra=math.nan, id="s-nan", tags=["bad-input"])]
    options, engines = RunOptions(quick=True, isolate=False), [AlwaysRight(), OffByOne()]
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    render(folder)
    return folder
