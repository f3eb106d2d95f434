"""Counted instructions of a run (``counts.jsonl``): the deterministic cost of each sampled pair.

With ``crosscheck run --timer instructions`` the cost phase
(:mod:`crosscheck.run.cost`) counts, under Valgrind's callgrind, the
instructions of a loop of ``calls`` queries of each sampled case x engine, and
of the same loop around an empty call; it appends one :class:`CountRecord` per
pair with the raw counts.  A separate file from ``timings.jsonl``, so that a
reader of wall-clock samples never meets a count, and a resumed run knows
which pairs each timer has done.

Per query, net of the loop's own cost::

    query_instructions  = (instructions - empty_instructions) / calls
    engine_instructions = engine_ir / calls

``engine_ir`` is what callgrind counted inside calls into the engine's shared objects
(:attr:`~crosscheck.core.contract.Adapter.binding_objects`): the engine's own work.
The rest of ``query_instructions`` is the harness's Python path of the query
(the adapter's code and the interpreter running it).

>>> r = CountRecord("c", "fcl", "sphere", "call", calls=10, instructions=1_000_500,
...                 empty=500, engine_ir=900_000)
>>> r.per_call, r.engine_per_call
(100000.0, 90000.0)
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.results import jsonlines

FILE = "counts.jsonl"
COLUMNS = ["case_id", "engine", "kind", "unit", "calls", "instructions", "empty", "engine_ir",
           "query_instructions", "engine_instructions"]
RESULT_COLUMNS = ("query_instructions", "engine_instructions")
"""The columns a run's results gain from its counts (NaN where a pair was not counted)."""


@dataclass(frozen=True, slots=True)
class CountRecord:
    """The raw instruction counts of one case x engine."""

    case_id: str
    engine: str
    kind: str
    unit: str
    """``"call"``: a loop of ``calls`` queries; ``"scene"``: one whole stepped scene run."""
    calls: int
    instructions: int
    """Counted in the loop of ``calls`` queries, the loop itself included."""
    empty: int
    """Counted in the same loop around a call that does nothing."""
    engine_ir: int = 0
    """Of ``instructions``, those inside calls into the engine's shared objects (0: the
    adapter names none)."""

    @property
    def per_call(self) -> float:
        """Instructions per query, net of the loop's own cost."""
        return (self.instructions - self.empty) / self.calls

    @property
    def engine_per_call(self) -> float:
        """Instructions per query inside the engine's entry points."""
        return self.engine_ir / self.calls

    def to_json(self) -> str:
        return json.dumps(asdict(self))


def read_counts(directory: Path) -> pd.DataFrame:
    """The count records of a run, one row per case x engine (the last one kept), with the
    per-query figures; empty if the run counted nothing."""
    path = directory / FILE
    rows: list[dict[str, Any]] = []
    for line in jsonlines.parse_lines(path):  # a half-written last line is left out
        try:
            record = CountRecord(**line)
        except TypeError:
            continue  # a line cut where it still reads as JSON
        rows.append({"case_id": record.case_id, "engine": record.engine,
                         "kind": record.kind, "unit": record.unit, "calls": record.calls,
                         "instructions": record.instructions, "empty": record.empty,
                         "engine_ir": record.engine_ir, "query_instructions": record.per_call,
                         "engine_instructions": (record.engine_per_call if record.engine_ir
                                                 else math.nan)})
    frame = pd.DataFrame(rows, columns=COLUMNS)
    return frame.drop_duplicates(["case_id", "engine"], keep="last").reset_index(drop=True)


def counted_pairs(directory: Path) -> set[tuple[str, str]]:
    """The (case id, engine) pairs a run has counted."""
    frame = read_counts(directory)
    return set(zip(frame["case_id"].astype(str), frame["engine"].astype(str), strict=True))


def with_counts(frame: pd.DataFrame, directory: Path) -> pd.DataFrame:
    """The results ``frame`` with :data:`RESULT_COLUMNS` filled from the run's counts (NaN
    where a pair was not counted: a run without ``--timer instructions`` has them empty)."""
    for column in RESULT_COLUMNS:
        frame[column] = math.nan
    counts = read_counts(directory)
    if counts.empty or frame.empty:
        return frame
    keyed = counts.set_index(["case_id", "engine"])
    keys = pd.MultiIndex.from_frame(frame[["case_id", "engine"]])
    found = keys.isin(keyed.index)
    if found.any():
        rows = keyed.reindex(keys[found])
        for column in RESULT_COLUMNS:
            frame.loc[found, column] = rows[column].to_numpy(dtype=float)
    return frame
