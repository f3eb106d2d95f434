"""The runner: every case on every engine, scored against the oracle, stored as it goes.

For each case the exact truth is computed once.  For each engine the case is
executed (:mod:`crosscheck.run.execute`) in that engine's worker process
(:mod:`crosscheck.run.worker`), then scored quantity by quantity.  An engine that
raises yields ``error`` rows, one that dies ``crash`` rows, one that hangs
``timeout`` rows; the run goes on.

By default the workers score: a lane sends each case with its truth
(:class:`~crosscheck.run.execute.Judged`), each engine's worker answers the pair's rows as
JSON lines (:mod:`crosscheck.run.scoring`), and the lanes return the outcomes of each case
(:class:`Executed`) to the parent, which writes them in chunks of up to
:data:`CHUNK_CASES` cases, one engine at a time.  What a worker could not score (a crash, a
timeout, a declared hang's probe; every pair in-process or on Dask) the parent judges in
columns with :func:`crosscheck.truth.columnar.judge_batch` and writes straight from them
(:func:`score_lines`, with :class:`crosscheck.results.rows.ColumnLines`, which shares the
row's one definition with the per-record writer), without a Record per row.  A chunk is
written when it is full, :data:`FLUSH_S` after the last write, and when the run
ends or is interrupted, so an interrupted run keeps every outcome it received.  A chunk's
scene cases first append what their exact run showed to ``scene_facts.jsonl``
(:func:`crosscheck.results.scene_facts.facts_of`, from the truth already computed: the
report reads it instead of running the reference again) and their recorded energy against
time to ``series.jsonl`` (:func:`energy_series`; the report's energy charts draw them); the
per-record path below writes rows only (the report then recomputes the facts).
``run(..., columnar=False)`` scores record by record in the lanes (:func:`score_case`);
``tests/truth/test_columnar.py`` and ``tests/run/test_worker_scoring.py`` check that every
path writes the same rows.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Observation, Record, quantities_of
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, PairCase, SceneCase, ToiCase
from crosscheck.results.rows import ColumnLines, line
from crosscheck.results.scene_facts import facts_of
from crosscheck.results.series import EXACT, SeriesRecord, series_of
from crosscheck.results.store import ResultsStore
from crosscheck.run.casework import (
    ITEM_CASES,
    Executed,
    Pairs,
    execute_case,
    execute_cases,
)
from crosscheck.run.distributed import DaskLanes
from crosscheck.run.execute import Executor, Lanes, Outcome
from crosscheck.run.lanes import LocalLanes
from crosscheck.run.scoring import case_fields, record, score_outcome
from crosscheck.truth.columnar import judge_batch

Progress = Callable[[int], None]
"""Called with the number of case x engine pairs just finished."""


def run_case(case: AnyCase, adapters: Sequence[Adapter], executor: Executor,
             options: RunOptions, done: Pairs = frozenset()) -> list[Record]:
    """Every record of one case: the truth once, then each adapter not already done.

    This is the verdict pass: nothing is timed here but a scene's one run (the
    timing phase, :mod:`crosscheck.run.timing_phase`, measures afterwards in quiet).
    Quantities a declared hang kept from answering (``Outcome.hung``) are rows of its
    ``hang_status`` (``timeout``, or ``skip`` in-process) with the hang's reason; the others
    are scored as usual.
    """
    executed = execute_case(case, adapters, executor, options, done)
    return [record for k, outcome in executed.outcomes
            for record in score_outcome(case, adapters[k], outcome, executed.truth)]


_instances: dict[type[Adapter], Adapter] = {}
_instances_lock = threading.Lock()


def _instance(cls: type[Adapter]) -> Adapter:
    """One instance per adapter class per process (engine clients of --no-isolation reused)."""
    with _instances_lock:
        if cls not in _instances:
            _instances[cls] = cls()
        return _instances[cls]


@dataclass(frozen=True)
class CaseJob:
    """The cases of one item (``(case, done pairs)`` each, :data:`ITEM_CASES` at most) on
    ``adapters``: picklable.

    Locally the job holds the adapter instances; pickled (to a Dask worker) it
    sends only their classes, instantiated once per worker process there.
    """

    adapters: tuple[Adapter, ...]
    options: RunOptions
    columnar: bool = False
    """Return each case's :class:`Executed` outcomes, for the parent to score in columns."""

    def __call__(self, item: Sequence[tuple[AnyCase, Pairs]],
                 executor: Executor) -> list[list[Record]] | list[Executed]:
        if self.columnar:
            return execute_cases(item, self.adapters, executor, self.options, scored=True)
        return [run_case(case, self.adapters, executor, self.options, done)
                for case, done in item]

    def __reduce__(self) -> tuple[Any, ...]:
        return _case_job, (tuple(type(a) for a in self.adapters), self.options, self.columnar)


