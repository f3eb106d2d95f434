"""The counted harness-overhead figures: instructions under callgrind, so a figure moves only
when the code does.

The wall-clock overhead figures (:func:`~crosscheck.studies.bench.figures.overhead_figures`)
drift with the shared machine's load, by tens of points between two benches; they are
recorded, never gating.  These figures judge the same target on the same four streams
(:func:`~crosscheck.studies.bench.streams.overhead_streams`: FCL in 3-D and pymunk in
2-D, spheres and boxes) in instructions: per case, the harness (``execute`` plus
``score_lines`` into JSON lines) over the raw engine loop
(:mod:`crosscheck.studies.bench.rawloops`), with the engine path alone (``execute``)
beside it.  A count is exact: the same code on the same inputs gives the same
instructions within about half a percent, whatever the machine's load; the number of
cases only averages the per-case variation.

Everything is counted in one process under Valgrind
(:mod:`crosscheck.studies.bench.counted_worker`, started with
:func:`crosscheck.run.callgrind.command`), so its start-up is paid once; this side reads
its dumps (:func:`crosscheck.run.callgrind.read_dump`), deletes them, and builds the
figures (:func:`figures_from`, :func:`counted_figure`).  Without Valgrind or its client
requests, or when the counting process fails, each figure is NaN, not met, and its note
says why (:func:`unmeasured`).

>>> from crosscheck.run.callgrind import Counts
>>> counts = {"raw": Counts(200_100, 150_000), "engine path": Counts(300_100, 150_000),
...           "harness": Counts(400_100, 150_000)}
>>> f = counted_figure("fcl", "sphere", 100, counts, Counts(100, 0), "valgrind-3.19.0")
>>> f.name, f.value, f.ok, f.detail["raw_instructions"], f.detail["engine_path_overhead_pct"]
('harness overhead fcl sphere, counted instructions', 100.0, False, 2000.0, 50.0)
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from crosscheck.run import callgrind
from crosscheck.run.cost import ENV
from crosscheck.run.runner import CHUNK_CASES
from crosscheck.studies.bench.kit import Figure
from crosscheck.studies.bench.streams import OVERHEAD_LIMIT_PCT, overhead_streams

CASES = CHUNK_CASES
"""Cases per stream: one chunk of the runner's columnar scoring (the count is exact: more
cases would only average the per-case variation, and spread the scoring's fixed cost
thinner than the runner does)."""
TIMEOUT_S = 900.0
"""The time the whole counting process may take (it takes well under a minute)."""
WORKER = "crosscheck.studies.bench.counted_worker"
"""The module run under callgrind."""
METHOD = ("instructions counted under Valgrind's callgrind in one process, on its main thread: "
          "per engine x kind, one uncounted pass of each path, then one counted pass of each "
          "over the cases with the garbage collector off, net of the empty counting loop; "
          "per case = count / cases")
"""How the figures were counted, in words (each figure's detail)."""


def name(engine: str, kind: str) -> str:
    """The counted figure's name (the wall-clock figure's, with how it was measured)."""
    return f"harness overhead {engine} {kind}, counted instructions"


def counted_figure(engine: str, kind: str, cases: int, counts: Mapping[str, callgrind.Counts],
                   empty: callgrind.Counts, valgrind: str,
                   limit: float = OVERHEAD_LIMIT_PCT) -> Figure:
    """The figure of one stream from its dumps: ``counts`` of the ``raw``, ``engine path`` and
    ``harness`` passes over ``cases`` cases, each net of the ``empty`` counting loop.

    The value is the harness's instructions per case over the raw loop's, less one, in
    percent; it meets the target when at most ``limit``.  The detail adds the engine
    path's overhead, the instructions per case of each path, and how many of them ran
    inside the engine's shared objects.
    """
    per = {path: (c.total - empty.total) / cases for path, c in counts.items()}
    inside = {path: c.engine / cases for path, c in counts.items()}
    raw, path, full = per["raw"], per["engine path"], per["harness"]
    over, path_over = full / raw - 1.0, path / raw - 1.0
    return Figure(
        name(engine, kind), over * 100.0, "%", f"<= {limit:.0f}%", over <= limit / 100.0,
        {"cases": cases, "raw_instructions": raw, "engine_path_instructions": path,
         "harness_instructions": full, "engine_path_overhead_pct": path_over * 100.0,
         "raw_engine_instructions": inside["raw"],
         "engine_path_engine_instructions": inside["engine path"],
         "harness_engine_instructions": inside["harness"],
         "empty_loop_instructions": empty.total, "valgrind": valgrind, "method": METHOD},
        note=(f"instructions per case, {cases} cases under callgrind: raw {raw:,.0f}, engine "
              f"path {path:,.0f} (+{path_over * 100.0:.0f}%), harness {full:,.0f}"))


def unmeasured(why: str) -> list[Figure]:
    """Every counted figure, not measured: NaN, not met, ``why`` in its note."""
    return [Figure(name(s.engine, s.kind), math.nan, "%", f"<= {OVERHEAD_LIMIT_PCT:.0f}%",
                   False, {"not_counted": why}, note=f"not counted: {why}")
            for s in overhead_streams(0)]


def _read(out_dir: Path, pid: int, number: int, objects: Sequence[str]) -> callgrind.Counts:
    """One dump of the counting process, its files deleted once read."""
    try:
        return callgrind.read_dump(callgrind.dump_path(out_dir, pid, number), objects)
    finally:
        for path in callgrind.dump_files(out_dir, pid, number):
            path.unlink(missing_ok=True)


def figures_from(out_dir: Path, report: Mapping[str, Any], valgrind: str) -> list[Figure]:
    """The figures of a counting process's ``report`` (its JSON, see
    :mod:`~crosscheck.studies.bench.counted_worker`), from its dumps in ``out_dir``."""
    pid, cases = int(report["pid"]), int(report["cases"])
    empty = _read(out_dir, pid, int(report["empty"]), ())
    figures = []
    for stream in report["streams"]:
        counts = {path: _read(out_dir, pid, int(number), stream["objects"])
                  for path, number in stream["dumps"].items()}
        figures.append(counted_figure(stream["engine"], stream["kind"], cases, counts, empty,
                                      valgrind))
    return figures


def counted_figures(cases: int = CASES) -> list[Figure]:
    """The counted harness-overhead figures of the four streams, ``cases`` cases each, from
    one process under callgrind (or :func:`unmeasured`, saying why)."""
    why = callgrind.missing()
    if why is not None:
        return unmeasured(why)
    with tempfile.TemporaryDirectory(prefix="crosscheck-bench-callgrind-") as tmp:
        out = Path(tmp)
        report = out / "report.json"
        command = callgrind.command([sys.executable, "-m", WORKER, str(cases), str(report)], out)
        try:
            done = subprocess.run(command, env=os.environ | ENV, stdin=subprocess.DEVNULL,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                  errors="replace", timeout=TIMEOUT_S, check=False)
        except subprocess.TimeoutExpired:
            return unmeasured(f"the counting process did not finish within {TIMEOUT_S:g} s")
        if done.returncode != 0 or not report.exists():
            tail = " ".join(done.stderr.strip().splitlines()[-3:]) or "no message"
            return unmeasured(f"the counting process failed (exit code {done.returncode}): "
                              f"{tail}")
        try:
            return figures_from(out, json.loads(report.read_text(encoding="utf-8")),
                                callgrind.version())
        except (OSError, ValueError, KeyError) as exc:
            return unmeasured(f"its counts could not be read: {type(exc).__name__}: {exc}")
