"""What every worker process of the harness shares, in one place: a run's engine workers
(:mod:`crosscheck.run.worker`) and a fuzz campaign's lanes
(:mod:`crosscheck.studies.fuzz.lanes`).

- :data:`CONTEXT`: the ``forkserver`` start method (safe with the parent's threads, the
  progress bar; cheap to restart after a crash);
- :func:`start`: start a process without telling it the parent's ``__main__``;
- :func:`quiet_child`: a worker's first act: Ctrl-C is the parent's to handle, and the C-level
  stdout and stderr go to /dev/null, so engine banners never reach the CLI;
- :func:`death`: the reason of a ``crash`` for a process that died, in words;
- :class:`Resident` and :func:`resident_mb`: resident memory read from ``/proc/<pid>/statm``.

>>> death(-9), death(3), death(None)
('worker killed by SIGKILL', 'worker exited with code 3', 'worker died')
"""

from __future__ import annotations

import contextlib
import math
import multiprocessing as mp
import multiprocessing.spawn as mp_spawn
import os
import signal
import sys
import threading
import types
from collections.abc import Iterable, Iterator
from multiprocessing.process import BaseProcess

CONTEXT = mp.get_context("forkserver")
"""The start method of every worker process of the harness's own interpreter."""

SPAWN = mp.get_context("spawn")
"""The start method of a worker in another interpreter (a pinned engine version's
environment, :mod:`crosscheck.run.envs`): a fresh ``python`` of that environment."""
_START_LOCK = threading.Lock()

PAGE_MB = os.sysconf("SC_PAGE_SIZE") / 2**20 if hasattr(os, "sysconf") else 4 / 1024
"""The size of a memory page in MB (``statm`` counts pages)."""


@contextlib.contextmanager
def without_main() -> Iterator[None]:
    """Start a worker (or any process) without telling it the parent's main module.

    A new process normally re-imports ``__main__`` (for the CLI: the whole CLI,
    pandas included, ~0.4 s per worker start or restart after a crash).  A
    worker needs only its target, importable by name, so it is started while
    ``__main__`` is a bare module.
    """
    saved = sys.modules["__main__"]
    sys.modules["__main__"] = types.ModuleType("__main__")
    try:
        yield
    finally:
        sys.modules["__main__"] = saved


def start(process: BaseProcess, executable: str | None = None) -> None:
    """Start ``process`` without the parent's ``__main__``, one start at a time (lanes of
    threads may start workers at once); a :data:`SPAWN` process with ``executable`` as its
    interpreter if given (multiprocessing keeps that setting globally: it is set for this
    start only, under the lock)."""
    with _START_LOCK, without_main():
        if executable is None:
            process.start()
            return
        saved = mp_spawn.get_executable()
        mp_spawn.set_executable(executable)
        try:
            process.start()
        finally:
            mp_spawn.set_executable(saved)


def quiet_child() -> None:
    """In a new worker: ignore SIGINT (an interrupted run never records a worker's death as an
    engine crash: the parent stops its workers) and send fds 1 and 2 to /dev/null."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    devnull = os.open(os.devnull, os.O_WRONLY)
    for fd in (1, 2):
        os.dup2(devnull, fd)
    os.close(devnull)


def death(code: int | None) -> str:
    """Why a worker is gone, from its exit code (negative: the signal that killed it)."""
    if code is None:
        return "worker died"
    if code < 0:
        try:
            return f"worker killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"worker killed by signal {-code}"
    return f"worker exited with code {code}"


class Resident:
    """The resident memory of one process, read cheaply again and again (``statm`` is opened
    once; a read costs ~5 us).  0 where ``/proc`` cannot tell."""

    def __init__(self, pid: int | None) -> None:
        self._statm: int | None = None
        with contextlib.suppress(OSError):
            self._statm = os.open(f"/proc/{pid}/statm", os.O_RDONLY)

    def mb(self) -> float:
        """The process's resident memory now, in MB (0 where it cannot be read)."""
        if self._statm is None:
            return 0.0
        try:
            return int(os.pread(self._statm, 128, 0).split()[1]) * PAGE_MB
        except (OSError, IndexError, ValueError):
            return 0.0

    def close(self) -> None:
        """Stop watching (closes ``statm``)."""
        if self._statm is not None:
            os.close(self._statm)
        self._statm = None


def resident_mb(pids: Iterable[int]) -> float:
    """The resident memory of these processes together, in MB (NaN where /proc is not
    readable)."""
    total = 0.0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/statm", encoding="ascii") as handle:
                total += int(handle.read().split()[1]) * PAGE_MB
        except (OSError, ValueError, IndexError):
            return math.nan
    return total
