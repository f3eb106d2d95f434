"""A/B symmetry: does an engine's answer on a swapped twin mirror its original answer?

Swapping A and B must leave ``hit`` and ``distance`` unchanged, negate
``normal`` and exchange ``v1`` and ``v2``.  The exact oracle does so by
construction (tested); engines need not, and where they do not, that is data
the report lists.  Values are compared within the row's tolerance (a verdict
exactly); rows the engine did not answer on both sides are left out.

A pair whose truth is undefined on either side (status ``undefined``: the normal
of coincident centres, say) has no right answer to mirror: it is still compared
and listed (``truth_undefined``), but :func:`summary` leaves it out of its counts.

>>> mirror_value("normal", [0.6, -0.8])
[-0.6, 0.8]
"""

from __future__ import annotations

import math
from typing import Any

import pandas as pd

from crosscheck.core.model import Status
from crosscheck.core.values import text_of
from crosscheck.report.frames import records
from crosscheck.results.run import DECODED

_PARTNER = {"v1": "v2", "v2": "v1"}
_VALUE = DECODED["value"]
COLUMNS = ["case_id", "engine", "quantity", "value", "swapped_value", "expected_swapped",
           "truth_undefined"]
"""The columns of :func:`asymmetries` (and of ``asymmetries.csv``)."""


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


def compared(frame: pd.DataFrame) -> pd.DataFrame:
    """Every original x engine x quantity answered on both sides: :data:`COLUMNS` and
    ``mirrors`` (whether the swapped answer mirrors the original's); ``frame`` carries its
    decoded values (:func:`crosscheck.results.run.decoded`)."""
    cols = ["case_id", "engine", "quantity", "value", _VALUE, "tolerance", "status"]
    twins = frame[frame["twin_of"].fillna("") != ""]
    twins = twins[cols].assign(case_id=twins["twin_of"])
    twins["quantity"] = twins["quantity"].map(lambda q: _PARTNER.get(q, q))
    both = frame[cols].merge(twins, on=["case_id", "engine", "quantity"],
                             suffixes=("", "_swapped"))
    rows = []
    for row in records(both):
        original, swapped = row[_VALUE], row[f"{_VALUE}_swapped"]
        if original is None or swapped is None:
            continue
        expected = mirror_value(str(row["quantity"]), original)
        rows.append({"case_id": row["case_id"], "engine": row["engine"],
                     "quantity": row["quantity"], "value": row["value"],
                     "swapped_value": row["value_swapped"],
                     "expected_swapped": text_of(expected),
                     "truth_undefined": Status.UNDEFINED in (row["status"],
                                                             row["status_swapped"]),
                     "mirrors": _close(expected, swapped, float(row["tolerance"]))})
    return pd.DataFrame(rows, columns=[*COLUMNS, "mirrors"])


def asymmetries(frame: pd.DataFrame, pairs: pd.DataFrame | None = None) -> pd.DataFrame:
    """Rows where an engine's swapped answer does not mirror its original answer (those
    whose truth is undefined included, marked ``truth_undefined``); ``pairs``: ``frame``'s
    :func:`compared`, when already made."""
    pairs = compared(frame) if pairs is None else pairs
    return pairs.loc[~pairs["mirrors"].astype(bool), COLUMNS].reset_index(drop=True)


def summary(pairs: pd.DataFrame) -> dict[str, Any]:
    """Counts of :func:`compared` pairs per engine x quantity, pairs whose truth is undefined
    left out: ``quantities`` (in run order), ``engines`` (per engine its ``asymmetric``
    and ``compared`` totals and per quantity ``[asymmetric, compared]``), ``asymmetric`` and
    ``compared`` (the run's totals) and ``undefined`` (the pairs left out, and how many of
    them do not mirror).

    >>> pairs = pd.DataFrame({"engine": ["e", "e", "e"], "quantity": ["hit", "hit", "normal"],
    ...                       "mirrors": [True, False, False],
    ...                       "truth_undefined": [False, False, True]})
    >>> s = summary(pairs)
    >>> s["engines"][0]["cells"], s["asymmetric"], s["compared"], s["undefined"]
    ({'hit': [1, 2]}, 1, 2, {'pairs': 1, 'asymmetric': 1})
    """
    undefined = pairs["truth_undefined"].astype(bool)
    kept = pairs[~undefined].assign(asymmetric=~pairs["mirrors"].astype(bool))
    quantities = [str(q) for q in dict.fromkeys(kept["quantity"])]
    engines = []
    for engine, group in kept.groupby("engine", sort=False):
        counts = group.groupby("quantity", sort=False)["asymmetric"].agg(["sum", "size"])
        engines.append({"engine": str(engine), "asymmetric": int(counts["sum"].sum()),
                        "compared": int(counts["size"].sum()), "cells": {
                            str(q): [int(n), int(total)] for q, (n, total) in counts.iterrows()}})
    return {"quantities": quantities, "engines": engines,
            "asymmetric": int(kept["asymmetric"].sum()), "compared": len(kept),
            "undefined": {"pairs": int(undefined.sum()),
                          "asymmetric": int((undefined & ~pairs["mirrors"].astype(bool)).sum())}}


def by_engine(pairs: pd.DataFrame) -> list[dict[str, Any]]:
    """Each engine's asymmetric answers (in run order): ``counted`` (the answers
    :func:`summary` counts, as rows), ``undefined`` (those whose truth is undefined) and
    ``cases`` (how many cases the counted ones come from)."""
    odd = pairs[~pairs["mirrors"].astype(bool)]
    out = []
    for engine, group in odd.groupby("engine", sort=False):
        undefined = group["truth_undefined"].astype(bool)
        out.append({"engine": str(engine),
                    "counted": group.loc[~undefined, COLUMNS].to_dict("records"),
                    "undefined": group.loc[undefined, COLUMNS].to_dict("records"),
                    "cases": int(group.loc[~undefined, "case_id"].nunique())})
    return out


def section(frame: pd.DataFrame, order: list[str],
            pairs: pd.DataFrame | None = None) -> dict[str, Any]:
    """The report section's context: :func:`summary` and :func:`by_engine` of the run, their
    engines in ``order`` (the run's); ``pairs``: ``frame``'s :func:`compared`, when already
    made."""
    pairs = compared(frame) if pairs is None else pairs
    rank = {engine: n for n, engine in enumerate(order)}

    def ordered(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
        return sorted(rows, key=lambda row: rank.get(row["engine"], len(rank)))

    counts = summary(pairs)
    return counts | {"engines": ordered(counts["engines"]),
                     "by_engine": ordered(by_engine(pairs))}
