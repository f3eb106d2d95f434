"""Executing one case on one adapter: prepare (untimed), query, and the calibrated timing loop.

This is what a worker process does for each task (see :mod:`crosscheck.worker`);
it also runs in-process for tests and for ``--no-isolation``.  An exception
raised by the engine becomes an ``error`` outcome with its reason.
"""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from adapters.base import Adapter
from crosscheck.model import Observation, Status
from crosscheck.schema import AnyCase
from crosscheck.timing import Timing, measure


@dataclass(frozen=True, slots=True)
class RunOptions:
    """How to run: ``quick`` skips timing; sample length and count otherwise.

    ``timeout_s`` limits one case x engine (prepare, query and timing) in its
    worker; ``isolate`` False runs engines in this process (no crash safety);
    ``time_per_group`` times only the first that many cases of each case
    file x kind x dim (0: every case), never swapped twins or bad input;
    ``timed_ids`` is that choice, made by the runner (None: time every case);
    ``jobs`` is the number of cases run at once; ``scheduler`` a Dask
    scheduler address to run cases on instead (see :mod:`crosscheck.distributed`).
    """

    quick: bool = False
    min_sample_s: float = 0.02
    samples: int = 5
    timeout_s: float = 5.0
    isolate: bool = True
    jobs: int = 1
    time_per_group: int = 3
    timed_ids: frozenset[str] | None = None
    scheduler: str | None = None


@dataclass(frozen=True, slots=True)
class Outcome:
    """What executing one case on one adapter gave: an observation, or a status and reason."""

    observation: Observation | None
    status: Status | None = None
    reason: str = ""
    setup_s: float = math.nan
    timing: Timing | None = None


def execute(adapter: Adapter, case: AnyCase, options: RunOptions) -> Outcome:
    """Prepare, query and (unless quick) time ``case`` on ``adapter``, in this process."""
    skip = _availability(adapter) or adapter.unsupported(case)
    if skip:
        return Outcome(None, Status.SKIP, skip)
    prepared: Any = None
    try:
        start = time.perf_counter()
        prepared = adapter.prepare(case)
        setup = time.perf_counter() - start
        observation = adapter.query(prepared)
        if observation.wall_s is not None:  # a scene: its one long run is the measurement
            timing: Timing | None = Timing(observation.wall_s, 0.0, 1, 1, 0.0, False)
        else:
            timing = None if options.quick else measure(
                lambda: adapter.query(prepared), min_sample_s=options.min_sample_s,
                samples=options.samples)
        return Outcome(observation, setup_s=setup, timing=timing)
    except Exception as exc:  # an engine fault is data, not a harness failure
        where = traceback.extract_tb(exc.__traceback__)[-1]
        return Outcome(None, Status.ERROR,
                        f"{type(exc).__name__}: {exc} (at {where.name}:{where.lineno})")
    finally:
        if prepared is not None:
            adapter.release(prepared)


_AVAILABLE: dict[int, tuple[Adapter, str | None]] = {}


def _availability(adapter: Adapter) -> str | None:
    """``adapter.available()``, asked once per adapter object (it cannot change in-process)."""
    known = _AVAILABLE.get(id(adapter))
    if known is None or known[0] is not adapter:
        known = _AVAILABLE[id(adapter)] = (adapter, adapter.available())
    return known[1]


Executor = Callable[[Adapter, AnyCase, RunOptions], Outcome]
"""Runs one case on one adapter: :func:`execute` in-process, or a worker pool's."""
