"""The results table as stored columns: ``results.parquet`` read back instead of ``results.jsonl``.

Parsing ``results.jsonl`` (every row's JSON, then the side files joined) is most of the cost
of re-rendering a large run; the report writes the same table, typed, to ``results.parquet``
(:mod:`crosscheck.report.parquet`).  That file carries a :func:`stamp`: the size of
``results.jsonl`` it was built from, its row count, and which columns are Python objects in
the table (Parquet reads them back as text).  :func:`read_results` returns the table from it
only when it is :func:`up_to_date`: the stamp is there and names the current size of
``results.jsonl`` (the store only appends; a resumed run rewrites it), and the file was written
after every file the table is built from (the rows, the cases and ``run.json``, which order
them, and the side files joined to them).  Otherwise (an older run, a run that grew since,
a file cut short) it returns None and the reader parses ``results.jsonl`` as before.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from crosscheck.results import counts, repeats, timings

FILE = "results.parquet"
KEY = b"crosscheck.stored"
"""The key of the stamp in the Parquet file's metadata."""
VERSION = 1
"""The stamp's version: a file stamped otherwise is not read back."""
SOURCES = ("results.jsonl", "cases.jsonl", "run.json", timings.FILE, counts.FILE, repeats.FILE)
"""The files the results table is built from: a stored copy older than one of them is stale."""


def stamp(directory: Path, frame: pd.DataFrame) -> dict[bytes, bytes]:
    """The metadata to store with ``frame``, the results table of the run in ``directory``."""
    rows = directory / "results.jsonl"
    data = {"version": VERSION, "jsonl_bytes": rows.stat().st_size if rows.exists() else None,
            "rows": len(frame), "columns": [str(c) for c in frame.columns],
            "objects": [str(c) for c in frame.columns if frame[c].dtype == object]}
    return {KEY: json.dumps(data).encode()}


def up_to_date(directory: Path, path: Path) -> bool:
    """Whether ``path`` was written after every file of :data:`SOURCES` in ``directory``."""
    try:
        written = path.stat().st_mtime_ns
    except FileNotFoundError:
        return False
    return all(written >= source.stat().st_mtime_ns
               for source in (directory / name for name in SOURCES) if source.exists())


def read_results(directory: Path) -> pd.DataFrame | None:
    """The results table from ``results.parquet`` when it is up to date with the rows and the
    side files it was built from, in the columns and types the table has (None: parse them)."""
    path = directory / FILE
    if not up_to_date(directory, path):
        return None
    try:
        table = pq.ParquetFile(path)
        data = _stamp(table.schema_arrow.metadata)
        rows = directory / "results.jsonl"
        if (data is None or data.get("jsonl_bytes") != rows.stat().st_size
                or data.get("rows") != table.metadata.num_rows):
            return None
        frame = table.read(columns=data["columns"]).to_pandas()
    except (OSError, pa.ArrowException, KeyError, ValueError):
        return None  # cut short, or not this harness's file
    return _objects(frame, data["objects"])


def _stamp(metadata: dict[bytes, bytes] | None) -> dict[str, Any] | None:
    """The stamp in a file's metadata (None: none, or of another version)."""
    text = (metadata or {}).get(KEY)
    data = json.loads(text) if text else None
    return data if isinstance(data, dict) and data.get("version") == VERSION else None


def _objects(frame: pd.DataFrame, names: Sequence[str]) -> pd.DataFrame:
    """``frame`` with ``names`` as Python objects again, a missing cell None (as written)."""
    for name in names:
        column = frame[name].astype(object)
        frame[name] = column.where(column.notna(), None)
    return frame