def _case_job(classes: Sequence[type[Adapter]], options: RunOptions,
              columnar: bool = False) -> CaseJob:
    return CaseJob(tuple(_instance(cls) for cls in classes), options, columnar)


def run(cases: Sequence[AnyCase], adapters: Sequence[Adapter], store: ResultsStore,
        options: RunOptions | None = None, progress: Progress | None = None,
        columnar: bool = True) -> int:
    """Record the cases in ``store`` (``cases.jsonl``), then :func:`run_pending`: the verdict
    pass alone, without a run.json (a whole run is :func:`crosscheck.run.launch.launch`)."""
    store.add_cases(cases)
    return run_pending(cases, adapters, store, options, progress, columnar)


def run_pending(cases: Sequence[AnyCase], adapters: Sequence[Adapter], store: ResultsStore,
                options: RunOptions | None = None, progress: Progress | None = None,
                columnar: bool = True) -> int:
    """Run every case on every adapter, appending records to ``store``; return the count.
    The cases are already recorded in ``store`` (by the caller, once per run).

    Engines run in worker processes unless ``options.isolate`` is False, so a
    crash or hang costs one case, not the run.  With ``options.jobs`` > 1,
    cases run concurrently in that many lanes, each with its own workers.
    Pairs in ``store.done`` (a resumed run) are not run again.  With
    ``options.scheduler``, cases run as tasks on that Dask cluster instead
    (:mod:`crosscheck.run.distributed`).  ``columnar`` (the default) scores in the
    parent in chunks (see the module docstring); False scores record by record.
    """
    options = options or RunOptions()
    todo = [c for c in cases if any((c.id, a.name) not in store.done for a in adapters)]
    done: dict[str, set[tuple[str, str]]] = {}
    for pair in store.done:
        done.setdefault(pair[0], set()).add(pair)
    items = ([(case, frozenset(done.get(case.id, ()))) for case in todo[i:i + ITEM_CASES]]
             for i in range(0, len(todo), ITEM_CASES))
    lanes: Lanes = DaskLanes(options) if options.scheduler else LocalLanes(options)
    chunk = _Chunk(store, adapters)
    with lanes:
        try:
            for results in lanes.map(CaseJob(tuple(adapters), options, columnar), items):
                for result in results:
                    chunk.add(result)
                if progress:
                    progress(len(adapters) * len(results))
        finally:  # also on Ctrl-C or a failed write: what was received is written
            chunk.flush()
    return chunk.count


CHUNK_CASES = 256
"""Columnar scoring: cases scored and written together, at most."""
FLUSH_S = 0.5
"""Columnar scoring: the longest a received outcome waits to be written (checked as the
next case arrives)."""


class _Chunk:
    """The received, not yet written cases of a columnar run (and the records of a
    per-record one, written at once)."""

    def __init__(self, store: ResultsStore, adapters: Sequence[Adapter]) -> None:
        self.store, self.adapters = store, adapters
        self.pending: list[Executed] = []
        self.count = 0
        self.written = time.monotonic()

    def add(self, result: list[Record] | Executed) -> None:
        if isinstance(result, list):
            self.store.append(result)
            self.count += len(result)
            return
        self.pending.append(result)
        if len(self.pending) >= CHUNK_CASES or time.monotonic() - self.written > FLUSH_S:
            self.flush()

    def flush(self) -> None:
        pending, self.pending = self.pending, []
        self.written = time.monotonic()
        self.store.append_scene_facts(facts for executed in pending
                                      if (facts := facts_of(executed.case, executed.truth)))
        self.store.append_series(record for executed in pending
                                 for record in energy_series(executed, self.adapters))
        for k, adapter in enumerate(self.adapters):
            mine = [(e.case, outcome, e.truth) for e in pending for j, outcome in e.outcomes
                    if j == k]
            text = "".join(_lines(adapter, run) for run in _runs(mine))
            if text:
                self.store.append_lines(text)
                self.count += text.count("\n")


