"""A/B symmetry: does an engine's answer on a swapped twin mirror its original answer?

Swapping A and B must leave ``hit`` and ``distance`` unchanged, negate
``normal`` and exchange ``v1`` and ``v2``.  The exact oracle does so by
construction (tested); engines need not, and where they do not, that is data
the report lists.  Values are compared within the row's tolerance (a verdict
exactly); rows the engine did not answer on both sides are left out.

>>> mirror_value("normal", [0.6, -0.8])
[-0.6, 0.8]
"""

from __future__ import annotations

import math
from typing import Any

import pandas as pd

from crosscheck.core.values import decode, text_of

_PARTNER = {"v1": "v2", "v2": "v1"}


def mirror_value(quantity: str, value: Any) -> Any:
    """What the swapped case's ``quantity`` should be, given the original's value."""
    if quantity == "normal" and isinstance(value, list):
        return [-x for x in value]
    return value


def _close(a: Any, b: Any, tolerance: float) -> bool:
    if isinstance(a, bool) or isinstance(b, bool):
        return bool(a == b)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y, tolerance) for x, y in zip(a, b, strict=True))
    if isinstance(a, float | int) and isinstance(b, float | int):
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        if a == b:  # equal, infinities included (inf - inf is NaN)
            return True
        return abs(a - b) <= (tolerance if math.isfinite(tolerance) else 0.0)
    return bool(a == b)


def asymmetries(frame: pd.DataFrame) -> pd.DataFrame:
    """Rows where an engine's swapped answer does not mirror its original answer."""
    cols = ["case_id", "engine", "quantity", "value", "tolerance"]
    twins = frame[frame["twin_of"].fillna("") != ""]
    twins = twins[cols].assign(case_id=twins["twin_of"])
    twins["quantity"] = twins["quantity"].map(lambda q: _PARTNER.get(q, q))
    both = frame[cols].merge(twins, on=["case_id", "engine", "quantity"],
                             suffixes=("", "_swapped"))
    rows = []
    for row in both.to_dict("records"):
        original, swapped = decode(row["value"]), decode(row["value_swapped"])
        if original is None or swapped is None:
            continue
        expected = mirror_value(str(row["quantity"]), original)
        if not _close(expected, swapped, float(row["tolerance"])):
            rows.append({"case_id": row["case_id"], "engine": row["engine"],
                         "quantity": row["quantity"], "value": row["value"],
                         "swapped_value": row["value_swapped"],
                         "expected_swapped": text_of(expected)})
    return pd.DataFrame(rows, columns=["case_id", "engine", "quantity", "value",
                                       "swapped_value", "expected_swapped"])
