"""Calibrated timing loops, in the manner of pyperf, keeping every sample; the machine yardstick.

The loop count is calibrated until one sample lasts at least ``min_sample_s``;
warm-up samples are discarded; every kept sample (the per-call time, net of
the loop's own cost, measured the same way on an empty call) is returned, with
the median and quartiles of :func:`crosscheck.results.timings.spread`.  A
measurement whose IQR exceeds 10% of its median is flagged unstable.

:func:`measure` does it all at once (the binding probe).  The timing phase's
rounds (:mod:`crosscheck.run.rounds`) split it: :func:`calibration` once per pair
(loops, warm-up, the empty loop's cost), then :func:`one_sample` once per round.
:func:`yardstick` times two fixed workloads, a numpy sort and a pure-Python loop:
the machine's speed at that moment.  The garbage collector is off while a sample
is taken, as :mod:`timeit` does: a collection landing in one sample and not in
another is noise, not the engine's cost.

>>> t = measure(lambda: sum(range(10)), min_sample_s=0.001, samples=3)
>>> t.loops >= 1 and len(t.values) == 3
True
>>> c = calibration(lambda: sum(range(10)), min_sample_s=0.001)
>>> c.values, len(one_sample(lambda: sum(range(10)), c).values)
((), 1)
>>> sorted(yardstick(2)), len(yardstick(2)["numpy"].values)
(['numpy', 'python'], 2)
"""

from __future__ import annotations

import gc
import statistics
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace

import numpy as np

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


@contextmanager
def _collector_off() -> Iterator[None]:
    """The garbage collector off for the block (back on after it, if it was on)."""
    collecting = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if collecting:
            gc.enable()


def calibration(fn: Callable[[], object], *, min_sample_s: float = 0.0025,
                warmups: int = 1) -> Timing:
    """A measurement of ``fn`` with no sample yet: its calibrated loop count and the empty
    loop's cost per call at that count, after ``warmups`` samples discarded."""
    with _collector_off():
        loops = calibrate(fn, min_sample_s)
        for _ in range(warmups):
            _sample(fn, loops)
        overhead = statistics.median(_sample(_nothing, loops) for _ in range(3))
    return Timing((), loops, overhead)


def one_sample(fn: Callable[[], object], calibrated: Timing) -> Timing:
    """``calibrated`` with one sample of ``fn`` as its values: ``calibrated.loops`` calls,
    per call, net of the empty loop's cost."""
    with _collector_off():
        value = _sample(fn, calibrated.loops)
    return replace(calibrated, values=(max(0.0, value - calibrated.overhead_s),))


def measure(fn: Callable[[], object], *, min_sample_s: float = 0.0025, samples: int = 20,
            warmups: int = 1) -> Timing:
    """Time ``fn``: calibrate, warm up, keep ``samples`` samples, subtract loop overhead."""
    with _collector_off():
        loops = calibrate(fn, min_sample_s)
        for _ in range(warmups):
            _sample(fn, loops)
        kept = [_sample(fn, loops) for _ in range(samples)]
        overhead = statistics.median(_sample(_nothing, loops) for _ in range(3))
    return Timing(tuple(max(0.0, x - overhead) for x in kept), loops, overhead)


# --- the machine yardstick ---------------------------------------------------------------------


_ARRAY = np.random.default_rng(12345).random(20_000)


def _numpy_kernel() -> object:
    return np.sort(_ARRAY)


def _python_loop() -> object:
    total = 0
    for i in range(2_000):
        total += i * i
    return total


WORKLOADS: dict[str, Callable[[], object]] = {"numpy": _numpy_kernel, "python": _python_loop}
"""The yardstick's fixed workloads: a numpy sort of 20,000 floats, a 2,000-step Python loop."""


def yardstick(samples: int, calibrated: Mapping[str, Timing] | None = None,
              min_sample_s: float = 0.0025) -> dict[str, Timing]:
    """The machine's speed now: ``samples`` samples of each of :data:`WORKLOADS`, with the
    loops of ``calibrated`` (None: calibrated now, after one warm-up sample)."""
    found = {}
    for name, fn in WORKLOADS.items():
        base = (calibrated[name] if calibrated and name in calibrated
                else calibration(fn, min_sample_s=min_sample_s))
        values = tuple(one_sample(fn, base).values[0] for _ in range(samples))
        found[name] = replace(base, values=values)
    return found
