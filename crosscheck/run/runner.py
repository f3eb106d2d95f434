"""The runner: every case on every engine, scored against the oracle, stored as it goes.

For each case the exact truth is computed once.  For each engine the case is
executed (:mod:`crosscheck.run.execute`) in that engine's worker process
(:mod:`crosscheck.run.worker`), then scored quantity by quantity.  An engine that
raises yields ``error`` rows, one that dies ``crash`` rows, one that hangs
``timeout`` rows; the run goes on.
"""

from __future__ import annotations

import json
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

from crosscheck.core.contract import HANG_PROBE_S, Adapter
from crosscheck.core.model import Observation, Record, Status, quantities_of
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.core.values import encode
from crosscheck.results.store import ResultsStore
from crosscheck.run.distributed import DaskLanes
from crosscheck.run.execute import Executor, Lanes, Outcome
from crosscheck.run.worker import LocalLanes
from crosscheck.truth import oracle
from crosscheck.truth.score import Verdict, judge


def score_case(case: AnyCase, adapter: Adapter, outcome: Outcome,
               truth: Observation) -> list[Record]:
    """The records of one case x engine: one per quantity, judged against the case as declared."""
    records = []
    for quantity in quantities_of(case.kind_enum):
        if outcome.observation is None:
            assert outcome.status is not None
            verdict = Verdict(outcome.status, reason=outcome.reason)
            value = None
        else:
            value = outcome.observation.get(quantity)
            verdict = judge(case, adapter.conventions, quantity, value, truth,
                            outcome.observation)
        records.append(_record(case, adapter.name, quantity, value, truth, verdict, outcome))
    return records


def _record(case: AnyCase, engine: str, quantity: str, value: Any, truth: Observation,
            verdict: Verdict, outcome: Outcome) -> Record:
    timing = outcome.timing
    return Record(
        case_id=case.id, source=case.source, kind=case.kind, dim=case.dim,
        tags=" ".join(case.tags), engine=engine, quantity=quantity,
        value=encode(value), truth=encode(truth.get(quantity)),
        error=verdict.error, tolerance=verdict.tolerance, status=verdict.status,
        category=verdict.category, reason=verdict.reason, setup_s=outcome.setup_s,
        query_s=timing.median_s if timing else math.nan,
        query_iqr_s=timing.iqr_s if timing else math.nan,
        loops=timing.loops if timing else 0,
        unstable=timing.unstable if timing else False,
        origin=case.origin, coords=json.dumps(case.coords) if case.coords else "",
        twin_of=case.twin_of, error_at_contact=verdict.error_at_contact,
    )


Progress = Callable[[int], None]
"""Called with the number of case x engine pairs just finished."""


Pairs = set[tuple[str, str]] | frozenset[tuple[str, str]]


def run_case(case: AnyCase, adapters: Sequence[Adapter], executor: Executor,
             options: RunOptions, done: Pairs = frozenset()) -> list[Record]:
    """Every record of one case: the truth once, then each adapter not already done.

    This is the verdict pass: nothing is timed here but a scene's one run (the
    timing phase, :mod:`crosscheck.run.timing_phase`, measures afterwards in quiet).
    Quantities a declared hang kept from answering (``Outcome.hung``) are ``timeout``
    rows with the hang's reason; the others are scored as usual.
    """
    skipped = _quick_skip(case) if options.quick else None
    truth = oracle.truth(case) if skipped is None else Observation()
    records: list[Record] = []
    for adapter in adapters:
        if (case.id, adapter.name) not in done:
            outcome = skipped or _execute(executor, adapter, case, options)
            scored = score_case(case, adapter, outcome, truth)
            if outcome.hung:
                stuck = Outcome(None, Status.TIMEOUT, outcome.hang_reason)
                timeouts = score_case(case, adapter, stuck, truth)
                scored = [t if r.quantity in outcome.hung else r
                          for r, t in zip(scored, timeouts, strict=True)]
            records += scored
    return records


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
    """``run_case`` of one ``(case, done pairs)`` item on ``adapters``: picklable.

    Locally the job holds the adapter instances; pickled (to a Dask worker) it
    sends only their classes, instantiated once per worker process there.
    """

    adapters: tuple[Adapter, ...]
    options: RunOptions

    def __call__(self, item: tuple[AnyCase, Pairs], executor: Executor) -> list[Record]:
        case, done = item
        return run_case(case, self.adapters, executor, self.options, done)

    def __reduce__(self) -> tuple[Any, ...]:
        return _case_job, (tuple(type(a) for a in self.adapters), self.options)


