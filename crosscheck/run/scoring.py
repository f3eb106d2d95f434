"""Scoring one case x engine: its outcome judged quantity by quantity into records and their
JSON lines.

Where it runs: in the engine's worker for the verdict pass (the worker is sent the case
with its exact truth, :class:`crosscheck.run.execute.Judged`, and answers the scored lines
with the outcome, :func:`scored_lines`), so the parent only appends what comes back; in
the parent for what a worker could not score (a crash, a timeout, a declared hang's probe)
and for the per-record callers (the repeat check, fuzzing, tests).  The rows are the same
either way: one definition of a row (:func:`record`, :func:`crosscheck.results.rows.line`).
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Observation, Record, Status, quantities_of
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.core.values import encode
from crosscheck.results.rows import line
from crosscheck.run.execute import Judged, Outcome, execute
from crosscheck.truth import measure_rules
from crosscheck.truth.score import Verdict, judge


def score_case(case: AnyCase, adapter: Adapter, outcome: Outcome,
               truth: Observation) -> list[Record]:
    """The records of one case x engine: one per quantity, judged against the case as declared."""
    records = []
    if isinstance(case, SceneCase) and outcome.observation is not None:
        outcome = replace(outcome, observation=measure_rules.complete(
            case, outcome.observation, truth))
    for quantity in quantities_of(case.kind_enum):
        if outcome.observation is None:
            assert outcome.status is not None
            verdict = Verdict(outcome.status, reason=outcome.reason)
            value = None
        else:
            value = outcome.observation.get(quantity)
            verdict = judge(case, adapter.conventions, quantity, value, truth,
                            outcome.observation)
        records.append(record(case, adapter.name, quantity, value, truth, verdict, outcome))
    return records


def case_fields(case: AnyCase, engine: str, outcome: Outcome) -> dict[str, Any]:
    """The fields every row of ``case`` on ``engine`` shares
    (:data:`~crosscheck.results.rows.CASE_FIELDS`: the case, the engine, the timing)."""
    timing = outcome.timing
    return {
        "case_id": case.id, "source": case.source, "kind": case.kind, "dim": int(case.dim),
        "tags": " ".join(case.tags), "engine": engine, "setup_s": outcome.setup_s,
        "query_s": timing.median_s if timing else math.nan,
        "query_iqr_s": timing.iqr_s if timing else math.nan,
        "loops": int(timing.loops) if timing else 0,
        "unstable": bool(timing.unstable) if timing else False,
        "origin": case.origin, "coords": json.dumps(case.coords) if case.coords else "",
        "twin_of": case.twin_of}


def record(case: AnyCase, engine: str, quantity: str, value: Any, truth: Observation,
            verdict: Verdict, outcome: Outcome) -> Record:
    return Record(
        **case_fields(case, engine, outcome), quantity=quantity,
        value=encode(value), truth=encode(truth.get(quantity)),
        error=verdict.error, tolerance=verdict.tolerance, status=verdict.status,
        category=verdict.category, reason=verdict.reason,
        error_at_contact=verdict.error_at_contact)


def score_outcome(case: AnyCase, adapter: Adapter, outcome: Outcome,
                  truth: Observation) -> list[Record]:
    """:func:`score_case`, with the quantities a declared hang kept from answering
    (``outcome.hung``) as rows of its ``hang_status`` and reason."""
    scored = score_case(case, adapter, outcome, truth)
    if outcome.hung:
        stuck = Outcome(None, outcome.hang_status, outcome.hang_reason)
        timeouts = score_case(case, adapter, stuck, truth)
        scored = [t if r.quantity in outcome.hung else r
                  for r, t in zip(scored, timeouts, strict=True)]
    return scored



def scored_lines(case: AnyCase, adapter: Adapter, outcome: Outcome, truth: Observation) -> str:
    """The JSON lines of :func:`score_outcome` (what ``results.jsonl`` holds for the pair)."""
    return "".join(line(r) for r in score_outcome(case, adapter, outcome, truth))


def answer_judged(adapter: Adapter, task: Judged, options: RunOptions, timed: bool,
                  skip: frozenset[str]) -> Outcome:
    """A worker's answer to :class:`~crosscheck.run.execute.Judged`: the case executed, then
    scored here (a crash or timeout is left to the pool, which retries or names it, and to
    the parent's scoring); a pair's observation stays here, a scene's goes back."""
    outcome = execute(adapter, task.case, options, timed, skip)
    if outcome.status in (Status.CRASH, Status.TIMEOUT):
        return outcome
    lines = scored_lines(task.case, adapter, outcome, task.truth)
    kept = outcome.observation if isinstance(task.case, SceneCase) else None
    return replace(outcome, observation=kept, lines=lines)
