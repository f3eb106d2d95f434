"""The timing phase: after the verdict pass, measure a representative sample in quiet.

One case x engine at a time (no other lane, no scoring competing for the
cores), in the engine's own worker, pinned to one core and the harness to
another where the OS allows it:

1. the machine yardstick (a fixed numpy kernel and a fixed pure-Python loop);
2. per engine: the cheapest call into its binding (``Adapter.binding_call``),
   then its sample: per kind, ``timing_cases`` cases drawn at random (seeded)
   from every case family, leaving out swapped twins (the same work), bad input
   and pairs that failed in the verdict pass; scenes only up to
   :data:`SCENE_LIMIT_S` per run, ``scene_repeats`` runs each;
3. the yardstick again, so the report shows whether the machine drifted.

Every kept sample goes to ``timings.jsonl`` as it is measured (a resumed run
skips what is there); the method, the pinning, the yardsticks and the binding
costs go to ``run.json`` (``RunInfo.timing``).
"""

from __future__ import annotations

import os
import random
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np
import pandas as pd

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.store import ResultsStore, read_results
from crosscheck.results.timings import TimingRecord, spread
from crosscheck.run.execute import Outcome, case_options, execute, probe_binding
from crosscheck.run.timing import Timing, measure
from crosscheck.run.worker import WorkerPool, pin

SCENE_LIMIT_S = 0.2
"""Scenes whose one run in the verdict pass took longer are not re-timed (budget)."""

Tick = Callable[[int], None]
Pair = tuple[AnyCase, Adapter]


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
    return (f"after the verdict pass, one case at a time: per engine x kind, up to "
            f"{options.timing_cases} cases drawn at random (seed {options.timing_seed}) from "
            "every case family, leaving out swapped twins, bad input and pairs that failed; "
            f"each query in a loop calibrated to at least {options.min_sample_s * 1e3:g} ms per "
            f"sample, 1 warm-up sample discarded, {options.samples} samples kept, the empty "
            f"loop's cost subtracted; scenes of at most {SCENE_LIMIT_S:g} s per run are run "
            f"{options.scene_repeats} times")


# --- the yardstick ----------------------------------------------------------------------------


_ARRAY = np.random.default_rng(12345).random(20_000)


def _numpy_kernel() -> object:
    return np.sort(_ARRAY)


def _python_loop() -> object:
    total = 0
    for i in range(2_000):
        total += i * i
    return total


def _summary(timing: Timing) -> dict[str, Any]:
    s = spread(timing.values)
    return {"median_s": s.median, "q1_s": s.q1, "q3_s": s.q3, "values": list(timing.values)}


def yardstick(options: RunOptions) -> dict[str, dict[str, Any]]:
    """The machine's speed now: a fixed numpy sort and a fixed pure-Python loop."""
    return {name: _summary(measure(fn, min_sample_s=options.min_sample_s,
                                   samples=options.samples))
            for name, fn in (("numpy", _numpy_kernel), ("python", _python_loop))}


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


class _Measurer:
    """Runs timed cases and binding probes, in workers (``isolate``) or in this process."""

    def __init__(self, options: RunOptions, cpu: int | None) -> None:
        self.options = options
        self.pool = WorkerPool(options, cpu) if options.isolate else None
        if self.pool is None:
            pin(0, cpu)

    def case(self, adapter: Adapter, case: AnyCase) -> Outcome:
        options = case_options(case, self.options)
        if self.pool is None:
            return execute(adapter, case, options, True)
        return self.pool.execute(adapter, case, options, True)

    def binding(self, adapter: Adapter) -> Timing | str:
        if self.pool is None:
            return probe_binding(adapter, self.options)
        return self.pool.binding(adapter, self.options)

    def close(self) -> None:
        if self.pool is not None:
            self.pool.close()


def _record(case: AnyCase, adapter: Adapter, timing: Timing) -> TimingRecord:
    return TimingRecord(case.id, adapter.name, case.kind, timing.unit, timing.loops,
                        timing.overhead_s, timing.values)


def _binding(found: Timing | str) -> dict[str, Any]:
    return {"none": found} if isinstance(found, str) else _summary(found)


def time_phase(store: ResultsStore, cases: Sequence[AnyCase], engines: Sequence[Adapter],
               options: RunOptions, start: Callable[[int], Tick] | None = None) -> dict[str, Any]:
    """Measure the sample into ``store`` (skipping pairs already timed); the run.json section.

    ``start(total)`` is told how many pairs are to be timed and returns the
    function to call as each finishes (a progress bar).
    """
    sample = timing_sample(cases, engines, read_results(store.directory), options)
    todo = [(c, a) for c, a in sample if (c.id, a.name) not in store.timed]
    tick = start(len(todo)) if start else None
    with _pinned(options) as (cpu, pinned):
        before = yardstick(options)
        measurer = _Measurer(options, cpu)
        binding: dict[str, dict[str, Any]] = {}
        failed = 0
        try:
            for adapter in engines:
                binding[adapter.name] = _binding(measurer.binding(adapter))
                for case, _ in (p for p in todo if p[1] is adapter):
                    outcome = measurer.case(adapter, case)
                    if outcome.timing is None:
                        failed += 1
                    else:
                        store.append_timing(_record(case, adapter, outcome.timing))
                    if tick:
                        tick(1)
        finally:
            measurer.close()
        after = yardstick(options)
    return {"method": method(options), "sampled": len(sample), "failed": failed,
            "pinned": pinned, "yardstick": {"start": before, "end": after},
            "binding": binding}