def _case_job(classes: Sequence[type[Adapter]], options: RunOptions) -> CaseJob:
    return CaseJob(tuple(_instance(cls) for cls in classes), options)


QUICK_SCENE_STEPS = 1000
"""``--quick`` runs a scene only up to this many steps (the rest are ``skip`` rows)."""


def _quick_skip(case: AnyCase) -> Outcome | None:
    if isinstance(case, SceneCase) and case.step_count > QUICK_SCENE_STEPS:
        return Outcome(None, Status.SKIP, f"--quick runs scenes of at most {QUICK_SCENE_STEPS} "
                                          f"steps; this one takes {case.step_count}")
    return None


def _execute(executor: Executor, adapter: Adapter, case: AnyCase, options: RunOptions) -> Outcome:
    """Execute, probing a declared known hang under HANG_PROBE_S and saying so.

    The full query is probed first (a fixed engine answers it).  If the probe times out
    and the adapter names only some quantities as hanging, the query runs again without
    them under the run's limit; they are marked ``hung`` (the rest is its outcome).
    """
    hang = adapter.known_hang(case)
    if isinstance(case, SceneCase):  # stepping takes seconds, not microseconds
        options = replace(options, timeout_s=max(options.timeout_s, SCENE_TIMEOUT_S))
    if hang is None:
        return executor(adapter, case, options)
    limit = min(options.timeout_s, HANG_PROBE_S)
    outcome = executor(adapter, case, replace(options, timeout_s=limit), False)
    if outcome.status is not Status.TIMEOUT:
        return outcome
    reason = f"{outcome.reason} (declared known hang: {hang})"
    every = frozenset(quantities_of(case.kind_enum))
    hanging = adapter.hanging_quantities(case) & every
    if not hanging or hanging == every:
        return replace(outcome, reason=reason)
    rest = executor(adapter, case, options, False, hanging)
    return replace(rest, hung=hanging, hang_reason=reason)


SCENE_TIMEOUT_S = 300.0
"""Time limit for one scene x engine (the run's --timeout if larger)."""


def run(cases: Sequence[AnyCase], adapters: Sequence[Adapter], store: ResultsStore,
        options: RunOptions | None = None, progress: Progress | None = None) -> int:
    """Run every case on every adapter, appending records to ``store``; return the count.

    Engines run in worker processes unless ``options.isolate`` is False, so a
    crash or hang costs one case, not the run.  With ``options.jobs`` > 1,
    cases run concurrently in that many lanes, each with its own workers.
    Pairs in ``store.done`` (a resumed run) are not run again.  With
    ``options.scheduler``, cases run as tasks on that Dask cluster instead
    (:mod:`crosscheck.run.distributed`).
    """
    options = options or RunOptions()
    store.add_cases(cases)
    todo = [c for c in cases if any((c.id, a.name) not in store.done for a in adapters)]
    done: dict[str, set[tuple[str, str]]] = {}
    for pair in store.done:
        done.setdefault(pair[0], set()).add(pair)
    items = ((case, frozenset(done.get(case.id, ()))) for case in todo)
    count = 0
    lanes: Lanes = DaskLanes(options) if options.scheduler else LocalLanes(options)
    with lanes:
        for records in lanes.map(CaseJob(tuple(adapters), options), items):
            store.append(records)
            count += len(records)
            if progress:
                progress(len(adapters))
    return count
