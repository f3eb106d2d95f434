"""Isolation: each engine library runs in its own worker process, so a crash or hang costs one case.

A :class:`WorkerPool` keeps one long-lived worker per engine library, shared by
its variants (engine clients such as a PyBullet connection live there and are
reused across cases).  Each task is sent over a pipe (the process itself, and how a
silent or greedy one is caught, is :mod:`crosscheck.run.worker_process`); the parent
waits at most ``timeout_s`` for each answer:

- an answer: the :class:`~crosscheck.run.execute.Outcome` of the case;
- the pipe closes (the worker died: segfault, abort, ``os._exit``): a
  ``crash`` outcome naming the signal or exit code;
- no answer in time: the worker is killed and the outcome is ``timeout``;
- the case blows ``worker_memory_mb`` on its own (it grows the worker by more
  than a fresh worker, its engine loaded, may grow under the limit): the worker
  is killed and the outcome is ``crash`` with the reason "memory limit" (a
  watchdog in the parent reads ``/proc/<pid>/statm`` every
  :data:`~crosscheck.run.worker_process.WATCH_S` while it waits; an answer that comes
  sooner costs nothing).

A batch of calls (:meth:`WorkerPool.many`: the cases of a lane's item on every engine)
runs on all its engines' workers at once, and each worker holds up to :data:`WINDOW`
tasks: the one it runs and the next, so that it starts the next case as soon as it has
answered, instead of waiting a round trip (and the parent's threads) for it.  A task's
time limit counts from when its worker could begin it (the previous answer, or the send
to an idle worker).  When a worker dies or is killed, the task it was running gets the
outcome and the tasks queued behind it go to a fresh worker.

A worker whose resident memory is over the limit after it answered (an engine
leaking case after case) is sent nothing more and recycled once it has answered the
task already queued; the case during which a leak piles past the limit is not blamed
for it.  Resident memory is watched rather than capped with ``RLIMIT_AS``/``RLIMIT_DATA``:
numpy, OpenBLAS and the engines reserve far more address space than they touch, so a cap
on virtual memory fails imports and turns an engine's ``std::bad_alloc`` into an abort,
while RSS is what a leak actually costs the machine.  Where ``/proc`` is missing the
limit is not enforced.

A dead or killed worker is replaced on the next task.  The timing phase sends the steps
of its rounds (:class:`~crosscheck.run.execute.Step`) to the engine workers, one at a
time, and the machine yardstick to a worker of its own on the same CPU.  Workers are
started by the ``forkserver`` method, which is safe with the parent's threads (the
progress bar) and cheap to restart.  Their C-level stdout and stderr go to
/dev/null, so engine banners and warnings never reach the CLI.  (How a worker process
is started, silenced, watched and told dead is :mod:`crosscheck.run.processes`, shared
with the fuzz lanes.)
"""

from __future__ import annotations

import os
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.run.envs import PinnedEnv
from crosscheck.run.execute import Call, Outcome, Step, Yardstick
from crosscheck.run.pinned import environment
from crosscheck.run.timing import Timing
from crosscheck.run.worker_process import (
    BINDING,
    WATCH_S,
    WorkerProcess,
    memory_limit,
    payload,
)

YARDSTICK = "(yardstick)"
"""The key of the yardstick's own worker among the engines' (no engine has this name)."""

STARTUP_TIMEOUT_S = 120.0
"""Time a new worker may take to start and load its engine; not charged to any case."""

RECHECK_S = 0.1
"""Between cases, resident memory is read at most this often (a read costs ~5 us)."""

WINDOW = 2
"""Tasks of a batch a worker holds at once: the one it runs and the next."""

PIPELINE_BYTES = 32_768
"""A task pickled larger than this is sent only to an idle worker.  Sent behind a running
one it could fill the pipe while that one's answer fills the other way, and both sides
would wait for each other; a pipe holds 64 KiB on Linux."""


def pin(pid: int, cpu: int | None) -> bool:
    """Pin process ``pid`` (0: this one) to ``cpu`` where the OS allows it; whether it did."""
    if cpu is None or not hasattr(os, "sched_setaffinity"):
        return False
    try:
        os.sched_setaffinity(pid, {cpu})
    except OSError:
        return False
    return True


