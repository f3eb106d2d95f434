"""Reading a run's JSON-lines files: the one reader, at the cost of one parse per file.

Every JSON-lines file of a run folder (``results.jsonl``, ``cases.jsonl``, ``timings.jsonl``,
``counts.jsonl``, ``repeats.jsonl``, ``series.jsonl``, ``scene_facts.jsonl``) is read by
:func:`read_lines` (or :func:`parse_lines`, its parsed half), the one place that tolerates a
half-written last line: a line that is not whole JSON (what a killed run leaves) is left out.
A full run's ``results.jsonl`` holds over a hundred thousand rows: the whole file is parsed
in one ``json.loads`` (a call per line costs about twice as much), and only a file with a
line that is not whole JSON is read line by line.  :func:`by_column` and
:func:`each_distinct` build the results frame's columns without a per-row pandas path.

>>> by_column([{"a": 1, "b": "x"}, {"a": 2}], ("a", "b"))
{'a': [1, 2], 'b': ['x', nan]}
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

Line = tuple[str, Any]
"""A whole line of a JSON-lines file: its text as written and its parsed content."""


def read_lines(path: Path) -> list[Line]:
    """Every whole line of a JSON-lines file, as written and parsed, in file order (none when
    the file does not exist; a blank line, or one that is not whole JSON, is left out)."""
    if not path.exists():
        return []
    texts = [text for text in path.read_text(encoding="utf-8").splitlines() if text.strip()]
    try:
        rows: list[Any] = json.loads("[" + ",".join(texts) + "]")
    except json.JSONDecodeError:
        rows = []
    if len(rows) == len(texts):
        return list(zip(texts, rows, strict=True))
    out = []
    for text in texts:
        try:
            out.append((text, json.loads(text)))
        except json.JSONDecodeError:
            continue  # a half-written last line of a killed run
    return out


def parse_lines(path: Path) -> list[Any]:
    """Every whole line of a JSON-lines file, parsed (:func:`read_lines` without the texts)."""
    return [data for _, data in read_lines(path)]


def by_column(rows: Sequence[dict[str, Any]], columns: Sequence[str]) -> dict[str, list[Any]]:
    """The rows' ``columns`` as lists; a field a row lacks is NaN, as pandas' list-of-dicts
    constructor fills it (that constructor costs about twice as much)."""
    try:
        return {column: [row[column] for row in rows] for column in columns}
    except KeyError:  # a field an older format lacks
        return {column: [row.get(column, math.nan) for row in rows] for column in columns}


def each_distinct(values: pd.Series, function: Callable[[Any], Any]) -> pd.Series:
    """``values.map(function)``, ``function`` called once per distinct value (a results column
    repeats a few texts across every row).

    >>> each_distinct(pd.Series(["a", "bb", "a"]), len).tolist()
    [1, 2, 1]
    """
    codes, distinct = pd.factorize(values, use_na_sentinel=False)
    mapped = [function(value) for value in distinct]
    return pd.Series([mapped[code] for code in codes], index=values.index)
