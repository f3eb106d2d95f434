"""The timing phase: after the verdict pass, measure a representative sample in quiet.

In the engines' own workers (no other lane, no scoring competing for the cores),
pinned to one core and the harness to another where the OS allows it:

1. the sample: per engine x kind, ``timing_cases`` cases drawn at random (seeded)
   from every case family, leaving out swapped twins (the same work), bad input
   and pairs that failed in the verdict pass; scenes only up to
   :data:`SCENE_LIMIT_S` per run;
2. the interleaved rounds (:mod:`crosscheck.run.rounds`): round 0 probes each
   engine's binding (``Adapter.binding_call``) and calibrates each pair; then every
   round takes one sample of every pair, engine after engine, and reads the machine
   yardstick (a fixed numpy kernel and a fixed pure-Python loop) on the engines' CPU,
   so that every engine's samples span the same stretch of the machine's drift, and
   each sample is stored with its round's yardstick.

Every pair goes to ``timings.jsonl`` as soon as it is complete (a resumed run skips
what is there); the method, the pinning, the yardsticks (at the start and the end,
and per round with the drift they measured) and the binding costs go to ``run.json``
(``RunInfo.timing``).
"""

from __future__ import annotations

import os
import random
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import replace
from typing import Any

import pandas as pd

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.run import Run
from crosscheck.results.store import ResultsStore
from crosscheck.run.execute import Outcome, Step, Yardstick, case_options, probe_binding, time_step
from crosscheck.run.rounds import Pair, Sampler, Tick, run_rounds, steps
from crosscheck.run.timing import Timing
from crosscheck.run.worker import WorkerPool, pin

SCENE_LIMIT_S = 0.2
"""Scenes whose one run in the verdict pass took longer are not re-timed (budget)."""


# --- the sample -----------------------------------------------------------------------------


def _eligible(frame: pd.DataFrame) -> set[tuple[str, str]]:
    """Pairs whose verdict rows hold no failure or skip, scenes fast enough to repeat."""
    if frame.empty:
        return set()
    failing = frame["status"].isin(Status.members("failed_or_skipped")) | (
        (frame["kind"] == "sphere_scene") & ~(frame["query_s"] <= SCENE_LIMIT_S))
    pairs = set(zip(frame["case_id"], frame["engine"], strict=True))
    bad = set(zip(frame.loc[failing, "case_id"], frame.loc[failing, "engine"], strict=True))
    return {(str(c), str(e)) for c, e in pairs - bad}


def timing_sample(cases: Sequence[AnyCase], engines: Sequence[Adapter], frame: pd.DataFrame,
                  options: RunOptions) -> list[Pair]:
    """Per engine x kind, up to ``options.timing_cases`` eligible cases drawn at random
    (seeded by ``options.timing_seed``, the engine and the kind), in suite order."""
    ok = _eligible(frame)
    chosen: list[Pair] = []
    for adapter in engines:
        kinds: dict[str, list[AnyCase]] = {}
        for case in cases:
            if (not case.twin_of and not case.bad_input and (case.id, adapter.name) in ok):
                kinds.setdefault(case.kind, []).append(case)
        for kind, pool in kinds.items():
            rng = random.Random(f"{options.timing_seed}:{adapter.name}:{kind}")
            picked = set(map(id, rng.sample(pool, min(options.timing_cases, len(pool)))))
            chosen += [(case, adapter) for case in pool if id(case) in picked]
    return chosen


def method(options: RunOptions) -> str:
    """The timing method in words, for run.json and the report."""
    return (f"after the verdict pass, in interleaved rounds: per engine x kind, up to "
            f"{options.timing_cases} cases drawn at random (seed {options.timing_seed}) from "
            "every case family, leaving out swapped twins, bad input and pairs that failed; "
            f"round 0 calibrates each query's loop to at least {options.min_sample_s * 1e3:g} "
            "ms per sample and discards 1 warm-up sample; then each round takes one sample of "
            "every case x engine, engine after engine, prepared anew, the empty loop's cost "
            f"subtracted, for {options.samples} rounds (scenes of at most {SCENE_LIMIT_S:g} s "
            f"per run: one run a round, {options.scene_repeats} runs), and reads the machine "
            "yardstick on the engines' CPU between rounds, stored with each sample")


