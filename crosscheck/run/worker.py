"""Isolation: each engine runs in its own worker process, so a crash or hang costs one case.

A :class:`WorkerPool` keeps one long-lived worker per adapter (engine clients
such as a PyBullet connection live there and are reused across cases).  Each
task is sent over a pipe; the parent waits at most ``timeout_s``:

- an answer: the :class:`~crosscheck.run.execute.Outcome` of the case;
- the pipe closes (the worker died: segfault, abort, ``os._exit``): a
  ``crash`` outcome naming the signal or exit code;
- no answer in time: the worker is killed and the outcome is ``timeout``.

A dead or killed worker is replaced on the next task.  Workers are started by
the ``forkserver`` method, which is safe with the parent's threads (the
progress bar) and cheap to restart.  Their C-level stdout and stderr go to
/dev/null, so engine banners and warnings never reach the CLI.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import os
import signal
import sys
import threading
import types
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, as_completed, wait
from multiprocessing.connection import Connection
from multiprocessing.process import BaseProcess
from typing import Any, TypeVar

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.run.execute import Executor, Outcome, execute, probe_binding
from crosscheck.run.timing import Timing

_CONTEXT = mp.get_context("forkserver")
_CONTEXT.set_forkserver_preload(["crosscheck.run.execute"])
_START_LOCK = threading.Lock()

BINDING = "binding"
Task = tuple[type[Adapter], AnyCase | str | None, RunOptions, bool, frozenset[str]]
"""What a worker is sent: a case to run (whether to time it, the quantities to skip),
``None`` to warm up, or :data:`BINDING` to time the cheapest call into the engine."""

STARTUP_TIMEOUT_S = 120.0
"""Time a new worker may take to start and load its engine; not charged to any case."""


def _silence_output() -> None:
    devnull = os.open(os.devnull, os.O_WRONLY)
    for fd in (1, 2):
        os.dup2(devnull, fd)
    os.close(devnull)


def _serve(conn: Connection) -> None:
    """Worker main loop: run tasks until the parent closes the pipe.

    Ctrl-C is the parent's to handle: a worker ignores SIGINT, so an
    interrupted run never records a worker's death as an engine crash.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _silence_output()
    adapters: dict[type[Adapter], Adapter] = {}
    while True:
        try:
            cls, case, options, timed, skip = conn.recv()
        except (EOFError, OSError):
            return
        adapter = adapters.setdefault(cls, cls())
        if case is None:  # warm-up: import the engine and connect, outside any case's time
            adapter.available()
            conn.send(None)
        elif isinstance(case, str):
            conn.send(probe_binding(adapter, options))
        else:
            conn.send(execute(adapter, case, options, timed, skip))


@contextlib.contextmanager
def _without_main() -> Iterator[None]:
    """Start a worker without telling it the parent's main module.

    A new process normally re-imports ``__main__`` (for the CLI: the whole CLI,
    pandas included, ~0.4 s per worker start or restart after a crash).  A
    worker needs only :func:`_serve`, importable by name, so it is started while
    ``__main__`` is a bare module.
    """
    saved = sys.modules["__main__"]
    sys.modules["__main__"] = types.ModuleType("__main__")
    try:
        yield
    finally:
        sys.modules["__main__"] = saved


def _death(code: int | None) -> str:
    if code is None:
        return "worker died"
    if code < 0:
        try:
            return f"worker killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"worker killed by signal {-code}"
    return f"worker exited with code {code}"


