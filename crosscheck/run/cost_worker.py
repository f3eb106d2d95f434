"""The counting worker: one engine library's process under callgrind, counting pair after pair.

Started by :mod:`crosscheck.run.cost` as ``valgrind --tool=callgrind ... python -m
crosscheck.run.cost_worker FD``, it reads tasks from the pipe on file descriptor
``FD`` (a :class:`multiprocessing.connection.Connection`) until the parent closes it:

- ``(adapter class, None, 0, 0)``: import the engine and load it (outside any pair);
  answers ``None``;
- ``(adapter class, case, calls, warmups)``: prepare the case (not counted), run the
  query ``warmups`` times (not counted: Python specialises its bytecode on the first
  calls, an engine fills its caches), then count a loop of ``calls`` queries and the
  same loop around an empty call; answers ``("ok", pid, query dump, empty dump)``
  with the numbers of the two dumps, or ``("error", reason)``.

A scene is one whole stepped run: it is warmed up by one run of its own, then
prepared afresh and counted once (``calls`` is 1).  The garbage collector is off while
counting, as in the wall-clock timer.  Ctrl-C is the parent's to handle.
"""

from __future__ import annotations

import gc
import os
import signal
import sys
import time
import traceback
from multiprocessing.connection import Connection
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.run.callgrind import Counter

Reply = tuple[Any, ...]

SETTLE_S = 0.02
"""A pause before each count, so that an engine's worker threads (rapier's rayon pool)
have stopped searching for work and gone to sleep: how the querying thread hands them
a job depends on whether they are awake."""


def _nothing() -> None:
    return None


def _scene_warmup(adapter: Adapter, case: AnyCase) -> None:
    prepared = adapter.prepare(case)
    try:
        adapter.query(prepared)
    finally:
        adapter.release(prepared)


def count_pair(counter: Counter, adapter: Adapter, case: AnyCase, calls: int,
               warmups: int) -> Reply:
    """Prepare, warm up and count ``case`` on ``adapter``; the reply to the parent."""
    unable = adapter.available() or adapter.unsupported(case)
    if unable:
        return ("error", unable)
    if isinstance(case, SceneCase):
        _scene_warmup(adapter, case)
        calls, warmups = 1, 0
    prepared = adapter.prepare(case)
    try:
        def query() -> object:
            return adapter.query(prepared)

        for _ in range(warmups):
            query()
        gc.collect()
        time.sleep(SETTLE_S)
        gc.disable()
        try:
            label = f"{case.id} {adapter.name}"
            return ("ok", os.getpid(), counter.count(query, calls, label),
                    counter.count(_nothing, calls, "empty loop"))
        finally:
            gc.enable()
    finally:
        adapter.release(prepared)


def serve(conn: Connection) -> None:
    """Answer tasks until the parent closes the pipe."""
    counter = Counter()
    adapters: dict[type[Adapter], Adapter] = {}
    while True:
        try:
            task = conn.recv()
        except (EOFError, OSError):
            return
        cls, case, calls, warmups = task
        adapter = adapters.setdefault(cls, cls())
        if case is None:
            adapter.available()
            conn.send(None)
            continue
        try:
            reply = count_pair(counter, adapter, case, calls, warmups)
        except Exception as exc:  # an engine fault is data: one pair, not the worker
            where = traceback.extract_tb(exc.__traceback__)[-1]
            reply = ("error", f"{type(exc).__name__}: {exc} (at {where.name}:{where.lineno})")
        conn.send(reply)


def main(argv: list[str]) -> int:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    serve(Connection(int(argv[1])))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
