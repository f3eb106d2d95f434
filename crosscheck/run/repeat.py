"""The repeat check: each disagreeing pair asked once more in a fresh worker, to find the engines
whose answer depends on something outside the case.

``crosscheck run --repeat-check`` runs it after the verdict pass and before the timing
phase (:func:`crosscheck.run.launch.launch`).  Every case x engine pair with a row in
:data:`REASKED` (``disagree``, ``error``, ``crash``) is asked again, once, in a worker
process started for that pair alone (:func:`~crosscheck.run.worker.fresh_worker`; in this
process under ``--no-isolation``), and its second answer is scored as the first was.  A
pair whose answer changed (any quantity's value text or status differs,
:func:`~crosscheck.results.repeats.changed`) is ``nondeterministic``.

Not asked again: agreeing pairs (the check is about the disagreements a report shows and a
repro script must reproduce: each costs a worker start, so agreement is not re-asked), and pairs
with a ``timeout`` row (whether an answer comes in time depends on the machine's load as
much as on the engine, and asking again costs the whole time limit).  A ``crash`` is asked
again: a fresh worker tells a crash of the case from one that the worker's history caused.
A second asking that runs out of time flags nothing, for the same reason as a first.

Each pair's :class:`~crosscheck.results.repeats.RepeatRecord` is appended to
``repeats.jsonl`` as it comes back, so an interrupted check keeps every answer received; a
resumed run asks only the pairs not in that file yet.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.repeats import Answer, RepeatRecord, changed, read_repeats
from crosscheck.results.run import Run
from crosscheck.results.store import ResultsStore
from crosscheck.run.casework import execute_case
from crosscheck.run.distributed import DaskLanes
from crosscheck.run.execute import Executor, Lanes, execute
from crosscheck.run.lanes import LocalLanes
from crosscheck.run.runner import score_outcome
from crosscheck.run.worker import fresh_worker

REASKED = frozenset({Status.DISAGREE, Status.ERROR, Status.CRASH})
"""A pair with a row of one of these statuses (and none :data:`NOT_REASKED`) is asked again."""
NOT_REASKED = frozenset({Status.TIMEOUT})

Pair = tuple[str, str]
Answers = dict[str, Answer]


def first_answers(run: Run, engines: Collection[str],
                  skip: Collection[Pair] = ()) -> dict[Pair, Answers]:
    """The stored answers (quantity -> value text and status) of every pair of ``engines`` to
    ask again, from the run's rows; the pairs in ``skip`` (already asked) left out."""
    answers: dict[Pair, Answers] = {}
    statuses: dict[Pair, set[str]] = {}
    rows = run.results
    for case_id, engine, quantity, value, status in zip(
            rows["case_id"], rows["engine"], rows["quantity"], rows["value"], rows["status"],
            strict=True):
        pair = (str(case_id), str(engine))
        if pair[1] in engines and pair not in skip:
            answers.setdefault(pair, {})[str(quantity)] = (str(value), str(status))
            statuses.setdefault(pair, set()).add(str(status))
    return {pair: answers[pair] for pair, seen in statuses.items()
            if seen & REASKED and not seen & NOT_REASKED}


def answers_of(records: Sequence[Record]) -> Answers:
    """A pair's scored records as answers (quantity -> value text and status)."""
    return {r.quantity: (r.value, str(r.status)) for r in records}


@dataclass(frozen=True)
class RepeatJob:
    """Ask one case again on the named engines, each in a fresh worker: picklable (a Dask
    task gets the adapters' classes, as :class:`~crosscheck.run.runner.CaseJob` does)."""

    adapters: tuple[Adapter, ...]
    options: RunOptions

    def __call__(self, item: tuple[AnyCase, frozenset[str]],
                 executor: Executor) -> list[list[Record]]:
        """The scored records of the second answer, one list per engine asked (the lane's own
        ``executor`` is not used: its workers have answered other cases)."""
        case, names = item
        fresh: Executor = fresh_worker if self.options.isolate else execute
        others = frozenset((case.id, a.name) for a in self.adapters if a.name not in names)
        executed = execute_case(case, self.adapters, fresh, self.options, others)
        return [score_outcome(case, self.adapters[k], outcome, executed.truth)
                for k, outcome in executed.outcomes]

    def __reduce__(self) -> tuple[Any, ...]:
        return _repeat_job, (tuple(type(a) for a in self.adapters), self.options)


def _repeat_job(classes: Sequence[type[Adapter]], options: RunOptions) -> RepeatJob:
    return RepeatJob(tuple(cls() for cls in classes), options)


def pending_repeats(store: ResultsStore, run: Run,
                    engines: Sequence[Adapter]) -> dict[Pair, Answers]:
    """The first answers of the pairs of ``run`` the repeat check has still to ask in
    ``store``."""
    return first_answers(run, {a.name for a in engines}, store.repeated)


def repeat_check(store: ResultsStore, run: Run, engines: Sequence[Adapter], options: RunOptions,
                 start: Callable[[int], Callable[[int], None]] | None = None,
                 previous: dict[str, Any] | None = None) -> dict[str, Any]:
    """Ask every pending pair of ``run`` again (``start(total)`` returns the progress
    function), append each record as it comes, and return the check's summary for run.json:
    ``pairs`` asked and ``nondeterministic`` ones in the whole run, ``seconds`` (with
    ``previous``, the summary of a part of the run that finished the check before it was
    interrupted, added; the time of a part interrupted during the check is not counted)."""
    began = time.monotonic()
    firsts = pending_repeats(store, run, engines)
    by_case: dict[str, set[str]] = {}
    for case_id, engine in firsts:
        by_case.setdefault(case_id, set()).add(engine)
    items = [(case, frozenset(by_case[case.id])) for case in run.cases.values()
             if case.id in by_case]
    progress = start(len(firsts)) if start else None
    lanes: Lanes = DaskLanes(options) if options.scheduler else LocalLanes(options)
    with lanes:
        for result in lanes.map(RepeatJob(tuple(engines), options), items):
            for records in result:
                _record(store, records, firsts)
            if progress:
                progress(len(result))
    seconds = time.monotonic() - began + float((previous or {}).get("seconds", 0.0))
    return summary(store.directory, seconds)


def _record(store: ResultsStore, records: Sequence[Record], firsts: dict[Pair, Answers]) -> None:
    pair = (records[0].case_id, records[0].engine)
    second = answers_of(records)
    store.append_repeat(RepeatRecord(*pair, second, changed(firsts[pair], second)))


def summary(directory: Path, seconds: float) -> dict[str, Any]:
    """The check's summary for run.json, counted from the run's ``repeats.jsonl``."""
    records = read_repeats(directory).values()
    return {"pairs": len(records), "nondeterministic": sum(r.nondeterministic for r in records),
            "seconds": round(seconds, 3)}
