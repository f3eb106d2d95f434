"""The instruction timer (``crosscheck run --timer instructions``): counted cost, not seconds.

After the wall-clock timing phase, the same sample (:func:`cost_sample`) is counted
under Valgrind's callgrind: one counting worker per engine library
(:mod:`crosscheck.run.cost_worker`, started once, so Valgrind's and the engine's
start-up are paid once), pair after pair.  Per pair it counts a loop of
:data:`CALLS` queries after :data:`WARMUPS` uncounted ones, and the same loop around
an empty call, and appends the raw counts to ``counts.jsonl``
(:mod:`crosscheck.results.counts`): instructions per query, and of those the ones
inside the engine's shared objects (its own work).

Counts do not depend on the machine's load or clock, so the engine libraries are
counted side by side, up to one worker per core.  A counting worker that dies or
does not answer within :data:`SLOWDOWN` times the case's time limit costs one pair
(counted as failed, with its reason in run.json) and is started again for the next.
Without Valgrind (or without the client-request hooks) nothing is counted and
run.json says why.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from multiprocessing import Pipe
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.core.contract import Adapter
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.results.counts import CountRecord
from crosscheck.results.run import Run
from crosscheck.results.store import ResultsStore
from crosscheck.run import callgrind
from crosscheck.run.execute import case_options
from crosscheck.run.pinned import environment
from crosscheck.run.timing_phase import timing_sample

CALLS = 10
"""Counted queries per pair (a count is exact: more calls only average one-off costs)."""
WARMUPS = 3
"""Uncounted queries first: Python 3.11 specialises a function's bytecode on its first
calls, and engines fill caches; the counted loop then repeats one steady path."""
SCENE_LIMIT_S = 0.02
"""Scenes whose one run in the verdict pass took longer are not counted (callgrind runs
code about 50 times slower than the processor: a budget, as in the wall-clock phase)."""
SLOWDOWN = 100.0
"""A pair may take this many times its case's time limit under callgrind."""
STARTUP_S = 600.0
"""Time a counting worker may take to start Valgrind and load its engine."""
ENV = {"PYTHONHASHSEED": "0", "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
"""Set in every counting worker: a fixed string hash (dict and set layouts, so the same
instructions run after run) and one thread per numeric library."""

Tick = Callable[[int], None]
Pair = tuple[AnyCase, Adapter]


def method() -> str:
    """The instruction timer in words, for run.json and the report."""
    return (f"instructions counted under Valgrind's callgrind, one worker per engine library: "
            f"per pair, {WARMUPS} uncounted queries, then a loop of {CALLS} counted ones, net "
            f"of the same loop around an empty call, on the thread that runs the queries; "
            f"scenes of at most {SCENE_LIMIT_S:g} s per run counted once; the engine's own "
            "work is what ran inside calls into its shared objects")


def cost_sample(cases: Sequence[AnyCase], engines: Sequence[Adapter], frame: pd.DataFrame,
                options: RunOptions) -> list[Pair]:
    """The wall-clock phase's sample, without scenes slower than :data:`SCENE_LIMIT_S`."""
    quick: set[tuple[str, str]] = set()
    if not frame.empty:
        scenes = frame[(frame["kind"] == "sphere_scene") & (frame["query_s"] <= SCENE_LIMIT_S)]
        quick = set(zip(scenes["case_id"].astype(str), scenes["engine"].astype(str),
                        strict=True))
    return [(case, adapter) for case, adapter in timing_sample(cases, engines, frame, options)
            if not isinstance(case, SceneCase) or (case.id, adapter.name) in quick]


class CountingWorker:
    """One engine library's process under callgrind, and the pipe to it."""

    def __init__(self, executable: str = sys.executable) -> None:
        self.out = Path(tempfile.mkdtemp(prefix="crosscheck-callgrind-"))
        mine, theirs = Pipe()
        self.conn: Connection = mine
        fd = theirs.fileno()
        python = [executable, "-m", "crosscheck.run.cost_worker", str(fd)]
        self.process = subprocess.Popen(
            callgrind.command(python, self.out), pass_fds=(fd,), env=os.environ | ENV,
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        theirs.close()

    def ask(self, task: tuple[Any, ...], timeout_s: float) -> tuple[Any, ...] | str | None:
        """The worker's reply to ``task``, or the reason there is none (a ``str``: it died or
        did not answer in time, and is then stopped)."""
        try:
            self.conn.send(task)
            if self.conn.poll(timeout_s):
                reply: tuple[Any, ...] | None = self.conn.recv()
                return reply
            self.kill()
            return f"no answer within {timeout_s:g} s under callgrind (worker stopped)"
        except (EOFError, OSError, BrokenPipeError):
            code = self.process.wait()
            return f"the counting worker died (exit code {code})"

    def dump(self, pid: int, number: int, objects: Sequence[str]) -> callgrind.Counts:
        """The counts of one of the worker's dumps, on the querying thread (the dump's files
        are removed once read)."""
        try:
            return callgrind.read_dump(callgrind.dump_path(self.out, pid, number), objects)
        finally:  # this dump's files, and those of the dump before it (thrown away)
            for path in [*callgrind.dump_files(self.out, pid, number - 1),
                         *callgrind.dump_files(self.out, pid, number)]:
                path.unlink(missing_ok=True)

    def alive(self) -> bool:
        return self.process.poll() is None

    def kill(self) -> None:
        if self.alive():
            self.process.kill()
        self.process.wait()

    def close(self) -> None:
        """Close the pipe (the worker then exits), wait for it, remove its files."""
        self.conn.close()
        try:
            self.process.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.kill()
        shutil.rmtree(self.out, ignore_errors=True)


class LibraryCounter:
    """Counts one engine library's pairs, one after another, in its own counting worker."""

    def __init__(self, store: ResultsStore, options: RunOptions, lock: threading.Lock,
                 tick: Tick | None, stopping: threading.Event) -> None:
        self.store, self.options, self.lock, self.tick = store, options, lock, tick
        self.stopping = stopping
        self.failed: dict[str, str] = {}
        self.worker: CountingWorker | None = None

    def _ready(self, adapter: Adapter) -> CountingWorker | str:
        if self.worker is not None and self.worker.alive():
            return self.worker
        if self.worker is not None:
            self.worker.close()
        env = environment(adapter)  # a pinned version counts in its environment's interpreter
        self.worker = CountingWorker(sys.executable if env is None else str(env.python))
        started = self.worker.ask((type(adapter), None, 0, 0), STARTUP_S)
        return self.worker if started is None else str(started)

    def count(self, pairs: Sequence[Pair]) -> None:
        try:
            for case, adapter in pairs:
                if self.stopping.is_set():
                    return
                reason = self._one(case, adapter)
                if reason:
                    self.failed[f"{case.id} x {adapter.name}"] = reason
                if self.tick:
                    self.tick(1)
        finally:
            if self.worker is not None:
                self.worker.close()

    def _one(self, case: AnyCase, adapter: Adapter) -> str:
        worker = self._ready(adapter)
        if isinstance(worker, str):
            return worker
        limit = case_options(case, self.options).timeout_s * SLOWDOWN
        reply = worker.ask((type(adapter), case, CALLS, WARMUPS), limit)
        if not isinstance(reply, tuple):
            return str(reply)
        if reply[0] != "ok":
            return str(reply[1])
        _, pid, query_dump, empty_dump = reply
        found = worker.dump(pid, query_dump, adapter.binding_objects)
        empty = worker.dump(pid, empty_dump, ())
        calls = 1 if isinstance(case, SceneCase) else CALLS
        record = CountRecord(case.id, adapter.name, case.kind,
                             "scene" if isinstance(case, SceneCase) else "call", calls,
                             found.total, empty.total, found.engine)
        with self.lock:
            self.store.append_count(record)
        return ""


def by_library(pairs: Sequence[Pair]) -> list[list[Pair]]:
    """The pairs grouped by engine library (the variants of one engine share a worker), in
    the order the libraries first appear."""
    groups: dict[str, list[Pair]] = {}
    for case, adapter in pairs:
        groups.setdefault(adapter.engine, []).append((case, adapter))
    return list(groups.values())


def cost_phase(store: ResultsStore, run: Run, engines: Sequence[Adapter], options: RunOptions,
               start: Callable[[int], Tick] | None = None) -> dict[str, Any]:
    """Count the sample of ``run``'s rows into ``store`` (skipping pairs already counted);
    the ``cost`` part of run.json's timing section.  ``start(total)`` returns the function to
    call as each pair finishes (a progress bar)."""
    began = time.monotonic()
    why = callgrind.missing()
    if why:
        return {"timer": "instructions", "none": why}
    sample = cost_sample(list(run.cases.values()), engines, run.results, options)
    todo = [(c, a) for c, a in sample if (c.id, a.name) not in store.counted]
    tick = start(len(todo)) if start else None
    lock, stopping = threading.Lock(), threading.Event()
    groups = by_library(todo)
    libraries = [LibraryCounter(store, options, lock, tick, stopping) for _ in groups]
    workers = max(1, min(len(groups), len(os.sched_getaffinity(0))
                         if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1))
    with ThreadPoolExecutor(max_workers=workers) as pool:
        futures = [pool.submit(lib.count, group) for lib, group in zip(libraries, groups,
                                                                       strict=True)]
        try:
            for future in futures:
                future.result()
        except BaseException:
            stopping.set()
            for lib in libraries:
                if lib.worker is not None:
                    lib.worker.kill()
            raise
    failed = {k: v for lib in libraries for k, v in lib.failed.items()}
    return {"timer": "instructions", "method": method(), "valgrind": callgrind.version(),
            "calls": CALLS, "warmups": WARMUPS, "sampled": len(sample),
            "counted": sum((c.id, a.name) in store.counted for c, a in sample),
            "failed": len(failed),
            "failures": dict(list(failed.items())[:20]), "parallel": workers,
            "wall_s": round(time.monotonic() - began, 3)}
