"""A run of fake engines whose costs are written by the test, never measured.

:func:`counted_run` runs fakes of known answers on a few sphere cases without a timing
phase (``--quick``), then writes each pair's cost itself: wall-clock samples in
``timings.jsonl`` (:class:`~crosscheck.results.timings.TimingRecord`) and instruction counts
in ``counts.jsonl`` (:class:`~crosscheck.results.counts.CountRecord`), as the timing phase and
``--timer instructions`` would, and renders the report.  The costs are chosen so that the
two measures disagree on the order: ``fake-right`` is the cheaper in instructions and the
slower on the wall clock, ``fake-twin`` (as right) the other way round.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import ClassVar

from crosscheck.core.options import RunOptions
from crosscheck.report.render import render
from crosscheck.results.counts import FILE as COUNTS_FILE
from crosscheck.results.counts import CountRecord
from crosscheck.results.store import ResultsStore
from crosscheck.results.timings import FILE as TIMINGS_FILE
from crosscheck.run.launch import launch, new_info
from tests.conftest import sphere
from tests.fakes import AlwaysRight, OffByOne


class Twin(AlwaysRight):
    """Exact, as ``fake-right``: the two tie on score and coverage, and cost decides."""

    name: ClassVar[str] = "fake-twin"


CASES = [sphere(0.0, 2.0 + i / 4, id=f"s{i}") for i in range(4)]
ENGINES = [AlwaysRight(), Twin(), OffByOne()]
WALL_S = {"fake-right": 3e-6, "fake-twin": 1e-6, "fake-off": 2e-6}
"""Seconds per query on the wall clock: fake-twin the fastest, fake-right the slowest."""
INSTRUCTIONS = {"fake-right": 50_000.0, "fake-twin": 80_000.0, "fake-off": 60_000.0}
"""Instructions per query: fake-right the cheapest, fake-twin the dearest."""
PARTLY = {e: n for e, n in INSTRUCTIONS.items() if e != "fake-twin"}
"""Every engine counted but fake-twin: the group is ranked by the wall clock."""
CALLS, EMPTY = 10, 500
"""The counted loop of each pair: queries, and the empty loop's instructions."""


def spread_of(median: float, case: int) -> tuple[float, ...]:
    """Three samples around ``median``, a little higher from case to case (a spread over
    cases, so that every IQR is above zero)."""
    level = median * (1 + case / 100)
    return (0.99 * level, level, 1.01 * level)


def timing_line(case: int, engine: str) -> str:
    """The ``timings.jsonl`` line of one pair: three samples (a line of any format reads)."""
    return json.dumps({"case_id": f"s{case}", "engine": engine, "kind": "sphere",
                       "unit": "call", "loops": 100, "overhead_s": 0.0,
                       "values": list(spread_of(WALL_S[engine], case))})


def count_record(case: int, engine: str, per_query: float) -> CountRecord:
    """The counts of one pair: ``per_query`` instructions per query (net of the loop), a
    little higher from case to case, 40% of them inside the engine."""
    level = per_query * (1 + case / 100)
    return CountRecord(f"s{case}", engine, "sphere", "call", calls=CALLS,
                       instructions=round(level * CALLS) + EMPTY, empty=EMPTY,
                       engine_ir=round(0.4 * level * CALLS))


def counted_run(folder: Path, counted: Mapping[str, float] = INSTRUCTIONS) -> Path:
    """The run in ``folder``, every pair timed at :data:`WALL_S`, the engines of ``counted``
    counted at their instructions per query (the others not at all), rendered."""
    options = RunOptions(quick=True, isolate=False)
    launch(ResultsStore(folder), CASES, ENGINES, options,
           new_info(folder, "test", options, ENGINES, CASES))
    pairs = [(i, e.name) for i in range(len(CASES)) for e in ENGINES]
    (folder / TIMINGS_FILE).write_text("".join(timing_line(i, e) + "\n" for i, e in pairs))
    (folder / COUNTS_FILE).write_text("".join(
        count_record(i, e, counted[e]).to_json() + "\n" for i, e in pairs if e in counted))
    render(folder)
    return folder
