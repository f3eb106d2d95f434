"""Executing cases on engines: the truth once per case, every pair's outcome, hangs probed.

A lane's item is a few cases (:data:`ITEM_CASES`): :func:`execute_cases` computes each
case's exact truth, then sends every pair of the item to the executor at once
(:func:`~crosscheck.run.execute.run_calls`: on a worker pool the engines' workers run side
by side, each handed its next case before it has answered the last), and returns the
unscored outcomes (:class:`Executed`) for the parent to score.  Pairs whose adapter
declares a known hang go one at a time through the probe of :func:`_execute`; ``--quick``
skips long scenes without running them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

from crosscheck.core.contract import HANG_PROBE_S, Adapter
from crosscheck.core.model import Observation, Status, quantities_of
from crosscheck.core.options import QUICK_SCENE_STEPS, RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.run.execute import (
    BatchExecutor,
    Call,
    Executor,
    Judged,
    Outcome,
    case_options,
    run_calls,
)
from crosscheck.truth import oracle

Pairs = set[tuple[str, str]] | frozenset[tuple[str, str]]
"""(case id, engine) pairs already done (a resumed run)."""

ITEM_CASES = 8
"""Cases of a lane's item: their pairs go to the workers together."""


@dataclass(frozen=True)
class Executed:
    """One case run on the engines of a job, not yet scored: what a lane returns when the
    parent scores in columns."""

    case: AnyCase
    truth: Observation
    outcomes: tuple[tuple[int, Outcome], ...]
    """(index of the adapter in the job's adapters, its outcome) for each pair not done."""


def execute_case(case: AnyCase, adapters: Sequence[Adapter], executor: Executor,
                 options: RunOptions, done: Pairs = frozenset()) -> Executed:
    """The truth of ``case`` once, then its outcome on each adapter not already done."""
    return execute_cases([(case, done)], adapters, executor, options)[0]


def execute_cases(items: Sequence[tuple[AnyCase, Pairs]], adapters: Sequence[Adapter],
                  executor: Executor, options: RunOptions,
                  truth: Callable[[AnyCase], Observation] = oracle.truth,
                  scored: bool = False) -> list[Executed]:
    """:func:`execute_case` of each ``(case, done pairs)``, the pairs run together: every
    pair without a declared hang in one :func:`~crosscheck.run.execute.run_calls`, then
    those with one, each probed on its own.  ``truth`` gives a case's exact truth (the
    oracle's, or a caller's memo of it).  ``scored``: on a worker pool, the workers score
    the pairs they answer (:class:`~crosscheck.run.execute.Judged`: their outcomes carry
    their rows as ``lines``)."""
    judged = scored and isinstance(executor, BatchExecutor)
    truths: list[Observation] = []
    slots: list[list[tuple[int, Outcome | int | None]]] = []
    calls: list[Call] = []
    for case, done in items:
        skipped = _quick_skip(case, options)
        truths.append(truth(case) if skipped is None else Observation())
        mine: list[tuple[int, Outcome | int | None]] = []
        for k, adapter in enumerate(adapters):
            if (case.id, adapter.name) in done:
                continue
            if skipped is not None or adapter.known_hang(case) is not None:
                mine.append((k, skipped))  # None: probed below
                continue
            mine.append((k, len(calls)))
            task = Judged(case, truths[-1]) if judged else case
            calls.append((adapter, task, case_options(case, options), False, frozenset()))
        slots.append(mine)
    answered = run_calls(executor, calls)
    return [Executed(case, truth, tuple(
        (k, answered[slot] if isinstance(slot, int)
         else slot or _execute(executor, adapters[k], case, options)) for k, slot in mine))
        for (case, _), truth, mine in zip(items, truths, slots, strict=True)]


def _quick_skip(case: AnyCase, options: RunOptions) -> Outcome | None:
    if isinstance(case, SceneCase) and options.skips(case.step_count):
        return Outcome(None, Status.SKIP, f"--quick runs scenes of at most {QUICK_SCENE_STEPS} "
                                          f"steps; this one takes {case.step_count}")
    return None


def _execute(executor: Executor, adapter: Adapter, case: AnyCase, options: RunOptions) -> Outcome:
    """Execute, probing a declared known hang under HANG_PROBE_S and saying so.

    The full query is probed first (a fixed engine answers it).  If the probe times out
    and the adapter names only some quantities as hanging, the query runs again without
    them under the run's limit; they are marked ``hung`` (the rest is its outcome).
    In-process (``isolate`` False) nothing could stop a hang, so the declared hanging
    quantities are never started (:func:`_skip_declared_hang`).
    """
    hang = adapter.known_hang(case)
    options = case_options(case, options)
    if hang is None:
        return executor(adapter, case, options)
    if not options.isolate:
        return _skip_declared_hang(executor, adapter, case, options, hang)
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


def _skip_declared_hang(executor: Executor, adapter: Adapter, case: AnyCase,
                        options: RunOptions, hang: str) -> Outcome:
    """In-process: the declared hanging quantities are ``skip`` rows naming the declaration;
    the others come from ``query_without`` them (all ``skip`` when every quantity hangs)."""
    reason = (f"declared known hang, not run in-process (--no-isolation has no time limit "
              f"to stop it): {hang}")
    every = frozenset(quantities_of(case.kind_enum))
    hanging = adapter.hanging_quantities(case) & every
    if not hanging or hanging == every:
        return Outcome(None, Status.SKIP, reason)
    rest = executor(adapter, case, options, False, hanging)
    return replace(rest, hung=hanging, hang_reason=reason, hang_status=Status.SKIP)
