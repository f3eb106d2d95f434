"""The runner: every case on every engine, scored against the oracle, stored as it goes.

For each case the exact truth is computed once.  For each engine the case is
prepared (untimed; its build time is recorded as ``setup_s``), queried once
for the observation, then timed in a calibrated loop unless the run is quick.
An engine that raises yields ``error`` rows; the run goes on.
"""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from adapters.base import Adapter
from crosscheck import oracle
from crosscheck.model import Observation, Record, Status, quantities_of
from crosscheck.schema import AnyCase, ResponseCase
from crosscheck.score import Verdict, encode, judge
from crosscheck.store import ResultsStore
from crosscheck.timing import Timing, measure


@dataclass(frozen=True, slots=True)
class RunOptions:
    """How to run: ``quick`` skips timing; sample length and count otherwise."""

    quick: bool = False
    min_sample_s: float = 0.02
    samples: int = 5


@dataclass(frozen=True, slots=True)
class _Outcome:
    observation: Observation | None
    status: Status | None = None
    reason: str = ""
    setup_s: float = math.nan
    timing: Timing | None = None


def _execute(adapter: Adapter, case: AnyCase, options: RunOptions) -> _Outcome:
    skip = adapter.available() or adapter.unsupported(case)
    if skip:
        return _Outcome(None, Status.SKIP, skip)
    prepared: Any = None
    try:
        start = time.perf_counter()
        prepared = adapter.prepare(case)
        setup = time.perf_counter() - start
        observation = adapter.query(prepared)
        timing = None if options.quick else measure(
            lambda: adapter.query(prepared), min_sample_s=options.min_sample_s,
            samples=options.samples)
        return _Outcome(observation, setup_s=setup, timing=timing)
    except Exception as exc:  # an engine fault is data, not a harness failure
        where = traceback.extract_tb(exc.__traceback__)[-1]
        return _Outcome(None, Status.ERROR,
                        f"{type(exc).__name__}: {exc} (at {where.name}:{where.lineno})")
    finally:
        if prepared is not None:
            adapter.release(prepared)


def score_case(case: AnyCase, adapter: Adapter, outcome: _Outcome,
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
            truth = truth_at_contact(case, outcome.observation, truth)
            verdict = judge(case, adapter.conventions, quantity, value, truth)
        records.append(_record(case, adapter.name, quantity, value, truth, verdict, outcome))
    return records


def truth_at_contact(case: AnyCase, observation: Observation, truth: Observation) -> Observation:
    """The truth at the centres where the engine resolved a response, if it says where."""
    if observation.resolved_at is None or not isinstance(case, ResponseCase):
        return truth
    pa, pb = observation.resolved_at
    moved = case.model_copy(update={"a": case.a.model_copy(update={"center": pa}),
                                    "b": case.b.model_copy(update={"center": pb})})
    return oracle.truth(moved)


def _record(case: AnyCase, engine: str, quantity: str, value: Any, truth: Observation,
            verdict: Verdict, outcome: _Outcome) -> Record:
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


Progress = Callable[[str], None]


def run(cases: Sequence[AnyCase], adapters: Sequence[Adapter], store: ResultsStore,
        options: RunOptions = RunOptions(), progress: Progress | None = None) -> int:
    """Run every case on every adapter, appending records to ``store``; return the count."""
    count = 0
    for case in cases:
        store.add_case(case)
        truth = oracle.truth(case)
        for adapter in adapters:
            records = score_case(case, adapter, _execute(adapter, case, options), truth)
            store.append(records)
            count += len(records)
            if progress:
                progress(f"{case.id} x {adapter.name}")
    return count
