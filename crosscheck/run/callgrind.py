"""Counting instructions under Valgrind's callgrind: the command, the client requests, the
dumps.

Wall time on a shared machine drifts by half within a run; the number of instructions a
query executes does not. The instruction timer (:mod:`crosscheck.run.cost`) runs each
engine library's worker under ``valgrind --tool=callgrind --instr-atstart=no`` and, around
a loop of queries, issues callgrind's client requests: start instrumentation, and dump the
counts just before and just after the loop (a dump zeroes them). Nothing outside the loop
is counted, so neither the interpreter's start-up nor the engine's import reaches a figure
(instrumentation starts with the first count); and only the thread that runs the queries
is counted (:data:`QUERY_THREAD`).

The client requests are machine instructions that only Valgrind recognises; Python issues
them through the native hooks that CodSpeed ships in ``pytest-codspeed`` (the
``callgrind_start_instrumentation``, ``callgrind_stop_instrumentation`` and
``instrument_hooks_set_executed_benchmark`` functions of its ``dist_instrument_hooks``
module: the last dumps the counts with a label).

A dump (callgrind's format, names compressed as ``(id) name`` the first time and ``(id)``
after, positions absolute with ``--compress-pos=no``) holds every function's cost and
every call's inclusive cost. :func:`read_dump` takes two figures from it: the total, and
the instructions inside calls that enter the engine's shared objects from outside them
(:attr:`Adapter.binding_objects <crosscheck.core.contract.Adapter.binding_objects>`): the
engine's own work, its library and what it calls included; the rest is the harness's
Python path.

>>> text = '''events: Ir
... ob=/usr/lib/libpython3.11.so
... fn=PyObject_Call
... 10 100
... cob=/venv/site-packages/pybullet.cpython-311-x86_64-linux-gnu.so
... cfn=pybullet_getClosestPointData
... calls=2 0
... 10 4000
... ob=/venv/site-packages/pybullet.cpython-311-x86_64-linux-gnu.so
... fn=pybullet_getClosestPointData
... 1 3000
... cob=/lib/libc.so.6
... cfn=malloc
... calls=2 0
... 1 1000
... totals: 4100
... '''
>>> parse_dump(text, ("pybullet*.so",))
Counts(total=4100, engine=4000)
"""

from __future__ import annotations

import fnmatch
import importlib
import os
import shutil
import subprocess
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

VALGRIND_OPTIONS = ("--tool=callgrind", "--instr-atstart=no", "--separate-threads=yes",
                    "--compress-pos=no", "-q")
"""What every counting worker runs under (its output file and log are added per worker)."""
QUERY_THREAD = 1
"""The thread whose instructions are counted: the worker's main thread, which runs the
queries.  An engine's own worker threads are not counted: what they do between jobs (a
work-stealing pool's search for work, rapier's rayon threads) depends on how the kernel
schedules them, not on the code.  Measured on rapier's pairs of ``cases/sphere.toml`` and
``cases/aabb.toml``: with every thread counted, two runs differed by up to 14% on a pair;
with the querying thread alone, by 0.12% (rapier's parallel pipeline ran its work on it)."""

HOOKS = "pytest_codspeed.instruments.hooks.dist_instrument_hooks"
"""The module that issues callgrind's client requests from Python (see the module docstring)."""


@dataclass(frozen=True, slots=True)
class Counts:
    """Instructions of one dump: all of them, and those inside the engine's entry points."""

    total: int
    engine: int


def valgrind() -> str | None:
    """The path of ``valgrind``, or None."""
    return shutil.which("valgrind")


def missing() -> str | None:
    """Why instructions cannot be counted here (None: they can)."""
    if valgrind() is None:
        return ("valgrind is not installed: install Debian's valgrind (make does it as root) "
                "to count instructions")
    try:
        hooks()
    except ImportError as exc:
        return f"no callgrind client requests from Python ({HOOKS}: {exc})"
    return None


def hooks() -> Any:
    """The native module that issues the client requests (ImportError if it is missing)."""
    module = importlib.import_module(HOOKS)
    for name in ("callgrind_start_instrumentation", "callgrind_stop_instrumentation",
                 "instrument_hooks_init", "instrument_hooks_set_executed_benchmark"):
        if not hasattr(module, name):
            raise ImportError(f"it has no {name}")
    return module


