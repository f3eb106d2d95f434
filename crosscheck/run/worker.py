"""Isolation: each engine library runs in its own worker process, so a crash or hang costs one case.

A :class:`WorkerPool` keeps one long-lived worker per engine library, shared by
its variants (engine clients such as a PyBullet connection live there and are
reused across cases).  Each task is sent over a pipe; the parent waits at most
``timeout_s``:

- an answer: the :class:`~crosscheck.run.execute.Outcome` of the case;
- the pipe closes (the worker died: segfault, abort, ``os._exit``): a
  ``crash`` outcome naming the signal or exit code;
- no answer in time: the worker is killed and the outcome is ``timeout``;
- the case blows ``worker_memory_mb`` on its own (it grows the worker by more
  than a fresh worker, its engine loaded, may grow under the limit): the worker
  is killed and the outcome is ``crash`` with the reason "memory limit" (a
  watchdog in the parent reads ``/proc/<pid>/statm`` every :data:`WATCH_S` while
  it waits; an answer that comes sooner costs nothing).

A worker whose resident memory is over the limit after it answered (an engine
leaking case after case) is recycled before the next case; the case during
which a leak piles past the limit is not blamed for it.  Resident memory is
watched rather than capped with ``RLIMIT_AS``/``RLIMIT_DATA``: numpy, OpenBLAS and
the engines reserve far more address space than they touch, so a cap on virtual
memory fails imports and turns an engine's ``std::bad_alloc`` into an abort,
while RSS is what a leak actually costs the machine.  Where ``/proc`` is missing
the limit is not enforced.

A dead or killed worker is replaced on the next task.  The timing phase sends the steps
of its rounds (:class:`~crosscheck.run.execute.Step`) to the engine workers, and the
machine yardstick to a worker of its own on the same CPU.  Workers are started by
the ``forkserver`` method, which is safe with the parent's threads (the
progress bar) and cheap to restart.  Their C-level stdout and stderr go to
/dev/null, so engine banners and warnings never reach the CLI.  (How a worker process
is started, silenced, watched and told dead is :mod:`crosscheck.run.processes`, shared
with the fuzz lanes.)
"""

from __future__ import annotations

import math
import os
import sys
import time
from multiprocessing.connection import Connection
from multiprocessing.process import BaseProcess
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.run.envs import PinnedEnv
from crosscheck.run.execute import (
    Outcome,
    Step,
    Yardstick,
    execute,
    probe_binding,
)
from crosscheck.run.pinned import environment
from crosscheck.run.processes import CONTEXT, SPAWN, Resident, death, quiet_child, start
from crosscheck.run.timing import Timing

# every worker imports these: imported once in the forkserver, no worker start pays for them
CONTEXT.set_forkserver_preload(["crosscheck.run.execute", "crosscheck.run.worker"])

BINDING = "binding"
YARDSTICK = "(yardstick)"
"""The key of the yardstick's own worker among the engines' (no engine has this name)."""
Task = tuple[type[Adapter] | None, AnyCase | Step | Yardstick | str | None, RunOptions, bool,
             frozenset[str]]
"""What a worker is sent: a case to run (whether to time it, the quantities to skip),
``None`` to warm up, :data:`BINDING` to time the cheapest call into the engine, a step of
the timing phase's rounds, or the yardstick (no adapter)."""

STARTUP_TIMEOUT_S = 120.0
"""Time a new worker may take to start and load its engine; not charged to any case."""

WATCH_S = 0.05
"""How often the parent reads a busy worker's resident memory while it waits for an answer."""

RECHECK_S = 0.1
"""Between cases, resident memory is read at most this often (a read costs ~5 us)."""


def _serve(conn: Connection) -> None:
    """Worker main loop: run tasks until the parent closes the pipe.

    Ctrl-C is the parent's to handle: a worker ignores SIGINT, so an
    interrupted run never records a worker's death as an engine crash
    (:func:`~crosscheck.run.processes.quiet_child`).
    """
    quiet_child()
    adapters: dict[type[Adapter], Adapter] = {}
    while True:
        try:
            cls, case, options, timed, skip = conn.recv()
        except (EOFError, OSError):
            return
        if isinstance(case, Yardstick):
            conn.send(case.measure(options))
            continue
        assert cls is not None
        adapter = adapters.setdefault(cls, cls())
        if isinstance(case, Step):
            conn.send(case.take(adapter, options))
        elif case is None:  # warm-up: import the engine and connect, outside any case's time
            adapter.available()
            conn.send(None)
        elif isinstance(case, str):
            conn.send(probe_binding(adapter, options))
        else:
            conn.send(execute(adapter, case, options, timed, skip))


