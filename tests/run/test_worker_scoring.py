"""The verdict pass scores in the engines' workers: a worker sent a case with its truth
(``Judged``) answers the pair's rows as JSON lines, the same rows the parent writes when it
scores (right, wrong and raising engines, responses, time of impact and scenes); a pair whose
worker died (crash) comes back unscored and the parent scores it."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from crosscheck.cases.load import load_paths
from crosscheck.cli.engines import select
from crosscheck.core.contract import Adapter
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.results.store import ResultsStore
from crosscheck.run import runner
from crosscheck.run.casework import execute_cases
from crosscheck.run.scoring import scored_lines
from crosscheck.run.worker import WorkerPool
from tests import fakes
from tests.conftest import ROOT

OPTIONS = RunOptions(timing_cases=0)


def some_cases() -> list[AnyCase]:
    """A few cases of every kind: detection, responses, time of impact, scenes."""
    picked: list[AnyCase] = []
    for name in ("sphere", "aabb", "response", "toi"):
        picked += load_paths([ROOT / "cases" / f"{name}.toml"]).cases[:4]
    picked += [c for c in load_paths([ROOT / "cases" / "fast.toml"]).cases
               if c.id.startswith("fast-head-on.dt=0.0166667.step_travel=0.5,")][:2]
    return picked


def engines() -> list[Adapter]:
    return [*select(["reference", "pymunk"]), fakes.OffByOne(), fakes.Raises()]


def test_a_worker_answers_the_rows_the_parent_would_write() -> None:
    cases, adapters = some_cases(), engines()
    items = [(case, frozenset[tuple[str, str]]()) for case in cases]
    pool = WorkerPool(OPTIONS)
    try:
        judged = execute_cases(items, adapters, pool, OPTIONS, scored=True)
        plain = execute_cases(items, adapters, pool, OPTIONS)
    finally:
        pool.close()
    for worker, here in zip(judged, plain, strict=True):
        assert len(worker.outcomes) == len(adapters)
        for (k, scored), (_, outcome) in zip(worker.outcomes, here.outcomes, strict=True):
            assert scored.lines is not None and outcome.lines is None
            # a pair's observation stays in the worker; a scene's comes back for its series
            assert (scored.observation is None) == (outcome.observation is None
                                                    or not isinstance(worker.case, SceneCase))
            expected = scored_lines(here.case, adapters[k], outcome, here.truth)
            assert _untimed(scored.lines) == _untimed(expected)


def _untimed(lines: str) -> list[dict[str, Any]]:
    rows = [json.loads(line) for line in lines.splitlines()]
    for row in rows:
        row.pop("setup_s")  # measured: differs between two askings (as a scene's query time)
        row.pop("query_s")
    return rows


def _run(folder: Path, cases: Sequence[AnyCase], adapters: Sequence[Adapter],
         columnar: bool) -> list[dict[str, Any]]:
    store = ResultsStore(folder)
    try:
        runner.run(cases, adapters, store, OPTIONS, columnar=columnar)
    finally:
        store.close()
    rows = _untimed((folder / "results.jsonl").read_text())
    return sorted(rows, key=lambda r: (r["case_id"], r["engine"], r["quantity"]))


def test_a_run_scored_in_the_workers_writes_what_scoring_here_writes_crashes_included(
        tmp_path: Path) -> None:
    cases, adapters = some_cases(), [*engines(), fakes.Aborts()]
    in_workers = _run(tmp_path / "workers", cases, adapters, columnar=True)
    here = _run(tmp_path / "here", cases, adapters, columnar=False)
    assert in_workers == here
    crashed = [r for r in in_workers if r["engine"] == "fake-aborts"]
    assert crashed and all(r["status"] == "crash" for r in crashed)
