"""The repeat check's answers (``repeats.jsonl``): each re-asked pair's second answer, and
whether it differs from the first.

``crosscheck run --repeat-check`` (:mod:`crosscheck.run.repeat`) appends one
:class:`RepeatRecord` per case x engine it asks again, as each answer comes: the second
answer of every quantity (its value text and status) and whether any of them differs from
the first (``nondeterministic``).  Reading a run, :func:`with_repeats` adds three columns to
its results (:data:`NOT_CHECKED` holds their value on a row that was not asked again: a
pair that agreed, a run without the check, a run written before format 5):

- ``nondeterministic``: True on every row of a pair whose answer changed;
- ``repeat_value``: the quantity's second answer, JSON text as ``value`` holds it;
- ``repeat_status``: the status of that answer.

>>> first = {"distance": ("-1.0", "disagree"), "hit": ("true", "agree")}
>>> changed(first, {"distance": ("-1.0", "disagree"), "hit": ("true", "agree")})
False
>>> changed(first, {"distance": ("-1.5", "disagree"), "hit": ("true", "agree")})
True
>>> changed(first, {"distance": ("null", "crash"), "hit": ("null", "crash")})
True
>>> changed(first, {"distance": ("null", "timeout"), "hit": ("null", "timeout")})
False
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.results import jsonlines

FILE = "repeats.jsonl"

Answer = tuple[str, str]
"""One quantity's answer as a results row holds it: (value text, status)."""

NOT_CHECKED: dict[str, Any] = {"nondeterministic": False, "repeat_value": None,
                               "repeat_status": ""}
"""The repeat columns of a row whose pair was not asked again."""
REPEAT_COLUMNS = tuple(NOT_CHECKED)


def changed(first: Mapping[str, Answer], second: Mapping[str, Answer]) -> bool:
    """Whether any quantity's value text or status differs between the two answers.  A second
    answer that ran out of time decides nothing (False): whether an answer comes in time
    depends on the machine's load as much as on the engine."""
    if any(status == "timeout" for _, status in second.values()):
        return False
    return any(second.get(quantity) != answer for quantity, answer in first.items())


@dataclass(frozen=True)
class RepeatRecord:
    """The second answer of one case x engine, quantity by quantity."""

    case_id: str
    engine: str
    answers: dict[str, Answer] = field(default_factory=dict)
    nondeterministic: bool = False

    def to_json(self) -> str:
        """The record's line in ``repeats.jsonl`` (without the newline)."""
        return json.dumps({
            "case_id": self.case_id, "engine": self.engine,
            "nondeterministic": self.nondeterministic,
            "answers": {q: {"value": v, "status": s} for q, (v, s) in self.answers.items()}})

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> RepeatRecord:
        answers = {str(q): (str(a["value"]), str(a["status"]))
                   for q, a in data["answers"].items()}
        return cls(str(data["case_id"]), str(data["engine"]), answers,
                   bool(data["nondeterministic"]))


def read_repeats(directory: Path) -> dict[tuple[str, str], RepeatRecord]:
    """The repeat records of a run by (case id, engine); a half-written last line (a killed
    run) is left out; none when the run has no ``repeats.jsonl``."""
    path = directory / FILE
    records: dict[tuple[str, str], RepeatRecord] = {}
    for line in jsonlines.parse_lines(path):  # a half-written last line is left out
        try:
            record = RepeatRecord.from_json(line)
        except (KeyError, TypeError, AttributeError):
            continue  # a line cut where it still reads as JSON
        records[(record.case_id, record.engine)] = record
    return records


def with_repeats(frame: pd.DataFrame, directory: Path) -> pd.DataFrame:
    """The results ``frame`` with the repeat columns, filled from the run's repeat records
    (:data:`NOT_CHECKED` on every other row), in the frame's row order."""
    records = read_repeats(directory)
    columns: dict[str, list[Any]] = {name: [] for name in REPEAT_COLUMNS}
    if not records:  # nothing asked again: every row is NOT_CHECKED
        columns = {name: [value] * len(frame) for name, value in NOT_CHECKED.items()}
    keys = zip(frame["case_id"].tolist(), frame["engine"].tolist(), frame["quantity"].tolist(),
               strict=True) if records else ()
    for case_id, engine, quantity in keys:
        record = records.get((str(case_id), str(engine)))
        answer = record.answers.get(str(quantity)) if record else None
        if record is None or answer is None:
            for name, value in NOT_CHECKED.items():
                columns[name].append(value)
            continue
        columns["nondeterministic"].append(record.nondeterministic)
        columns["repeat_value"].append(answer[0])
        columns["repeat_status"].append(answer[1])
    return frame.assign(nondeterministic=pd.Series(columns["nondeterministic"], dtype=bool,
                                                   index=frame.index),
                        repeat_value=pd.Series(columns["repeat_value"], dtype=object,
                                               index=frame.index),
                        repeat_status=pd.Series(columns["repeat_status"], dtype=object,
                                                index=frame.index))
