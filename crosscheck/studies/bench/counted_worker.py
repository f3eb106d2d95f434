"""The counting side of the counted harness-overhead figures: runs under callgrind, counts, says
which dumps hold what.

Started by :mod:`crosscheck.studies.bench.counted` as ``valgrind --tool=callgrind ...
python -m crosscheck.studies.bench.counted_worker N REPORT`` (one process for every
figure, so Valgrind's and the engines' start-up are paid once).  It counts the empty
counting loop once, then, for each stream of :func:`~crosscheck.studies.bench.streams.
overhead_streams` (``N`` cases each):

1. builds the cases, the raw loop and the exact truths (not counted);
2. runs each path once, uncounted (imports, engine caches, Python's specialised
   bytecode);
3. collects and freezes the objects it holds and turns the garbage collector off, as the
   counting worker of a run does (:mod:`crosscheck.run.cost_worker`);
4. counts one call of each path, one dump each: the raw loop over the ``N`` cases, the
   engine path (``execute`` per case) and the harness (``execute`` per case, then
   ``score_lines`` into JSON lines).

It then writes ``REPORT``, a JSON object: its pid, the number of cases, the empty loop's
dump, and per stream the engine, kind, the engine's shared objects and the dump number of
each path.  Its stdout is the engines' (nothing is read from it).
"""

from __future__ import annotations

import gc
import json
import os
import sys
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

from crosscheck.run.callgrind import Counter
from crosscheck.studies.bench.kit import settle
from crosscheck.studies.bench.streams import engine_path, harness, overhead_streams

PATHS = ("raw", "engine path", "harness")
"""The paths counted per stream, in the order they are counted."""


def _nothing() -> None:
    return None


def count_streams(counter: Counter, n: int) -> dict[str, Any]:
    """Count every path of every stream of ``n`` cases; the report (see the module docstring)."""
    report: dict[str, Any] = {"pid": os.getpid(), "cases": n, "streams": []}
    gc.disable()
    try:
        report["empty"] = counter.count(_nothing, 1, "empty")
    finally:
        gc.enable()
    for stream in overhead_streams(n):
        cases = stream.cases()
        adapter, run_slice = harness(stream.engine, cases)
        made: tuple[Callable[[], object], ...] = (
            stream.raw(), engine_path(adapter, cases), partial(run_slice, 0, n))
        paths = dict(zip(PATHS, made, strict=True))
        for path in paths.values():  # warm up, uncounted
            path()
        settle()
        gc.disable()
        try:
            dumps = {name: counter.count(path, 1, f"{stream.engine} {stream.kind} {name}")
                     for name, path in paths.items()}
        finally:
            gc.enable()
        report["streams"].append({"engine": stream.engine, "kind": stream.kind,
                                  "objects": list(adapter.binding_objects), "dumps": dumps})
    return report


def main(argv: list[str]) -> int:
    n, out = int(argv[1]), Path(argv[2])
    report = count_streams(Counter(), n)
    out.write_text(json.dumps(report), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