# --- measuring ---------------------------------------------------------------------------------


@contextmanager
def _pinned(options: RunOptions) -> Iterator[tuple[int | None, str]]:
    """The CPU for engine workers, with this process moved to another one (restored after)."""
    allowed = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    unpinned = ("pinning off (--no-pin)" if not options.pin
                else "not pinned: the OS does not allow it" if not allowed
                else "not pinned: one CPU available" if len(allowed) < 2 else "")
    if unpinned:
        yield None, unpinned
        return
    worker_cpu, own_cpu = allowed[-1], allowed[0]
    if not pin(0, own_cpu):
        yield None, "not pinned: the OS refused"
        return
    try:
        yield worker_cpu, f"engine workers pinned to CPU {worker_cpu}, the harness to {own_cpu}"
    finally:
        os.sched_setaffinity(0, set(allowed))


class Measurer:
    """The real :class:`~crosscheck.run.rounds.Sampler`: steps, binding probes and the
    yardstick in workers on ``cpu`` (``isolate``), or in this process, moved to ``cpu``."""

    def __init__(self, options: RunOptions, cpu: int | None) -> None:
        self.options = options
        self.pool = WorkerPool(options, cpu) if options.isolate else None
        self.loops: dict[str, Timing] | None = None  # the yardstick's, once calibrated
        if self.pool is None:
            pin(0, cpu)

    def step(self, adapter: Adapter, case: AnyCase, calibrated: Timing | None) -> Outcome:
        options = case_options(case, self.options)
        if self.pool is None:
            return time_step(adapter, case, options, calibrated)
        return self.pool.execute(adapter, Step(case, calibrated), options, True)

    def binding(self, adapter: Adapter) -> Timing | str:
        if self.pool is None:
            return probe_binding(adapter, self.options)
        return self.pool.binding(adapter, self.options)

    def yardstick(self, samples: int) -> dict[str, Timing] | str:
        task = Yardstick(samples, self.loops)
        found = task.measure(self.options) if self.pool is None else self.pool.yardstick(
            task, self.options)
        if self.loops is None and not isinstance(found, str):
            self.loops = {name: replace(t, values=()) for name, t in found.items()}
        return found

    def close(self) -> None:
        if self.pool is not None:
            self.pool.close()


SamplerFactory = Callable[[RunOptions, int | None], Sampler]
"""Makes the phase's sampler from the options and the engines' CPU (None: not pinned)."""


def time_phase(store: ResultsStore, run: Run, engines: Sequence[Adapter],
               options: RunOptions, start: Callable[[int], Tick] | None = None, *,
               sampler: SamplerFactory = Measurer) -> dict[str, Any]:
    """Measure the sample of ``run``'s rows into ``store`` (skipping pairs already timed); the
    run.json section.

    ``start(total)`` is told how many steps are to be taken (per pair: its calibration
    and each of its samples, :func:`crosscheck.run.rounds.steps`) and returns the
    function to call as they are taken (a progress bar).  ``sampler`` measures: the
    engines' workers, or injected times in tests.
    """
    sample = timing_sample(list(run.cases.values()), engines, run.results, options)
    todo = [(c, a) for c, a in sample if (c.id, a.name) not in store.timed]
    tick = start(steps(todo, options)) if start else None
    with _pinned(options) as (cpu, pinned):
        measurer = sampler(options, cpu)
        try:
            rounds = run_rounds(store, todo, engines, options, measurer, tick)
        finally:
            measurer.close()
    return {"method": method(options), "sampled": len(sample), "pinned": pinned,
            **rounds.section()}
