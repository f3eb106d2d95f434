"""The runner: every case on every engine, scored against the oracle, stored as it goes.

For each case the exact truth is computed once.  For each engine the case is
executed (:mod:`crosscheck.execute`) in that engine's worker process
(:mod:`crosscheck.worker`), then scored quantity by quantity.  An engine that
raises yields ``error`` rows, one that dies ``crash`` rows, one that hangs
``timeout`` rows; the run goes on.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from adapters.base import HANG_PROBE_S, Adapter
from crosscheck import oracle
from crosscheck.distributed import CaseJob, DaskLanes
from crosscheck.execute import Executor, Outcome, RunOptions
from crosscheck.model import Observation, Record, Status, quantities_of
from crosscheck.schema import AnyCase, ResponseCase, SceneCase
from crosscheck.score import Verdict, encode, judge
from crosscheck.store import ResultsStore
from crosscheck.worker import Lanes


def score_case(case: AnyCase, adapter: Adapter, outcome: Outcome,
               truth: Observation) -> list[Record]:
    """The records of one case x engine: one per quantity of the case's kind."""
    records = []
    for quantity in quantities_of(case.kind_enum):
        if outcome.observation is None:
            assert outcome.status is not None
            verdict = Verdict(outcome.status, reason=outcome.reason)
            value = None
        else:
            value = outcome.observation.get(quantity)
            judged, truth = at_contact(case, outcome.observation, truth)
            verdict = judge(judged, adapter.conventions, quantity, value, truth)
        records.append(_record(case, adapter.name, quantity, value, truth, verdict, outcome))
    return records


def at_contact(case: AnyCase, observation: Observation,
               truth: Observation) -> tuple[AnyCase, Observation]:
    """The case and truth at the centres where the engine resolved a response, if it says."""
    if observation.resolved_at is None or not isinstance(case, ResponseCase):
        return case, truth
    pa, pb = observation.resolved_at
    moved = case.model_copy(update={"a": case.a.model_copy(update={"center": pa}),
                                    "b": case.b.model_copy(update={"center": pb})})
    return moved, oracle.truth(moved)


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
    )


Progress = Callable[[int], None]
"""Called with the number of case x engine pairs just finished."""


Pairs = set[tuple[str, str]] | frozenset[tuple[str, str]]


def run_case(case: AnyCase, adapters: Sequence[Adapter], executor: Executor,
             options: RunOptions, done: Pairs = frozenset()) -> list[Record]:
    """Every record of one case: the truth once, then each adapter not already done."""
    skipped = _quick_skip(case) if options.quick else None  # the run's --quick, not sampling
    truth = oracle.truth(case) if skipped is None else Observation()
    if options.timed_ids is not None and case.id not in options.timed_ids:
        options = replace(options, quick=True)
    records: list[Record] = []
    for adapter in adapters:
        if (case.id, adapter.name) not in done:
            outcome = skipped
            records += score_case(case, adapter,
                                  outcome or _execute(executor, adapter, case, options), truth)
    return records


QUICK_SCENE_STEPS = 1000
"""``--quick`` runs a scene only up to this many steps (the rest are ``skip`` rows)."""


def _quick_skip(case: AnyCase) -> Outcome | None:
    if isinstance(case, SceneCase) and case.step_count > QUICK_SCENE_STEPS:
        return Outcome(None, Status.SKIP, f"--quick runs scenes of at most {QUICK_SCENE_STEPS} "
                                          f"steps; this one takes {case.step_count}")
    return None


def _execute(executor: Executor, adapter: Adapter, case: AnyCase,
             options: RunOptions) -> Outcome:
    """Execute, probing a declared known hang under HANG_PROBE_S and saying so."""
    hang = adapter.known_hang(case)
    if isinstance(case, SceneCase):  # stepping takes seconds, not microseconds
        options = replace(options, timeout_s=max(options.timeout_s, SCENE_TIMEOUT_S))
    if hang is None:
        return executor(adapter, case, options)
    limit = min(options.timeout_s, HANG_PROBE_S)
    outcome = executor(adapter, case, replace(options, timeout_s=limit, quick=True))
    if outcome.status is Status.TIMEOUT:
        return replace(outcome, reason=f"{outcome.reason} (declared known hang: {hang})")
    return outcome


SCENE_TIMEOUT_S = 300.0
"""Time limit for one scene x engine (the run's --timeout if larger)."""


def timed_sample(cases: Sequence[AnyCase], per_group: int) -> frozenset[str]:
    """The first ``per_group`` cases of each case file x kind x dim, in suite order.

    Swapped twins (the same work as their original) and bad-input cases
    (timing a failure says nothing) are never timed.
    """
    counts: Counter[tuple[str, str, int]] = Counter()
    chosen = []
    for case in cases:
        key = (Path(case.source).stem, case.kind, case.dim)
        if ("swapped" not in case.tags and not case.bad_input and counts[key] < per_group
                and not isinstance(case, SceneCase)):  # a scene times its own one run
            counts[key] += 1
            chosen.append(case.id)
    return frozenset(chosen)


def run(cases: Sequence[AnyCase], adapters: Sequence[Adapter], store: ResultsStore,
        options: RunOptions | None = None, progress: Progress | None = None) -> int:
    """Run every case on every adapter, appending records to ``store``; return the count.

    Engines run in worker processes unless ``options.isolate`` is False, so a
    crash or hang costs one case, not the run.  With ``options.jobs`` > 1,
    cases run concurrently in that many lanes, each with its own workers.
    Pairs in ``store.done`` (a resumed run) are not run again.  With
    ``options.scheduler``, cases run as tasks on that Dask cluster instead
    (:mod:`crosscheck.distributed`).
    """
    options = options or RunOptions()
    if options.time_per_group and options.timed_ids is None and not options.quick:
        options = replace(options, timed_ids=timed_sample(cases, options.time_per_group))
    store.add_cases(cases)
    todo = [c for c in cases if any((c.id, a.name) not in store.done for a in adapters)]
    done: dict[str, set[tuple[str, str]]] = {}
    for pair in store.done:
        done.setdefault(pair[0], set()).add(pair)
    items = ((case, frozenset(done.get(case.id, ()))) for case in todo)
    count = 0
    lanes: Lanes | DaskLanes = DaskLanes(options) if options.scheduler else Lanes(options)
    with lanes:
        for records in lanes.map(CaseJob(tuple(adapters), options), items):
            store.append(records)
            count += len(records)
            if progress:
                progress(len(adapters))
    return count
