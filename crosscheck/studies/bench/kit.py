"""What every bench figure shares: the :class:`Figure` value, the project root, memory probes,
and a subprocess timer that follows a command's whole session.

>>> Figure("x", 2.0, "x", ">= 1", True).ok
True
>>> Figure("wall", 300.0, "%", RECORDED, True, gating=False).gating
False
"""

from __future__ import annotations

import gc
import os
import subprocess
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from crosscheck.run.processes import resident_mb

ROOT = Path(__file__).resolve().parents[3]
"""The project folder (case files, reports)."""


RECORDED = "recorded, never gating"
"""The target of a figure kept for the record only (``gating`` False): a wall-clock figure
whose target a counted figure judges instead, since the wall clock of a shared machine
drifts too much within a run to judge it."""


@dataclass(frozen=True)
class Figure:
    """One measured figure: its value, the target, whether it meets it, and details.

    ``gating`` False: the figure is recorded, never judged (its ``ok`` is True and its
    target :data:`RECORDED`); a figure that could not be measured has a NaN value, ``ok``
    False and the reason in its note.
    """
    name: str
    value: float
    unit: str
    target: str
    ok: bool
    detail: dict[str, Any] = field(default_factory=dict)
    note: str = ""
    gating: bool = True


def settle() -> None:
    """Collect, then freeze what exists (the cases and truths built for timing).

    A worker holds one case at a time; the bench holds all of them, and without
    this every garbage collection would walk them inside the timed loops.
    """
    gc.collect()
    gc.freeze()


def rss_mb() -> float:
    """This process's resident memory now (MB; NaN where /proc is not readable)."""
    return resident_mb([os.getpid()])


def session_rss_mb(sid: int) -> float:
    """Proportional resident memory (PSS) of the processes in session ``sid`` now (MB).

    PSS splits each shared page among its sharers, so forked workers are not
    counted twice for the pages they share with the forkserver.
    """
    total_kb = 0
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            if int(fields[3]) != sid:  # field 6 of stat: the session id
                continue
            for line in (stat.parent / "smaps_rollup").read_text().splitlines():
                if line.startswith("Pss:"):
                    total_kb += int(line.split()[1])
        except (OSError, ValueError, IndexError):
            continue  # the process ended while we looked
    return total_kb / 1024


def run_measured(cmd: Sequence[str]) -> tuple[int, float, float, str]:
    """Run ``cmd`` in its own session: return code, wall seconds, peak session RSS, stderr tail."""
    start = time.perf_counter()
    with tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=err,
                                start_new_session=True)
        peak = 0.0
        while proc.poll() is None:
            peak = max(peak, session_rss_mb(proc.pid))
            time.sleep(0.1)
        wall = time.perf_counter() - start
        err.seek(0)
        tail = err.read()[-300:]
    return proc.returncode, wall, peak, tail
