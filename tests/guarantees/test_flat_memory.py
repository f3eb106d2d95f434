"""A long run keeps its resident memory flat: records stream to disk and at most 2 x jobs
items of cases are in flight, so 100,000 cases grow the parent by less than 50 MB from 20,000 on."""

from __future__ import annotations

from pathlib import Path

import pytest

import adapters
from crosscheck.core.model import Kind
from crosscheck.core.options import RunOptions
from crosscheck.results.run import read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.runner import run
from crosscheck.studies.bench.figures import rss_mb
from crosscheck.studies.fuzz.generator import generate


@pytest.mark.slow
def test_a_100k_case_run_keeps_memory_flat(tmp_path: Path) -> None:
    cases = [g.case for g in generate(Kind.SPHERE, 100_000, seed=3)]
    store = ResultsStore(tmp_path / "run")
    samples: list[float] = []
    done = 0

    def progress(n: int) -> None:  # n pairs just finished (the cases of one lane item)
        nonlocal done
        if (done + n) // 10_000 > done // 10_000:
            samples.append(rss_mb())
        done += n

    run(cases, [adapters.get("reference")], store, RunOptions(quick=True, jobs=2),
        progress=progress)
    store.close()
    assert len(read_results(tmp_path / "run")) == 300_000
    assert len(samples) == 10
    growth = samples[-1] - samples[1]
    assert growth < 50, f"resident memory grew {growth:.0f} MB from 20k to 100k cases: {samples}"
