"""The conformance kit in a process of its own, for the plugin's conformance items.

The kit asks the engine in the process that runs it (:mod:`crosscheck.testing.conformance`):
an engine that crashes, or a query that hangs, would take the pytest session with it.  The
plugin runs it in a worker process instead (started as the run's workers are,
:mod:`crosscheck.run.processes`), so that a crash or a hang costs the conformance items,
never the session: :func:`run_kit` gives the failures, the check the kit stopped at, and
why the kit did not finish ('' if it did).  A class that cannot be sent to another process
(it does not pickle by reference) is checked in this process, and the kit's ``worker``
check says why it must.
"""

from __future__ import annotations

import pickle
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import Any

from crosscheck.run import processes
from crosscheck.testing.conformance import Checker, Failure

KIT_TIMEOUT_S = 300.0
"""How long the kit may take in its process before it is killed (it starts a worker of its
own for the ``worker`` check, and asks a few samples per capability)."""


@dataclass(frozen=True)
class KitOutcome:
    """What the kit found: its failures, the check it stopped at ('' if none), and why it
    did not finish ('' if it did: its process died, it hung or raised)."""

    failures: tuple[Failure, ...]
    stopped: str = ""
    broken: str = ""


def in_this_process(cls: Any, name: str, public_sources: bool) -> KitOutcome:
    """The kit run here."""
    checker = Checker(cls, name, public_sources=public_sources)
    return KitOutcome(tuple(checker.run()), checker.stopped)


def _child(cls: Any, name: str, public_sources: bool, conn: Connection) -> None:
    processes.quiet_child()
    try:
        outcome = in_this_process(cls, name, public_sources)
    except BaseException as exc:  # a fault of the kit itself, said in words
        outcome = KitOutcome((), "", f"the kit raised {type(exc).__name__}: {exc}")
    conn.send(outcome)
    conn.close()


def _sendable(cls: Any) -> bool:
    try:
        return pickle.loads(pickle.dumps(cls)) is cls and cls.__module__ != "__main__"
    except Exception:
        return False


def run_kit(cls: Any, name: str, public_sources: bool,
            timeout_s: float = KIT_TIMEOUT_S) -> KitOutcome:
    """The kit run on ``cls`` in a worker process (here, if ``cls`` cannot be sent to one)."""
    if not _sendable(cls):
        return in_this_process(cls, name, public_sources)
    receive, send = processes.CONTEXT.Pipe(duplex=False)
    process = processes.CONTEXT.Process(target=_child, args=(cls, name, public_sources, send))
    processes.start(process)  # not a daemon: the kit's worker check starts a process of its own
    send.close()
    try:
        if not receive.poll(timeout_s):
            return KitOutcome((), "", f"the kit did not finish within {timeout_s:g} s (a query "
                                      f"that hangs?): its process was killed")
        try:
            outcome: KitOutcome = receive.recv()
        except EOFError:
            process.join()
            return KitOutcome((), "", f"the kit's process died: "
                                      f"{processes.death(process.exitcode)}")
        return outcome
    finally:
        if process.is_alive():
            process.kill()
        process.join()
        receive.close()