@dataclass
class _Flight:
    """One engine's share of a batch: calls not sent yet, and those its worker holds."""

    queue: deque[int] = field(default_factory=deque)
    flying: deque[int] = field(default_factory=deque)
    since: float = 0.0
    """When the worker could begin the first task it holds (the time limit counts from it)."""
    watched: float = 0.0
    recycle: bool = False
    """Over its memory limit after an answer: sent nothing more, recycled once idle."""


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
        self._workers: dict[str, WorkerProcess] = {}

    def _worker(self, adapter: Adapter, options: RunOptions) -> WorkerProcess | Outcome:
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

    def _live(self, key: str, options: RunOptions,
              env: PinnedEnv | None = None) -> WorkerProcess:
        """The live worker under ``key`` (an engine, or :data:`YARDSTICK`), started (in
        ``env``'s interpreter, for a pinned engine version) and pinned to the CPU if need
        be."""
        worker = self._workers.get(key)
        if worker is None or not worker.alive():
            worker = self._workers[key] = WorkerProcess(options.worker_memory_mb, env)
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
        return self.many([(adapter, case, options, timed, skip)])[0]

    __call__ = execute

    def many(self, calls: Sequence[Call]) -> list[Outcome]:
        """The outcome of every call, in order: each engine's calls run in turn in its
        worker, the engines' workers at once, each worker holding up to :data:`WINDOW`."""
        outcomes: list[Outcome | None] = [None] * len(calls)
        flights: dict[str, _Flight] = {}
        for k, call in enumerate(calls):
            flights.setdefault(call[0].engine, _Flight()).queue.append(k)
        while True:
            for key, flight in flights.items():
                self._feed(key, flight, calls, outcomes)
            busy = {self._workers[key].conn: key for key, f in flights.items() if f.flying}
            if not busy:
                break
            ready = set(wait(list(busy), timeout=self._patience(busy, flights, calls)))
            now = time.monotonic()
            for conn, key in busy.items():
                if conn in ready:
                    self._take(key, flights[key], outcomes)
                elif now - flights[key].watched >= WATCH_S:
                    self._watch(key, flights[key], calls, outcomes)
        assert all(outcome is not None for outcome in outcomes)
        return outcomes  # type: ignore[return-value]

    def _patience(self, busy: dict[Connection, str], flights: dict[str, _Flight],
                  calls: Sequence[Call]) -> float:
        """How long to wait for an answer before watching the busy workers again."""
        now = time.monotonic()
        due = min(flights[key].since + calls[flights[key].flying[0]][2].timeout_s
                  for key in busy.values())
        return max(0.0, min(WATCH_S, due - now))

    def _feed(self, key: str, flight: _Flight, calls: Sequence[Call],
              outcomes: list[Outcome | None]) -> None:
        """Send the engine's next calls until its worker holds :data:`WINDOW` of them."""
        while flight.queue and len(flight.flying) < WINDOW and not flight.recycle:
            k = flight.queue[0]
            adapter, case, options, timed, skip = calls[k]
            if flight.flying:
                worker = self._workers[key]
                if type(adapter) not in worker.warmed:
                    return  # warmed up once the worker is idle (its answers come in order)
            else:
                started = self._worker(adapter, options)
                if isinstance(started, Outcome):
                    outcomes[flight.queue.popleft()] = started
                    continue
                worker = started
            data = payload((type(adapter), case, options, timed, skip))
            if flight.flying and len(data) > PIPELINE_BYTES:
                return
            if not worker.send(data):
                if flight.flying:
                    return  # dead: the answer of the task it held says how
                outcomes[flight.queue.popleft()] = worker.died()
                self._drop(adapter)
                continue
            if not flight.flying:
                flight.since = flight.watched = time.monotonic()
            flight.flying.append(flight.queue.popleft())

    def _take(self, key: str, flight: _Flight, outcomes: list[Outcome | None]) -> None:
        """The answer of the engine's oldest task in flight (it is ready)."""
        worker = self._workers[key]
        answer = worker.answer()
        assert isinstance(answer, Outcome)
        outcomes[flight.flying.popleft()] = answer
        flight.since = flight.watched = time.monotonic()
        if answer.status in (Status.CRASH, Status.TIMEOUT):
            self._requeue(key, flight)
        elif not flight.recycle and worker.over_limit(RECHECK_S):
            flight.recycle = True  # it answered, but leaked past the limit
        if flight.recycle and not flight.flying:
            self._workers.pop(key).kill()
            self.recycled += 1
            flight.recycle = False

    def _watch(self, key: str, flight: _Flight, calls: Sequence[Call],
               outcomes: list[Outcome | None]) -> None:
        """Kill the engine's worker if its task in flight is over time or memory."""
        flight.watched = time.monotonic()
        timeout_s = calls[flight.flying[0]][2].timeout_s
        stopped = self._workers[key].watch(flight.since + timeout_s, timeout_s)
        if stopped is not None:
            outcomes[flight.flying.popleft()] = stopped
            self._requeue(key, flight)

    def _requeue(self, key: str, flight: _Flight) -> None:
        """The worker is dead or done for: kill it, and send what it held to a fresh one."""
        self._workers.pop(key).kill()
        flight.queue.extendleft(reversed(flight.flying))
        flight.flying.clear()
        flight.recycle = False

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
