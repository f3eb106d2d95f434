"""``results.parquet``: the results table with typed columns, for pandas users.

``results.csv`` keeps every value as JSON text, exact but to be parsed.
The Parquet file holds the same rows with the values already typed, so
``pd.read_parquet`` needs no parsing:

- ``value_bool`` / ``truth_bool``: a verdict (``hit``);
- ``value_float`` / ``truth_float``: a number (``distance``, ``energy``);
- ``value_vector`` / ``truth_vector``: a vector (``normal``, ``v1``, ``v2``,
  ``momentum``), as a list of float64;
- scene positions and velocities (a vector per body) stay as JSON text in
  ``value`` and ``truth``.

A missing or undefined value is null in the typed columns; the row's
``status`` and ``reason`` say why.  Timing columns (``query_s`` and the rest)
describe the case x engine, so they repeat on each of its quantity rows.  The values come
decoded, once per run (:attr:`crosscheck.results.run.Run.decoded`): nothing is parsed here.

>>> typed([0.6, 0.8]), typed(True), typed(None), typed(1e-09), typed(float("inf"))
(('vector', [0.6, 0.8]), ('bool', True), (None, None), ('float', 1e-09), ('float', inf))
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from crosscheck.results import stored
from crosscheck.results.run import DECODED

KINDS = ("bool", "float", "vector")


def typed(value: object) -> tuple[str | None, Any]:
    """The type and value of one decoded cell (``(None, None)``: none, or not typable)."""
    if isinstance(value, bool):
        return "bool", value
    if isinstance(value, int | float):
        return "float", float(value)
    if isinstance(value, list) and all(isinstance(x, int | float) for x in value):
        return "vector", [float(x) for x in value]
    return None, None


def _columns(cells: pd.Series, prefix: str) -> dict[str, list[Any]]:
    """The typed columns of one decoded column."""
    out: dict[str, list[Any]] = {f"{prefix}_{kind}": [] for kind in KINDS}
    for cell in cells:
        kind, value = typed(cell)
        for name in KINDS:
            out[f"{prefix}_{name}"].append(value if kind == name else None)
    return out


def typed_frame(frame: pd.DataFrame, values: pd.DataFrame) -> pd.DataFrame:
    """The results with typed value and truth columns added beside the JSON text, from
    ``values``: the decoded columns (:func:`crosscheck.results.run.decoded`) of ``frame``."""
    out = frame.copy()
    for prefix in ("value", "truth"):
        columns = _columns(values[DECODED[prefix]], prefix)
        out[f"{prefix}_bool"] = pd.Series(columns[f"{prefix}_bool"], dtype="boolean")
        out[f"{prefix}_float"] = pd.Series(columns[f"{prefix}_float"], dtype="Float64")
        out[f"{prefix}_vector"] = columns[f"{prefix}_vector"]
    return out


def write_parquet(frame: pd.DataFrame, values: pd.DataFrame, directory: Path) -> Path:
    """Write ``results.parquet`` (pyarrow) from a results DataFrame (the run's whole table) and
    its decoded values, stamped (:func:`crosscheck.results.stored.stamp`) so that a later
    reader takes the table from it instead of parsing ``results.jsonl``; written whole or not
    at all (a temporary file renamed)."""
    path = directory / stored.FILE
    table = pa.Table.from_pandas(typed_frame(frame, values), preserve_index=False)
    table = table.replace_schema_metadata({**(table.schema.metadata or {}),
                                           **stored.stamp(directory, frame)})
    partial = path.with_suffix(".parquet.tmp")
    pq.write_table(table, partial)
    os.replace(partial, path)
    return path