class _Worker:
    """One worker process and its pipe."""

    def __init__(self) -> None:
        self.conn, child = _CONTEXT.Pipe()
        self.process: BaseProcess = _CONTEXT.Process(target=_serve, args=(child,), daemon=True)
        with _START_LOCK, _without_main():
            self.process.start()
        child.close()

    def call(self, task: Task, timeout_s: float) -> Any:
        try:
            self.conn.send(task)
            if not self.conn.poll(timeout_s):
                self.kill()
                return Outcome(None, Status.TIMEOUT, f"no answer within {timeout_s:g} s")
            return self.conn.recv()
        except (EOFError, OSError, BrokenPipeError):
            self.process.join(timeout=2)
            return Outcome(None, Status.CRASH, _death(self.process.exitcode))

    def alive(self) -> bool:
        return self.process.is_alive()

    def kill(self) -> None:
        if self.process.is_alive():
            self.process.kill()
        self.process.join(timeout=5)
        self.conn.close()

    def close(self) -> None:
        self.conn.close()
        self.process.join(timeout=2)
        if self.process.is_alive():
            self.kill()


def pin(pid: int, cpu: int | None) -> bool:
    """Pin process ``pid`` (0: this one) to ``cpu`` where the OS allows it; whether it did."""
    if cpu is None or not hasattr(os, "sched_setaffinity"):
        return False
    try:
        os.sched_setaffinity(pid, {cpu})
    except OSError:
        return False
    return True


class WorkerPool:
    """One worker per adapter, restarted after a crash or timeout (pinned to ``cpu`` if given)."""

    def __init__(self, options: RunOptions, cpu: int | None = None) -> None:
        self.options = options
        self.cpu = cpu
        self._workers: dict[str, _Worker] = {}

    def _worker(self, adapter: Adapter, options: RunOptions) -> _Worker | Outcome:
        """The adapter's live worker, started (and warmed up) if need be; or why it cannot."""
        worker = self._workers.get(adapter.name)
        if worker is None or not worker.alive():
            worker = self._workers[adapter.name] = _Worker()
            pin(worker.process.pid or 0, self.cpu)
            started = worker.call((type(adapter), None, options, False, frozenset()),
                                  STARTUP_TIMEOUT_S)
            if started is not None:  # the worker could not even start: that case's outcome
                del self._workers[adapter.name]
                assert isinstance(started, Outcome)
                return started
        return worker

    def binding(self, adapter: Adapter, options: RunOptions) -> Timing | str:
        """The cost of the cheapest call into the adapter's engine, measured in its worker."""
        worker = self._worker(adapter, options)
        if isinstance(worker, Outcome):
            return worker.reason
        answer = worker.call((type(adapter), BINDING, options, True, frozenset()),
                             options.timeout_s)
        if isinstance(answer, Outcome):  # it hung or died
            worker.kill()
            del self._workers[adapter.name]
            return answer.reason
        assert isinstance(answer, Timing | str)
        return answer

    def execute(self, adapter: Adapter, case: AnyCase, options: RunOptions,
                timed: bool = False, skip: frozenset[str] = frozenset()) -> Outcome:
        """Run ``case`` on ``adapter`` (without the quantities in ``skip``) in the adapter's
        worker, within the time limit."""
        worker = self._worker(adapter, options)
        if isinstance(worker, Outcome):
            return worker
        outcome = worker.call((type(adapter), case, options, timed, skip), options.timeout_s)
        assert isinstance(outcome, Outcome)
        if outcome.status in (Status.CRASH, Status.TIMEOUT):
            worker.kill()
            del self._workers[adapter.name]
        return outcome

    def close(self) -> None:
        """Stop every worker."""
        for worker in self._workers.values():
            worker.close()
        self._workers.clear()


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
        return pool.execute

    def _call(self, fn: Callable[[T, Executor], R], item: T) -> R:
        return fn(item, self._executor())

    def map(self, fn: Callable[[T, Executor], R], items: Iterable[T]) -> Iterator[R]:
        """Yield ``fn(item, executor)`` for every item, as they finish."""
        jobs = max(1, self.options.jobs)
        if jobs == 1:
            for item in items:
                yield fn(item, self._executor())
            return
        with ThreadPoolExecutor(max_workers=jobs) as threads:
            pending: set[Future[R]] = set()
            for item in items:
                pending.add(threads.submit(self._call, fn, item))
                if len(pending) >= 2 * jobs:
                    finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                    yield from (f.result() for f in finished)
            for future in as_completed(pending):
                yield future.result()
