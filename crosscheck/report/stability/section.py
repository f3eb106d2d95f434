"""The stability section of the page: the threshold matrix as the page draws it (header rows
of axes, sweep families and walks; a row of cells per engine)."""

import re
from collections.abc import Hashable, Mapping
from typing import Any

import pandas as pd

from crosscheck.core.kinds import spec
from crosscheck.report.frames import records
from crosscheck.report.stability.points import DIRECTIONS
from crosscheck.report.stability.study import with_category

# --- the matrix -------------------------------------------------------------------------------


def short_name(sweep: str) -> str:
    """A sweep's name in a header: without ``sweep-``, its dimension and dashes.

    >>> short_name("sweep-sphere-3d-gap"), short_name("sweep-resp-2d-oblique-mass-ratio")
    ('sphere gap', 'resp oblique mass ratio')
    """
    words = sweep.removeprefix("sweep-").split("-")
    return " ".join(w for w in words if not re.fullmatch(r"[23]d", w)) or sweep


def quantity_label(row: Mapping[Hashable, Any]) -> str:
    """The line of a cell naming the quantity it summarises.

    >>> quantity_label({"kind": "sphere", "quantity": "hit"})
    'hit (no distance)'
    """
    headline = spec(str(row["kind"])).headline
    quantity = str(row["quantity"])
    if row.get("param") == "time_horizon":
        return f"{quantity} (s)"
    return quantity if quantity == headline else f"{quantity} (no {headline})"


def _cell(row: Mapping[Hashable, Any] | None, engine: str, where: str) -> dict[str, Any]:
    """One matrix cell: its big text, its note beside it, its lines, its colour (None:
    grey, no verdict) and its hover text."""
    if row is None or row["state"] == "unjudged":
        why = "no rows (not run)" if row is None else str(row["verdict"])
        return {"main": "\u2013", "note": "", "lines": ["no verdict"], "colour": None,
                "title": f"{engine} on {where}: {why}"}
    lines = ([f"to {row['checked']:.3g}"] if row["state"] == "none"
             else [with_category(str(row["status"]), str(row["category"]))])
    if row["recovers"]:
        lines.append(f"agrees again at {row['recovered_at']:.3g}")
    return {"main": row["cell"], "note": "(easiest)" if row["state"] == "already" else "",
            "lines": [*lines, quantity_label(row)],
            "colour": f"hsl({round(120 * row['reached'])}, 65%, 78%)",
            "title": f"{engine} on {where}: {row['verdict']}"}


def _columns(shown: pd.DataFrame) -> list[dict[str, Any]]:
    """The matrix's columns: by axis, then sweep family (3-D first), then walk."""
    firsts = shown.drop_duplicates("column")
    rank = {name: {v: i for i, v in enumerate(dict.fromkeys(firsts[name]))}
            for name in ("axis", "family")}
    columns = []
    for row in records(firsts):
        param, dim = str(row["param"]), int(row["dim"])
        walks = [d.name for d in DIRECTIONS[param]]
        twin = f", the 2-D twin of {row['family']}" if row["sweep"] != row["family"] else ""
        walk = str(row["direction"]) if len(walks) > 1 else ""  # named when there are two
        columns.append({
            "key": row["column"], "axis": row["axis"], "family": row["family"],
            "label": f"{dim}-D", "walk": walk,
            "where": f"{row['sweep']} ({dim}-D{twin}; {walk + ': ' if walk else ''}"
                     f"{row['harder']})",
            "order": (rank["axis"][row["axis"]], rank["family"][row["family"]], -dim,
                      walks.index(str(row["direction"])))})
    return sorted(columns, key=lambda c: c["order"])


def _spans(columns: list[dict[str, Any]], key: str) -> list[dict[str, Any]]:
    """Runs of neighbouring columns with the same ``key``: its value and how many."""
    spans: list[dict[str, Any]] = []
    for column in columns:
        if spans and spans[-1]["name"] == column[key]:
            spans[-1]["span"] += 1
        else:
            spans.append({"name": column[key], "span": 1})
    return spans


def matrix(table: pd.DataFrame) -> dict[str, Any]:
    """The threshold matrix as the page draws it: header rows (the axes with which way is
    harder, the sweep families, then each column's dimension and walk) and a row of cells per
    engine, one per column (``rows`` is empty without thresholds)."""
    shown = table[table["headline"].astype(bool)]
    columns = _columns(shown)
    axes = _spans(columns, "axis")
    for span in axes:  # one way is harder, or (the scale) both ways from 1
        harder = set(shown.loc[shown["axis"] == span["name"], "harder"])
        span["note"] = str(harder.pop()) if len(harder) == 1 else "harder away from 1"
    families = [span | {"label": short_name(str(span["name"]))}
                for span in _spans(columns, "family")]
    cells = {(r["engine"], r["column"]): r for r in records(shown)}
    rows = [{"engine": engine, "cells": [_cell(cells.get((engine, c["key"])), engine, c["where"])
                                         for c in columns]}
            for engine in dict.fromkeys(str(e) for e in table["engine"])]
    return {"axes": axes, "families": families, "columns": columns, "rows": rows}


