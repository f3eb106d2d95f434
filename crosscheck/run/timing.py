"""Calibrated timing loops, in the manner of pyperf.

The loop count is calibrated until one sample lasts at least ``min_sample_s``;
warm-up samples are discarded; the median and interquartile range of the
per-call times of the kept samples are reported.  The cost of the loop itself
(an empty call, measured the same way) is subtracted and reported.  A
measurement whose IQR exceeds ``UNSTABLE_SPREAD`` of its median is flagged
unstable.

>>> t = measure(lambda: sum(range(10)), min_sample_s=0.001, samples=3)
>>> t.loops >= 1 and t.median_s > 0
True
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

UNSTABLE_SPREAD = 0.10
"""IQR / median above which a measurement is flagged unstable."""


@dataclass(frozen=True, slots=True)
class Timing:
    """Per-call time of one function, net of the loop's own cost."""

    median_s: float
    iqr_s: float
    loops: int
    samples: int
    overhead_s: float
    unstable: bool


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


def _quartiles(xs: list[float]) -> tuple[float, float, float]:
    if len(xs) < 2:
        return xs[0], xs[0], xs[0]
    q1, q2, q3 = statistics.quantiles(xs, n=4, method="inclusive")
    return q1, q2, q3


def measure(fn: Callable[[], object], *, min_sample_s: float = 0.02, samples: int = 5,
            warmups: int = 1) -> Timing:
    """Time ``fn``: calibrate, warm up, keep ``samples`` samples, subtract loop overhead."""
    loops = calibrate(fn, min_sample_s)
    for _ in range(warmups):
        _sample(fn, loops)
    kept = [_sample(fn, loops) for _ in range(samples)]
    overhead = statistics.median(_sample(_nothing, loops) for _ in range(3))
    net = [max(0.0, x - overhead) for x in kept]
    q1, median, q3 = _quartiles(net)
    unstable = median <= 0 or (q3 - q1) > UNSTABLE_SPREAD * median
    return Timing(median, q3 - q1, loops, samples, overhead, unstable)