def _serve_pinned(conn: Connection, site_packages: str) -> None:
    """:func:`_serve` in a pinned version's interpreter: a spawned process gets the parent's
    ``sys.path``, so the environment's own packages are put first again, before any task
    (and so any engine) is unpickled."""
    sys.path.insert(0, site_packages)
    _serve(conn)


def memory_limit(what: str, limit_mb: float) -> str:
    """The reason of a ``crash`` for a worker over ``--worker-memory``."""
    return f"memory limit: {what}, past --worker-memory {limit_mb:g} MB"


class _Worker:
    """One worker process and its pipe, its resident memory watched against ``memory_mb``."""

    def __init__(self, memory_mb: float, env: PinnedEnv | None = None) -> None:
        self.memory_mb = memory_mb
        self.conn, child = CONTEXT.Pipe()
        if env is None:
            self.process: BaseProcess = CONTEXT.Process(target=_serve, args=(child,),
                                                        daemon=True)
            start(self.process)
        else:  # the pinned version's own interpreter
            self.process = SPAWN.Process(target=_serve_pinned,
                                         args=(child, str(env.site_packages)), daemon=True)
            start(self.process, str(env.python))
        child.close()
        self.resident = Resident(self.process.pid)
        self.last_mb = 0.0  # at the last check: after the last answer, so as a case begins
        self.checked = -math.inf  # time.monotonic() of that check
        self.warmed: set[type[Adapter]] = set()  # adapters warmed up in this process
        self.fresh_mb = 0.0  # once its engine was loaded

    def over_limit(self, unless_within_s: float = 0.0) -> bool:
        """Whether the worker's resident memory is over its limit (kept as ``last_mb``); not
        read again if it was read less than ``unless_within_s`` ago."""
        now = time.monotonic()
        if now - self.checked >= unless_within_s:
            self.last_mb, self.checked = self.resident.mb(), now
        return self.last_mb > self.memory_mb

    def call(self, task: Task, timeout_s: float) -> Any:
        try:
            self.conn.send(task)
            stopped = self._wait(timeout_s)
            return stopped if stopped is not None else self.conn.recv()
        except (EOFError, OSError, BrokenPipeError):
            self.process.join(timeout=2)
            return Outcome(None, Status.CRASH, death(self.process.exitcode))

    def _wait(self, timeout_s: float) -> Outcome | None:
        """None once an answer is ready; else the worker is killed and the outcome says why:
        no answer within ``timeout_s``, or the case alone grew the worker by more than a fresh
        one may grow (checked every WATCH_S).  A smaller growth past the limit (a leak piling
        up) finishes the case and is recycled after it: RSS stays under twice the limit."""
        deadline = time.monotonic() + timeout_s
        while not self.conn.poll(max(0.0, min(WATCH_S, deadline - time.monotonic()))):
            resident = self.resident.mb()
            if resident - self.last_mb > self.memory_mb - self.fresh_mb:
                self.kill()
                what = (f"this case alone grew the worker from {self.last_mb:.0f} to "
                        f"{resident:.0f} MB (a fresh one holds {self.fresh_mb:.0f} MB)"
                        if self.fresh_mb else
                        f"the worker reached {resident:.0f} MB while loading its engine")
                return Outcome(None, Status.CRASH, memory_limit(what, self.memory_mb))
            if time.monotonic() >= deadline:
                self.kill()
                return Outcome(None, Status.TIMEOUT, f"no answer within {timeout_s:g} s")
        return None

    def alive(self) -> bool:
        return self.process.is_alive()

    def kill(self) -> None:
        if self.process.is_alive():
            self.process.kill()
        self.process.join(timeout=5)
        self.conn.close()
        self.resident.close()

    def close(self) -> None:
        self.conn.close()
        self.process.join(timeout=2)
        if self.process.is_alive():
            self.kill()
        self.resident.close()


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
    """One worker per engine library, shared by its variants (``pybullet`` and
    ``pybullet-default`` run in one process); restarted after a crash or timeout (pinned to
    ``cpu`` if given), recycled between cases when its resident memory passes
    ``options.worker_memory_mb`` (``recycled`` counts those; ``started`` counts every
    worker process started).

    Variants of one engine share its crash modes, so sharing their worker keeps a crash
    or hang to one case x engine variant (the task in flight) while the library is
    imported and the process started once per lane instead of once per variant.  Each
    variant is warmed up in the worker the first time it is used there, outside any
    case's time.
    """

    def __init__(self, options: RunOptions, cpu: int | None = None) -> None:
        self.options = options
        self.cpu = cpu
        self.recycled = 0
        self.started = 0
        self._workers: dict[str, _Worker] = {}

    def _worker(self, adapter: Adapter, options: RunOptions) -> _Worker | Outcome:
        """The engine's live worker, started and the adapter warmed up in it if need be; or
        why it cannot."""
        worker = self._live(adapter.engine, options, environment(adapter))
        if type(adapter) in worker.warmed:
            return worker
        started = worker.call((type(adapter), None, options, False, frozenset()),
                              STARTUP_TIMEOUT_S)
        if started is None and worker.over_limit():  # the engine alone is over the limit
            started = Outcome(None, Status.CRASH, memory_limit(
                f"the worker holds {worker.last_mb:.0f} MB once its engine is loaded",
                worker.memory_mb))
        if started is not None:  # the worker could not even start: that case's outcome
            self._drop(adapter)
            assert isinstance(started, Outcome)
            return started
        worker.fresh_mb = worker.last_mb
        worker.warmed.add(type(adapter))
        return worker

    def _live(self, key: str, options: RunOptions, env: PinnedEnv | None = None) -> _Worker:
        """The live worker under ``key`` (an engine, or :data:`YARDSTICK`), started (in
        ``env``'s interpreter, for a pinned engine version) and pinned to the CPU if need
        be."""
        worker = self._workers.get(key)
        if worker is None or not worker.alive():
            worker = self._workers[key] = _Worker(options.worker_memory_mb, env)
            self.started += 1
            pin(worker.process.pid or 0, self.cpu)
        return worker

    def _drop(self, adapter: Adapter) -> None:
        """Kill the adapter's worker (a fresh one starts on its engine's next task)."""
        self._workers.pop(adapter.engine).kill()

    def yardstick(self, task: Yardstick, options: RunOptions) -> dict[str, Timing] | str:
        """The machine yardstick, measured in a worker of its own on the engine workers' CPU;
        or why not (its worker died or hung)."""
        worker = self._live(YARDSTICK, options)
        answer = worker.call((None, task, options, True, frozenset()), STARTUP_TIMEOUT_S)
        if isinstance(answer, Outcome):
            self._workers.pop(YARDSTICK).kill()
            return answer.reason
        assert isinstance(answer, dict)
        return answer

    def binding(self, adapter: Adapter, options: RunOptions) -> Timing | str:
        """The cost of the cheapest call into the adapter's engine, measured in its worker."""
        worker = self._worker(adapter, options)
        if isinstance(worker, Outcome):
            return worker.reason
        answer = worker.call((type(adapter), BINDING, options, True, frozenset()),
                             options.timeout_s)
        if isinstance(answer, Outcome):  # it hung or died
            self._drop(adapter)
            return answer.reason
        assert isinstance(answer, Timing | str)
        return answer

    def execute(self, adapter: Adapter, case: AnyCase | Step, options: RunOptions,
                timed: bool = False, skip: frozenset[str] = frozenset()) -> Outcome:
        """Run ``case`` on ``adapter`` (without the quantities in ``skip``), or a step of the
        timing phase's rounds, in the adapter's worker, within the time limit."""
        worker = self._worker(adapter, options)
        if isinstance(worker, Outcome):
            return worker
        outcome = worker.call((type(adapter), case, options, timed, skip), options.timeout_s)
        assert isinstance(outcome, Outcome)
        if outcome.status in (Status.CRASH, Status.TIMEOUT):
            self._drop(adapter)
        elif worker.over_limit(RECHECK_S):  # it answered, but leaked past the limit: recycle
            self._drop(adapter)
            self.recycled += 1
        return outcome

    def close(self, at_once: bool = False) -> None:
        """Stop every worker (``at_once``: kill it, without letting it tidy up)."""
        for worker in self._workers.values():
            if at_once:
                worker.kill()
            else:
                worker.close()
        self._workers.clear()


def fresh_worker(adapter: Adapter, case: AnyCase, options: RunOptions, timed: bool = False,
                 skip: frozenset[str] = frozenset()) -> Outcome:
    """An :class:`~crosscheck.run.execute.Executor` that runs every call in a worker process
    started for it alone (its engine loaded and warmed up, nothing else asked there), then
    stopped: the repeat check's second asking (:mod:`crosscheck.run.repeat`)."""
    pool = WorkerPool(options)
    try:
        return pool.execute(adapter, case, options, timed, skip)
    finally:
        pool.close(at_once=True)  # it will answer nothing else: its exit would only cost time