Scoring = tuple[AnyCase, Outcome, Observation]
"""A case, an engine's outcome on it, and its truth."""


def _runs(mine: list[Scoring]) -> list[list[Scoring]]:
    """``mine`` in runs of consecutive pairs scored alike: by their worker, or here."""
    runs: list[list[Scoring]] = []
    for scoring in mine:
        if runs and (runs[-1][0][1].lines is None) == (scoring[1].lines is None):
            runs[-1].append(scoring)
        else:
            runs.append([scoring])
    return runs


def _lines(adapter: Adapter, run: list[Scoring]) -> str:
    """The JSON lines of a run of :func:`_runs`: as the worker scored them, or scored here."""
    if run[0][1].lines is not None:
        return "".join(outcome.lines or "" for _, outcome, _ in run)
    cases, outcomes, truths = zip(*run, strict=True)
    return score_lines(cases, adapter, outcomes, truths)


def energy_series(executed: Executed, adapters: Sequence[Adapter]) -> list[SeriesRecord]:
    """The energy series of one executed scene case (``series.jsonl``,
    :mod:`crosscheck.results.series`): the exact reference's, then each engine's whose
    observation carries a trajectory; none for a pair case or an open-space scene."""
    case = executed.case
    if not isinstance(case, SceneCase):
        return []
    found = [series_of(case, EXACT, executed.truth.trajectory)]
    found += [series_of(case, adapters[k].name, outcome.observation.trajectory)
              for k, outcome in executed.outcomes if outcome.observation is not None]
    return [record for record in found if record is not None]


def score_lines(cases: Sequence[AnyCase], adapter: Adapter, outcomes: Sequence[Outcome],
                truths: Sequence[Observation]) -> str:
    """The JSON lines of ``cases`` on ``adapter``, as :meth:`ResultsStore.append` writes
    the records of :func:`score_outcome`: pair cases with an observation judged in columns
    (:func:`~crosscheck.truth.columnar.judge_batch`), the rest record by record."""
    plain = [k for k, (case, outcome) in enumerate(zip(cases, outcomes, strict=True))
             if outcome.observation is not None and not outcome.hung
             and not isinstance(case, SceneCase | ToiCase)]
    columns = judge_batch([_pair(cases[k]) for k in plain], adapter.conventions,
                          [_observed(outcomes[k]) for k in plain], [truths[k] for k in plain])
    rows = ColumnLines(columns)
    lines: list[str] = []
    marked = set(plain)
    for k, case in enumerate(cases):
        if k in marked:
            lines += rows.lines(case_fields(case, adapter.name, outcomes[k]),
                                _observed(outcomes[k]), truths[k])
        else:
            lines += map(line, score_outcome(case, adapter, outcomes[k], truths[k]))
    return "".join(lines)


def score_records(cases: Sequence[AnyCase], adapter: Adapter, outcomes: Sequence[Outcome],
                  truths: Sequence[Observation]) -> list[Record]:
    """The records of :func:`score_outcome` for every case, judged in columns as in
    :func:`score_lines` (for a caller that keeps records rather than writing lines)."""
    plain = [k for k, (case, outcome) in enumerate(zip(cases, outcomes, strict=True))
             if outcome.observation is not None and not outcome.hung
             and not isinstance(case, SceneCase | ToiCase)]
    columns = judge_batch([_pair(cases[k]) for k in plain], adapter.conventions,
                          [_observed(outcomes[k]) for k in plain], [truths[k] for k in plain])
    marked, row, records = set(plain), 0, []
    for k, case in enumerate(cases):
        if k not in marked:
            records += score_outcome(case, adapter, outcomes[k], truths[k])
            continue
        observation = _observed(outcomes[k])
        for quantity in quantities_of(case.kind_enum):
            records.append(record(case, adapter.name, quantity, observation.get(quantity),
                                   truths[k], columns.verdict(row), outcomes[k]))
            row += 1
    return records


def _pair(case: AnyCase) -> PairCase:
    assert not isinstance(case, SceneCase | ToiCase)
    return case


def _observed(outcome: Outcome) -> Observation:
    assert outcome.observation is not None
    return outcome.observation
