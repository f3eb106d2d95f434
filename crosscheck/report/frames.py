"""Rows of a DataFrame as plain Python records, without pandas' per-cell boxing.

``DataFrame.to_dict("records")`` boxes every cell through pandas' generic path (and iterates
Arrow-backed text columns element by element); the report walks tens of thousands of rows,
so :func:`records` reads each column once with ``tolist`` instead.  The records are the same:
numbers, booleans and text as Python objects, missing text as NaN.

>>> import pandas as pd
>>> frame = pd.DataFrame({"a": [1, 2], "b": ["x", "y"], "c": [0.5, 1.5], "d": [True, False]})
>>> records(frame) == frame.to_dict("records")
True
>>> [type(v).__name__ for v in records(frame)[0].values()]
['int', 'str', 'float', 'bool']
>>> big = pd.concat([frame] * SMALL, ignore_index=True)
>>> records(big)[-2:] == frame.to_dict("records")
True
"""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any

import pandas as pd

SMALL = 1000
"""Below this many rows a frame is read as one object array (fewer calls), above it column by
column (less conversion)."""


def records(frame: pd.DataFrame) -> list[dict[Hashable, Any]]:
    """The rows of ``frame`` as dicts by column name, as ``frame.to_dict("records")``."""
    names = list(frame.columns)
    if len(frame) < SMALL:  # one conversion of the whole block beats a call per column
        rows = frame.to_numpy(dtype=object).tolist()
        return [dict(zip(names, values, strict=True)) for values in rows]
    columns = [frame.iloc[:, i].tolist() for i in range(len(names))]
    return [dict(zip(names, values, strict=True)) for values in zip(*columns, strict=True)]

