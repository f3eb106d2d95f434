"""One engine worker process: its main loop, and the parent's handle on it.

The worker (:func:`serve`) answers tasks in the order they were sent, one answer per task;
the parent's :class:`WorkerProcess` sends a task, and either waits for its answer
(:meth:`WorkerProcess.call`, the warm-up, the binding probe, the yardstick) or keeps a few
tasks in flight at once and takes their answers as they come (the pool's batches,
:meth:`crosscheck.run.worker.WorkerPool.many`): a worker that is sent its next case before it
has finished the current one never waits for the parent between cases.

How long a worker may take, how much memory it may hold, and how its death is named are
watched here (:meth:`WorkerProcess.watch`); what to do about it is the pool's.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Iterable
from multiprocessing.connection import Connection
from multiprocessing.process import BaseProcess
from multiprocessing.reduction import ForkingPickler
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.run.envs import PinnedEnv
from crosscheck.run.execute import Judged, Outcome, Step, Yardstick, execute, probe_binding
from crosscheck.run.processes import CONTEXT, SPAWN, Resident, death, quiet_child, start
from crosscheck.run.scoring import answer_judged

PRELOAD = ("crosscheck.run.execute", "crosscheck.run.worker_process")
"""Every worker imports these: imported once in the forkserver, no worker start pays for them
(the scoring with them: a worker scores the verdict pass's cases, :class:`Judged`)."""
CONTEXT.set_forkserver_preload(list(PRELOAD))


def preload(adapters: Iterable[Adapter]) -> None:
    """Import the modules of these adapters (those whose ``light_import`` says their import
    loads no engine) in the forkserver too, beside :data:`PRELOAD`: each worker then starts
    with numpy, pydantic and the adapter code imported (tens of milliseconds per start).
    Effective until the forkserver starts, with a run's first worker."""
    modules = sorted({type(a).__module__ for a in adapters if a.light_import})
    CONTEXT.set_forkserver_preload([*PRELOAD, *modules])

BINDING = "binding"
Task = tuple[type[Adapter] | None, AnyCase | Judged | Step | Yardstick | str | None, RunOptions,
             bool, frozenset[str]]
"""What a worker is sent: a case to run (whether to time it, the quantities to skip) or
to run and score (:class:`~crosscheck.run.execute.Judged`),
``None`` to warm up, :data:`BINDING` to time the cheapest call into the engine, a step of
the timing phase's rounds, or the yardstick (no adapter)."""

WATCH_S = 0.05
"""How often the parent reads a busy worker's resident memory while it waits for an answer."""


def serve(conn: Connection) -> None:
    """Worker main loop: run tasks until the parent closes the pipe, answering each in turn.

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
        elif isinstance(case, Judged):
            conn.send(answer_judged(adapter, case, options, timed, skip))
        elif case is None:  # warm-up: import the engine and connect, outside any case's time
            adapter.available()
            conn.send(None)
        elif isinstance(case, str):
            conn.send(probe_binding(adapter, options))
        else:
            conn.send(execute(adapter, case, options, timed, skip))


def _serve_pinned(conn: Connection, site_packages: str) -> None:
    """:func:`serve` in a pinned version's interpreter: a spawned process gets the parent's
    ``sys.path``, so the environment's own packages are put first again, before any task
    (and so any engine) is unpickled."""
    sys.path.insert(0, site_packages)
    serve(conn)


def memory_limit(what: str, limit_mb: float) -> str:
    """The reason of a ``crash`` for a worker over ``--worker-memory``."""
    return f"memory limit: {what}, past --worker-memory {limit_mb:g} MB"


def payload(task: Task) -> bytes:
    """``task`` pickled as the pipe carries it (what :meth:`Connection.send` would write)."""
    return bytes(ForkingPickler.dumps(task))


class WorkerProcess:
    """One worker process and its pipe, its resident memory watched against ``memory_mb``."""

    def __init__(self, memory_mb: float, env: PinnedEnv | None = None) -> None:
        self.memory_mb = memory_mb
        self.conn, child = CONTEXT.Pipe()
        if env is None:
            self.process: BaseProcess = CONTEXT.Process(target=serve, args=(child,),
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
        """Send ``task`` and wait for its answer; an :class:`Outcome` of ``crash`` or
        ``timeout`` (the worker killed) if there is none."""
        if not self.send(payload(task)):
            return self.died()
        deadline = time.monotonic() + timeout_s
        while not self.conn.poll(max(0.0, min(WATCH_S, deadline - time.monotonic()))):
            stopped = self.watch(deadline, timeout_s)
            if stopped is not None:
                return stopped
        return self.answer()

    def send(self, data: bytes) -> bool:
        """Write one pickled task to the worker; False if it is gone."""
        try:
            self.conn.send_bytes(data)
        except (EOFError, OSError):
            return False
        return True

    def answer(self) -> Any:
        """The next answer (it is ready), or the ``crash`` outcome of a worker that died."""
        try:
            return self.conn.recv()
        except (EOFError, OSError):
            return self.died()

    def died(self) -> Outcome:
        """The ``crash`` outcome of the task in flight when the worker's pipe closed."""
        self.process.join(timeout=2)
        return Outcome(None, Status.CRASH, death(self.process.exitcode))

    def watch(self, deadline: float, timeout_s: float) -> Outcome | None:
        """While a task is in flight and unanswered: None if it may go on; else the worker
        is killed and the outcome says why: no answer by ``deadline`` (``timeout_s`` after
        it began), or the task alone grew the worker by more than a fresh one may grow.
        A smaller growth past the limit (a leak piling up) finishes the task and is
        recycled after it by the pool: RSS stays under twice the limit."""
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
