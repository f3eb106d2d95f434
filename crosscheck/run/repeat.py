"""The repeat check: each disagreeing pair asked once more in a fresh worker, to find the engines
whose answer depends on something outside the case.

``crosscheck run --repeat-check`` runs it after the verdict pass and before the timing
phase (:func:`crosscheck.run.launch.launch`).  Every case x engine pair with a row in
:data:`REASKED` (``disagree``, ``error``, ``crash``) is asked again, once, and its second
answer is scored as the first was.  A pair whose answer changed (any quantity's value text
or status differs, :func:`~crosscheck.results.repeats.changed`) is ``nondeterministic``.

Where it is asked: in a worker process started for a batch (:class:`RepeatJob`): the pairs
of one engine library (its variants share a worker, as in the verdict pass), at most
:data:`BATCH_CASES` cases of them, in a worker started for that batch alone and stopped
after it (in this process under ``--no-isolation``), the cases in the reverse of the run's
order.  The second answer thus comes from a process with another history than the first
(other addresses, other cases asked before it): what an answer depends on beyond its case
shows as a change.  (Before, one worker per pair cost a process start per pair, ten
minutes of a full run.  FCL's answers on some deep sphere overlaps differ from one process
to the next at random; batches flag them as a worker per pair did.)  A pair that crashes
its worker is asked in the next one the pool starts, so a crash of the case is still told
from one the worker's history caused.

Scene pairs are asked again in the deep tier only (``crosscheck run --deep``): asking every
disagreeing scene again costs as much as stepping the scenes did, a large share of a
standard run, and no scene has answered differently in the full runs so far (the engines
step deterministically from the same inputs); the summary's ``scenes`` says which.

Not asked again: agreeing pairs (the check is about the disagreements a report shows and a
repro script must reproduce), and pairs with a ``timeout`` row (whether an answer comes in
time depends on the machine's load as much as on the engine, and asking again costs the
whole time limit).  A second asking that runs out of time flags nothing, for the same
reason as a first.

Each batch's :class:`~crosscheck.results.repeats.RepeatRecord` lines are appended to
``repeats.jsonl`` as the batch comes back, so an interrupted check keeps every answer
received; a resumed run asks only the pairs not in that file yet.  The exact truth of each
case is computed once per lane, not once per batch (:class:`RepeatJob` keeps it).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Observation, Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.results.repeats import Answer, RepeatRecord, changed, read_repeats
from crosscheck.results.run import Run
from crosscheck.results.store import ResultsStore
from crosscheck.run.casework import execute_cases
from crosscheck.run.distributed import DaskLanes
from crosscheck.run.execute import Executor, Lanes, execute
from crosscheck.run.lanes import LocalLanes
from crosscheck.run.scoring import score_outcome
from crosscheck.run.worker import WorkerPool
from crosscheck.truth import oracle

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


BATCH_CASES = 400
"""Cases of one engine library asked again in one fresh worker, at most."""

Batch = tuple[tuple[AnyCase, frozenset[Pair]], ...]
"""One batch: each case with its pairs *not* to ask again (the other engines', the agreeing)."""


@dataclass(frozen=True)
class RepeatJob:
    """Ask one batch again in a worker started for it alone: picklable (a Dask task gets the
    adapters' classes, as :class:`~crosscheck.run.runner.CaseJob` does)."""

    adapters: tuple[Adapter, ...]
    options: RunOptions
    truths: dict[str, Observation] = field(default_factory=dict, compare=False)
    """Each case's exact truth, computed once (lanes are threads of one process)."""

    def truth(self, case: AnyCase) -> Observation:
        """The exact truth of ``case``, from :attr:`truths` once computed."""
        if case.id not in self.truths:
            self.truths[case.id] = oracle.truth(case)
        return self.truths[case.id]

    def __call__(self, batch: Batch, executor: Executor) -> list[list[Record]]:
        """The scored records of the second answers, one list per pair asked (the lane's own
        ``executor`` is not used: its workers have answered other cases)."""
        if not self.options.isolate:
            return self._ask(batch, execute)
        pool = WorkerPool(self.options)
        try:
            return self._ask(batch, pool)
        finally:
            pool.close(at_once=True)  # it will answer nothing else: its exit would only cost time

    def _ask(self, batch: Batch, fresh: Executor) -> list[list[Record]]:
        executed = execute_cases(batch, self.adapters, fresh, self.options, self.truth)
        return [score_outcome(e.case, self.adapters[k], outcome, e.truth)
                for e in executed for k, outcome in e.outcomes]

    def __reduce__(self) -> tuple[Any, ...]:
        return _repeat_job, (tuple(type(a) for a in self.adapters), self.options)


def _repeat_job(classes: Sequence[type[Adapter]], options: RunOptions) -> RepeatJob:
    return RepeatJob(tuple(cls() for cls in classes), options)


def batches(firsts: Collection[Pair], cases: dict[str, AnyCase],
            engines: Sequence[Adapter]) -> list[Batch]:
    """The pairs to ask again as batches: per engine library (in run order), its cases in
    the reverse of the run's order (so a case's history in the batch is not the one it had in
    the verdict pass), in runs of at most :data:`BATCH_CASES`, each with the pairs not to
    ask."""
    libraries: dict[str, dict[str, None]] = {}
    library = {a.name: a.engine for a in engines}
    for case_id, name in firsts:
        libraries.setdefault(library[name], {})[case_id] = None
    found: list[Batch] = []
    for engine in dict.fromkeys(a.engine for a in engines):
        ids = [c for c in reversed(cases) if c in libraries.get(engine, {})]
        for i in range(0, len(ids), BATCH_CASES):
            found.append(tuple(
                (cases[c], frozenset((c, a.name) for a in engines
                                     if a.engine != engine or (c, a.name) not in firsts))
                for c in ids[i:i + BATCH_CASES]))
    return found


def scenes_asked(run: Run) -> bool:
    """Whether the check asks scene pairs again: in the deep tier only (see the module's
    docstring)."""
    return run.info.tier == "deep"


def pending_repeats(store: ResultsStore, run: Run,
                    engines: Sequence[Adapter]) -> dict[Pair, Answers]:
    """The first answers of the pairs of ``run`` the repeat check has still to ask in
    ``store`` (scene pairs only when :func:`scenes_asked`)."""
    firsts = first_answers(run, {a.name for a in engines}, store.repeated)
    if scenes_asked(run):
        return firsts
    return {pair: answers for pair, answers in firsts.items()
            if not isinstance(run.cases[pair[0]], SceneCase)}


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
    progress = start(len(firsts)) if start else None
    lanes: Lanes = DaskLanes(options) if options.scheduler else LocalLanes(options)
    with lanes:
        for result in lanes.map(RepeatJob(tuple(engines), options),
                                batches(firsts, run.cases, engines)):
            for records in result:
                _record(store, records, firsts)
            if progress:
                progress(len(result))
    seconds = time.monotonic() - began + float((previous or {}).get("seconds", 0.0))
    return {**summary(store.directory, seconds), "scenes": scenes_asked(run)}


def _record(store: ResultsStore, records: Sequence[Record], firsts: dict[Pair, Answers]) -> None:
    pair = (records[0].case_id, records[0].engine)
    second = answers_of(records)
    store.append_repeat(RepeatRecord(*pair, second, changed(firsts[pair], second)))


def summary(directory: Path, seconds: float) -> dict[str, Any]:
    """The check's summary for run.json, counted from the run's ``repeats.jsonl`` (the
    caller adds ``scenes``: whether scene pairs were asked)."""
    records = read_repeats(directory).values()
    return {"pairs": len(records), "nondeterministic": sum(r.nondeterministic for r in records),
            "seconds": round(seconds, 3)}
