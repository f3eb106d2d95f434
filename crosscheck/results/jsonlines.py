"""Reading a run's JSON-lines files into columns, at the cost of one parse per file.

A full run's ``results.jsonl`` holds over a hundred thousand rows: :func:`parse_lines`
parses the whole file in one ``json.loads`` (a call per line costs about twice as much), and
:func:`by_column` and :func:`each_distinct` build the results frame's columns without a
per-row pandas path.  A file with a line that is not whole JSON (the half-written last line
of a killed run) is read line by line, that line left out, as
:mod:`crosscheck.results.store` has always read it.

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


def parse_lines(path: Path) -> list[Any]:
    """Every whole line of a JSON-lines file, parsed (none when the file does not exist)."""
    if not path.exists():
        return []
    texts = [text for text in path.read_text(encoding="utf-8").splitlines() if text.strip()]
    try:
        rows: list[Any] = json.loads("[" + ",".join(texts) + "]")
    except json.JSONDecodeError:
        rows = []
    if len(rows) == len(texts):
        return rows
    out = []
    for text in texts:
        try:
            out.append(json.loads(text))
        except json.JSONDecodeError:
            continue  # a half-written last line of a killed run
    return out


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
