"""Calibrated timing loops, in the manner of pyperf, keeping every sample.

The loop count is calibrated until one sample lasts at least ``min_sample_s``;
warm-up samples are discarded; every kept sample (the per-call time, net of
the loop's own cost, measured the same way on an empty call) is returned, with
the median and quartiles of :func:`crosscheck.results.timings.spread`.  A
measurement whose IQR exceeds 10% of its median is flagged unstable.

>>> t = measure(lambda: sum(range(10)), min_sample_s=0.001, samples=3)
>>> t.loops >= 1 and t.median_s > 0 and len(t.values) == 3
True
"""

from __future__ import annotations

import gc
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from crosscheck.results.timings import spread


@dataclass(frozen=True, slots=True)
class Timing:
    """Every kept sample of one measurement (seconds per call, or per scene run)."""

    values: tuple[float, ...]
    loops: int
    overhead_s: float
    unit: str = "call"

    @property
    def median_s(self) -> float:
        return spread(self.values).median

    @property
    def iqr_s(self) -> float:
        return spread(self.values).iqr if len(self.values) > 1 else float("nan")

    @property
    def unstable(self) -> bool:
        return len(self.values) > 1 and spread(self.values).unstable

    @classmethod
    def of_runs(cls, walls: Sequence[float]) -> Timing:
        """The timing of whole runs (a scene stepped ``len(walls)`` times)."""
        return cls(tuple(walls), 1, 0.0, "scene")


def _sample(fn: Callable[[], object], loops: int) -> float:
    clock = time.perf_counter
    start = clock()
    for _ in range(loops):
        fn()
    return (clock() - start) / loops


def calibrate(fn: Callable[[], object], min_sample_s: float, max_loops: int = 10**7) -> int:
    """The loop count for which one sample of ``fn`` lasts at least ``min_sample_s``."""
    loops = 1
    while loops < max_loops:
        elapsed = _sample(fn, loops) * loops
        if elapsed >= min_sample_s:
            return loops
        factor = 2.0 if elapsed <= 0 else min(10.0, 1.2 * min_sample_s / elapsed)
        loops = min(max_loops, max(loops + 1, int(loops * factor)))
    return loops


def _nothing() -> None:
    return None


def measure(fn: Callable[[], object], *, min_sample_s: float = 0.0025, samples: int = 20,
            warmups: int = 1) -> Timing:
    """Time ``fn``: calibrate, warm up, keep ``samples`` samples, subtract loop overhead.

    The garbage collector is off while it measures, as :mod:`timeit` does: a collection
    landing in one sample and not in another is noise, not the engine's cost.
    """
    collecting = gc.isenabled()
    gc.disable()
    try:
        loops = calibrate(fn, min_sample_s)
        for _ in range(warmups):
            _sample(fn, loops)
        kept = [_sample(fn, loops) for _ in range(samples)]
        overhead = statistics.median(_sample(_nothing, loops) for _ in range(3))
    finally:
        if collecting:
            gc.enable()
    return Timing(tuple(max(0.0, x - overhead) for x in kept), loops, overhead)