def command(python: Sequence[str], out_dir: Path) -> list[str]:
    """The command that runs ``python`` (an interpreter and its arguments) under callgrind,
    its dumps written to ``out_dir/cg.<pid>.<n>`` and Valgrind's own messages to
    ``out_dir/valgrind.log``."""
    tool = valgrind()
    if tool is None:
        raise FileNotFoundError("valgrind is not installed")
    return [tool, *VALGRIND_OPTIONS, f"--callgrind-out-file={out_dir}/cg.%p",
            f"--log-file={out_dir}/valgrind.log", *python]


class Counter:
    """In a process running under callgrind: count the instructions of a loop of calls.

    Instrumentation is switched on at the first count and stays on: switching it off and
    on again makes Valgrind translate every code block anew, which cost more than the
    counting itself (0.74 s a case against 0.29 s, for PyBullet's spheres).  A count is
    then the span between two dumps (a dump zeroes the counts): one just before the
    loop, whose counts are thrown away, and one just after it.  The dumps of a process
    are numbered 1, 2, ... in the order they were made.
    """

    def __init__(self) -> None:
        self._hooks = hooks()
        self._instance = self._hooks.instrument_hooks_init()
        self.dumps = 0
        self._started = False

    def _dump(self, label: str) -> int:
        self._hooks.instrument_hooks_set_executed_benchmark(
            self._instance, os.getpid(), label.encode("ascii", "replace"))
        self.dumps += 1
        return self.dumps

    def count(self, fn: Callable[[], object], calls: int, label: str) -> int:
        """Count ``calls`` calls of ``fn`` (in one loop, its own cost included); the number of
        the dump that holds the count (the one before it holds what preceded the loop)."""
        if not self._started:
            self._hooks.callgrind_start_instrumentation()
            self._started = True
        loop = range(calls)
        self._dump("before " + label)
        for _ in loop:
            fn()
        return self._dump(label)


def dump_path(out_dir: Path, pid: int, number: int) -> Path:
    """Where callgrind wrote dump ``number`` of process ``pid`` for :data:`QUERY_THREAD`."""
    return out_dir / f"cg.{pid}.{number}-{QUERY_THREAD:02d}"


def dump_files(out_dir: Path, pid: int, number: int) -> list[Path]:
    """Every file of dump ``number`` of process ``pid`` (one per thread that ran)."""
    return sorted(out_dir.glob(f"cg.{pid}.{number}-*"))


def _matches(path: str, patterns: Sequence[str]) -> bool:
    name = path.rsplit("/", 1)[-1]
    return any(fnmatch.fnmatch(name, p) or fnmatch.fnmatch(path, p) for p in patterns)


def parse_dump(text: str, objects: Sequence[str]) -> Counts:
    """The total and the engine's instructions of one dump (see the module docstring).

    A call counts for the engine when its callee's object matches ``objects`` (a
    pattern on the file name or the whole path) and its caller's does not: calls
    inside the engine are already in the inclusive cost of the call that entered it.
    """
    total = engine = 0
    current = callee = ""
    inside: dict[str, bool] = {}
    names: dict[str, str] = {}
    pending = False

    def named(value: str) -> str:  # "(3) /lib/x.so" defines object 3; "(3)" refers to it
        if not value.startswith("("):
            return value
        key, _, name = value[1:].partition(")")
        if name.strip():
            names[key] = name.strip()
        return names.get(key, value)

    def within(obj: str) -> bool:
        if obj not in inside:
            inside[obj] = bool(objects) and _matches(obj, objects)
        return inside[obj]

    for line in text.splitlines():
        if pending:  # the inclusive cost line after calls=: "<position> <Ir> ..."
            fields = line.split()
            if len(fields) > 1 and within(callee) and not within(current):
                engine += int(fields[1])
            pending, callee = False, ""
        elif line.startswith("ob="):
            current = named(line[3:])
        elif line.startswith("cob="):
            callee = named(line[4:])
        elif line.startswith("calls="):
            callee, pending = callee or current, True
        elif line.startswith("totals:"):
            total = int(line.split()[1])
    return Counts(total, engine)


def read_dump(path: Path, objects: Sequence[str]) -> Counts:
    """:func:`parse_dump` of the file at ``path``."""
    return parse_dump(path.read_text(encoding="utf-8", errors="replace"), objects)


def version() -> str:
    """Valgrind's version line, or why there is none."""
    tool = valgrind()
    if tool is None:
        return "not installed"
    done = subprocess.run([tool, "--version"], capture_output=True, text=True, check=False)
    return done.stdout.strip() or done.stderr.strip()
