"""Scale-out over a Dask cluster: ``crosscheck run --scheduler tcp://host:8786``.

:class:`DaskLanes` is one of the :class:`~crosscheck.run.execute.Lanes`: a
context manager whose :meth:`~DaskLanes.map` applies ``fn(item, executor)``
to every item and yields the results as they finish, with a bounded window
of pending work.  Each item is submitted as one task to a
``dask.distributed.Client``; ``fn`` and the item must be picklable (the
runner sends a :class:`~crosscheck.run.runner.CaseJob` and a few cases,
``(case, done pairs of that case)`` each: :data:`~crosscheck.run.casework.ITEM_CASES`).

On each Dask worker the engines keep their isolation: every worker thread
has its own :class:`~crosscheck.run.worker.WorkerPool`, cached at module level
for the life of the Dask worker process, so engine clients are reused
across cases and a crash or hang of an engine is still a ``crash`` or
``timeout`` row, not a lost Dask worker.  The records stream back to the
client, which appends them to the run's :class:`~crosscheck.results.store.ResultsStore`.

Worker processes cannot start engine workers if they are daemonic, which
``dask worker`` (with its nanny) makes them by default: start workers with
``DASK_DISTRIBUTED__WORKER__DAEMON=False`` (or ``--no-nanny``), or pass
``--no-isolation``.

A worker lost in the middle of a run (killed, out of memory) costs nothing: the
scheduler runs its tasks again on another worker, and each task's records reach
the client once, from its one future, so a retried case is never written twice.
Losing the scheduler (or a task that killed every worker it ran on) raises
:class:`ClusterLost`, with the finished rows already in the store: the run
stops cleanly and ``--resume`` finishes it.

Dask is imported only when a scheduler is used (inside :class:`DaskLanes`): these
are the harness's only function-level imports besides the optional engines, because
``import distributed`` costs 0.32-0.40 s (``python -X importtime``, measured here)
against 0.54 s for the whole CLI, and a local run never needs it.
"""

from __future__ import annotations

import atexit
import contextlib
import logging
import multiprocessing as mp
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import CancelledError
from typing import TYPE_CHECKING, TypeVar

from crosscheck.core.options import RunOptions
from crosscheck.run.execute import Executor, execute
from crosscheck.run.worker import WorkerPool

if TYPE_CHECKING:
    from distributed import Client, Future

T = TypeVar("T")
R = TypeVar("R")

DAEMON_HINT = ("this Dask worker is a daemonic process and cannot start engine worker "
               "processes: start workers with DASK_DISTRIBUTED__WORKER__DAEMON=False "
               "(or 'dask worker --no-nanny'), or run with --no-isolation")


class ClusterLost(RuntimeError):
    """The Dask scheduler cannot be reached, or was lost in the middle of the run."""


# --- on each Dask worker --------------------------------------------------------------------

_local = threading.local()
_pools: list[WorkerPool] = []
_pools_lock = threading.Lock()


def _close_pools() -> None:
    with _pools_lock:
        for pool in _pools:
            pool.close()
        _pools.clear()


atexit.register(_close_pools)


def worker_executor(options: RunOptions) -> Executor:
    """This thread's executor in this process: its cached WorkerPool, or in-process."""
    if not options.isolate:
        return execute
    pool: WorkerPool | None = getattr(_local, "pool", None)
    if pool is None:
        if mp.current_process().daemon:
            raise RuntimeError(DAEMON_HINT)
        pool = _local.pool = WorkerPool(options)
        with _pools_lock:
            _pools.append(pool)
    return pool


def _remote(fn: Callable[[T, Executor], R], item: T, options: RunOptions) -> R:
    """The task run on a Dask worker: ``fn(item, executor)`` with this worker's executor."""
    return fn(item, worker_executor(options))


# --- on the client --------------------------------------------------------------------------

class _OneLine(logging.Filter):
    """Keep the Dask client's own log lines, without their tracebacks: a lost connection is
    reported by :class:`ClusterLost`, in one message with the resume hint."""

    def filter(self, record: logging.LogRecord) -> bool:
        record.exc_info, record.exc_text = None, None
        return True


_QUIET = _OneLine()
_CLIENT_LOGGERS = ("distributed.client", "distributed.comm", "distributed.core")


class DaskLanes:
    """Lanes on a Dask cluster: every item is a task on ``options.scheduler``.

    :meth:`map` keeps at most twice the larger of ``jobs`` and the cluster's
    thread count tasks pending and yields results as they finish.
    """

    def __init__(self, options: RunOptions) -> None:
        if not options.scheduler:
            raise ValueError("DaskLanes needs options.scheduler (a scheduler address)")
        self.options = options
        self.address = options.scheduler
        self._client: Client | None = None

    def __enter__(self) -> DaskLanes:
        from distributed import Client

        try:
            client = Client(self.address, set_as_default=False)  # type: ignore[no-untyped-call]
        except OSError as exc:
            raise ClusterLost(f"cannot reach the Dask scheduler {self.address}: {exc}") from exc
        self._client = client
        for name in _CLIENT_LOGGERS:
            logging.getLogger(name).addFilter(_QUIET)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._client is not None:
            with contextlib.suppress(OSError, TimeoutError):  # a lost scheduler: nothing to close
                self._client.close(timeout=5)  # type: ignore[no-untyped-call]
            self._client = None
        for name in _CLIENT_LOGGERS:  # after closing: closing a lost client logs its retries
            logging.getLogger(name).removeFilter(_QUIET)

    def _window(self, client: Client) -> int:
        threads: dict[str, int] = client.nthreads()  # type: ignore[no-untyped-call]
        return 2 * max(1, self.options.jobs, sum(threads.values()))

    def map(self, fn: Callable[[T, Executor], R], items: Iterable[T]) -> Iterator[R]:
        """Yield ``fn(item, executor)`` for every item, run on the cluster, as they finish.

        Raises :class:`ClusterLost` when the scheduler is lost (its tasks are
        cancelled) or a task killed every worker it was given.
        """
        from distributed import KilledWorker

        try:
            yield from self._map(fn, items)
        except (CancelledError, KilledWorker, OSError) as exc:
            # the client's attempts to reconnect, cancelled as it closes, would print their
            # tracebacks; ClusterLost says what happened
            logging.getLogger("distributed").setLevel(logging.CRITICAL)
            raise ClusterLost(f"the Dask cluster at {self.address} was lost in the middle "
                              f"of the run ({type(exc).__name__}: {exc})") from exc

    def _map(self, fn: Callable[[T, Executor], R], items: Iterable[T]) -> Iterator[R]:
        from distributed import as_completed

        client = self._client
        if client is None:
            raise RuntimeError("use DaskLanes as a context manager")
        window = self._window(client)
        pending: as_completed = as_completed(loop=client.loop)  # type: ignore[no-untyped-call]
        count = 0
        try:
            for item in items:
                future: Future[R] = client.submit(_remote, fn, item, self.options, pure=False)
                pending.add(future)  # type: ignore[no-untyped-call]
                count += 1
                if count >= window:
                    done = next(pending)
                    count -= 1
                    yield done.result()
            for done in pending:
                yield done.result()
        finally:
            pending.clear()  # type: ignore[no-untyped-call]
