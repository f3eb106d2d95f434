"""Lanes of execution: ``jobs`` cases at once on this machine, each lane with its own executor.

:class:`LocalLanes` is the runner's and the repeat check's way to run items in parallel
here (the Dask lanes are :mod:`crosscheck.run.distributed`): each lane has its own
:class:`~crosscheck.run.worker.WorkerPool` (or, with ``--no-isolation``, runs in this
process), and results are yielded as they finish.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, as_completed, wait
from typing import TypeVar

from crosscheck.core.options import RunOptions
from crosscheck.run.execute import Executor, execute, stop_between_items
from crosscheck.run.worker import WorkerPool

T = TypeVar("T")
R = TypeVar("R")


class LocalLanes:
    """``jobs`` lanes of execution, each with its own executor (a WorkerPool, or in-process).

    :meth:`map` applies ``fn(item, executor)`` to every item, at most ``jobs``
    at a time, and yields results as they finish (a bounded window, so a
    long run never holds every pending item at once).
    """

    def __init__(self, options: RunOptions) -> None:
        self.options = options
        self._local = threading.local()
        self._pools: list[WorkerPool] = []
        self._lock = threading.Lock()

    def __enter__(self) -> LocalLanes:
        return self

    def __exit__(self, *exc: object) -> None:
        for pool in self._pools:
            pool.close()

    def _executor(self) -> Executor:
        if not self.options.isolate:
            return execute
        pool: WorkerPool | None = getattr(self._local, "pool", None)
        if pool is None:
            pool = self._local.pool = WorkerPool(self.options)
            with self._lock:
                self._pools.append(pool)
        return pool

    def _call(self, fn: Callable[[T, Executor], R], item: T) -> R:
        return fn(item, self._executor())

    def map(self, fn: Callable[[T, Executor], R], items: Iterable[T]) -> Iterator[R]:
        """Yield ``fn(item, executor)`` for every item, as they finish.

        In-process (``isolate`` False), Ctrl-C stops between items: the first SIGINT lets
        the items in flight finish and be yielded, starts no other, then raises
        KeyboardInterrupt; a second SIGINT raises at once.  (A worker process can be
        killed at any moment, an engine in this process cannot: interrupted mid-query it
        may be left half-changed, and one stuck in C never sees the signal at all.)
        """
        jobs = max(1, self.options.jobs)
        with stop_between_items(not self.options.isolate) as stop:
            if jobs == 1:
                for item in items:
                    if stop.is_set():
                        break
                    yield fn(item, self._executor())
            else:
                yield from self._threaded(fn, items, jobs, stop)
            if stop.is_set():
                raise KeyboardInterrupt

    def _threaded(self, fn: Callable[[T, Executor], R], items: Iterable[T], jobs: int,
                  stop: threading.Event) -> Iterator[R]:
        with ThreadPoolExecutor(max_workers=jobs) as threads:
            pending: set[Future[R]] = set()
            for item in items:
                if stop.is_set():
                    break
                pending.add(threads.submit(self._call, fn, item))
                if len(pending) >= 2 * jobs:
                    finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                    yield from (f.result() for f in finished)
            if stop.is_set():  # items not started yet stay for --resume
                for future in pending:
                    future.cancel()
            for future in as_completed(pending):
                if not future.cancelled():
                    yield future.result()
