"""Moved and resized scenes against the engine's own origin run: a check that needs no truth.

A ``-moved`` block sweeps ``offset`` (every centre coordinate and the walls moved by it) and
a ``-scaled`` block sweeps ``scale`` (lengths, speeds and gravity multiplied by it; times
unchanged); both hold their origin point (offset 0, scale 1).  Physics does not depend on
where a scene is or, so scaled, on its size, so each engine's values at a point, brought back
to the origin's frame, should be its own values at the origin point:

- moved: ``settle``, ``apex``, ``bounce_time`` and ``energy_drift`` the same, ``positions``
  with the offset subtracted from every coordinate;
- scaled: lengths (``settle``, ``apex``, ``positions``) divided by the scale, times
  (``bounce_time``) and ``energy_drift`` (relative to the energy scale) the same.

Each point's **difference** in a quantity is the largest ``|point - origin|`` over its
elements, each over ``max(|origin|, the quantity's scale)`` (:func:`difference`): relative,
with the scene's own scale as a floor so that a value near 0 (a settle gap, a coordinate at
0) does not turn rounding into a large ratio.  A list of another length (a bounce more or
less) or a value on one side only counts as infinite.  The point's difference is its largest
over the quantities, with the quantity named; the block's **first point beyond**
:data:`TOLERANCE` is the offset or scale nearest the origin on each side (below and above)
whose difference exceeds it.

The exact reference is checked the same way (engine ``exact``, from the ``truth`` column):
its answers differ along a sweep only by the rounding of the moved inputs, so it shows what
the comparison itself allows.  Reads only stored rows and the cases; it never runs an engine.

>>> difference("positions", [[1000.0, 1000.0, 1000.125]], [[0.0, 0.0, 0.125]], "offset",
...            1000.0, 0.125)
0.0
>>> difference("apex", [2.0, 1.0], [1.0], "scale", 2.0, 0.125)
inf
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import pandas as pd

from crosscheck.core.kinds import quantity_named
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.results.jsonlines import each_distinct
from crosscheck.results.run import DECODED

TOLERANCE = 1e-6
"""The relative difference from the origin run beyond which a point counts as changed.

About eight float32 ulps (2**-23, 1.2e-7) of the scene's own scale: the rounding of a float32
engine's arithmetic at the origin's size stays within it, and so does a float64 engine moved
by 1e7 (its coordinates there round by 1e7 * 2**-53, about 1e-9, some 1e-8 of a radius of
0.125), so a point beyond it shows a dependence on position or size, not rounding alone."""

QUANTITIES = ("settle", "apex", "bounce_time", "energy_drift", "positions")
"""The quantities compared, in the order a tie names them."""
WORLD = {"offset": 0.0, "scale": 1.0}
"""The sweep coordinates of a moved or resized block, at their origin point's value."""
EXACT = "exact"
_VALUE, _TRUTH = DECODED["value"], DECODED["truth"]
"""The engine name of the exact reference's row (read from the ``truth`` column)."""
COLUMNS = ("block", "coords", "engine", "axis", "at", "difference", "quantity", "note",
           "beyond", "first_beyond")
"""The columns of :func:`points` (and of ``metamorphic.csv``)."""


def _coords(text: Any) -> dict[str, Any]:
    if isinstance(text, dict):
        return text
    if not isinstance(text, str) or not text:
        return {}
    parsed = json.loads(text)
    return parsed if isinstance(parsed, dict) else {}


def _flat(value: Any) -> list[float]:
    if isinstance(value, list):
        return [x for item in value for x in _flat(item)]
    return [float(value)]


def _origin_frame(quantity: str, value: Any, axis: str, at: float) -> list[float]:
    """A point's value as the origin run would give it: the offset taken from every position
    coordinate, lengths (the quantities whose spec says their value scales with the bodies:
    :attr:`crosscheck.core.kinds.Quantity.length`) divided by the scale."""
    flat = _flat(value)
    if axis == "offset" and quantity == "positions":
        return [x - at for x in flat]
    if axis == "scale" and quantity_named(quantity).length:
        return [x / at for x in flat]
    return flat


def difference(quantity: str, value: Any, origin: Any, axis: str, at: float,
               floor: float) -> float:
    """The largest relative difference of a point's ``value`` (at ``axis`` = ``at``) from the
    origin's, each element over ``max(|origin|, floor)``; infinite when one side has no value
    or the two differ in length.

    >>> difference("settle", [0.5], [0.25], "scale", 2.0, 0.125)
    0.0
    >>> difference("bounce_time", [0.5], [0.5], "scale", 2.0, 10.0)  # times: unscaled
    0.0
    >>> difference("energy_drift", None, 0.0, "offset", 1e3, 0.1)
    inf
    """
    if value is None or origin is None:
        return 0.0 if value is None and origin is None else math.inf
    mine, theirs = _origin_frame(quantity, value, axis, at), _flat(origin)
    if len(mine) != len(theirs):
        return math.inf
    worst = 0.0
    for a, b in zip(mine, theirs, strict=True):
        if math.isnan(a) or math.isnan(b):
            if not (math.isnan(a) and math.isnan(b)):
                return math.inf
            continue
        worst = max(worst, abs(a - b) / max(abs(b), floor) if a != b else 0.0)
    return worst


def floors(case: AnyCase | None) -> dict[str, float]:
    """Each quantity's scale in the origin scene: its mean radius for lengths, its duration for
    times, ``1 / duration`` for ``energy_drift`` (a drift per second of the energy scale: a
    difference of the energy scale over the run); 1 when the case is unknown."""
    if not isinstance(case, SceneCase) or not case.bodies:
        return dict.fromkeys(QUANTITIES, 1.0)
    radius = math.fsum(b.radius for b in case.bodies) / len(case.bodies)
    duration = float(case.duration or 0.0) or 1.0
    return {"settle": radius, "apex": radius, "positions": radius, "bounce_time": duration,
            "energy_drift": 1.0 / duration}


def _note(quantity: str, value: Any, origin: Any) -> str:
    """Why a difference is infinite: a value on one side only, or lists of other lengths."""
    if value is None or origin is None:
        return f"{quantity}: " + ("no value here" if value is None else "no value at the origin")
    mine, theirs = _flat(value), _flat(origin)
    if len(mine) != len(theirs):
        return f"{quantity}: {len(mine)} values here, {len(theirs)} at the origin"
    return ""


def _values(frame: pd.DataFrame) -> dict[tuple[str, str], dict[str, Any]]:
    """Each (case, engine)'s decoded values by quantity, the exact ones as engine ``exact``
    (``frame`` carries them: :func:`crosscheck.results.run.decoded`)."""
    out: dict[tuple[str, str], dict[str, Any]] = {}
    for row in frame.itertuples(index=False):
        case_id, quantity = str(row.case_id), str(row.quantity)
        out.setdefault((case_id, str(row.engine)), {})[quantity] = getattr(row, _VALUE)
        exact = out.setdefault((case_id, EXACT), {})
        if exact.get(quantity) is None:
            exact[quantity] = getattr(row, _TRUTH)
    return out


def _swept(frame: pd.DataFrame) -> pd.DataFrame:
    """The rows of world-swept blocks, with ``axis``, ``at`` and ``rest`` (the other coords as
    JSON text, ``dt`` among them)."""
    if not {"origin", "coords", "quantity"} <= set(frame.columns):
        frame = pd.DataFrame(columns=["case_id", "engine", "quantity", "value", "truth",
                                      _VALUE, _TRUTH, "origin", "coords"])
    rows = frame[frame["quantity"].isin(QUANTITIES) & frame["origin"].notna()]
    if rows.empty:
        return rows.assign(axis=[], at=[], rest=[])
    texts = rows["coords"].tolist()  # a case's coords on every row: each text placed once
    placed = (each_distinct(rows["coords"], _placed).tolist()
              if all(isinstance(t, str) for t in texts) else [_placed(t) for t in texts])
    rows = rows.assign(axis=[p[0] for p in placed], at=[p[1] for p in placed],
                       rest=[p[2] for p in placed])
    return rows[rows["axis"] != ""]


def _placed(text: Any) -> tuple[str, float, str]:
    """The world axis a point's coordinates move it along (``""``: none), where on it, and
    the other coordinates as JSON text.

    >>> _placed('{"dt": 0.01, "offset": 1000.0}')
    ('offset', 1000.0, '{"dt": 0.01}')
    """
    coords = _coords(text)
    axis = next((n for n in WORLD if n in coords), "")
    at = float(coords.get(axis, math.nan)) if axis else math.nan
    return axis, at, json.dumps({k: v for k, v in sorted(coords.items()) if k not in WORLD})


def points(frame: pd.DataFrame, cases: Mapping[str, AnyCase]) -> pd.DataFrame:
    """One row per swept point (origin point left out) x engine (and ``exact``): its largest
    difference from the origin run, the quantity, a note when infinite, whether it is beyond
    :data:`TOLERANCE`, and the first point beyond on its side of the origin (NaN: none)."""
    rows = _swept(frame)
    out: list[dict[str, Any]] = []
    for (block, axis, rest), group in rows.groupby(["origin", "axis", "rest"], sort=False):
        at_of = dict(zip(group["case_id"].astype(str), group["at"], strict=True))
        origin_ids = [c for c, at in at_of.items() if at == WORLD[str(axis)]]
        if not origin_ids:
            continue
        values = _values(group)
        floor = floors(cases.get(origin_ids[0]))
        engines = [EXACT, *dict.fromkeys(group["engine"].astype(str))]
        for engine in engines:
            base = values.get((origin_ids[0], engine))
            if base is None or all(v is None for v in base.values()):
                continue  # the engine does not step scenes (skip): nothing to compare
            for case_id, at in sorted(at_of.items(), key=lambda item: item[1]):
                mine = values.get((case_id, engine))
                if case_id == origin_ids[0] or mine is None:
                    continue
                out.append(_point(str(block), str(rest), engine, str(axis), float(at), mine,
                                  base, floor))
    table = pd.DataFrame(out, columns=list(COLUMNS[:-1]))
    return _with_first(table)


def _point(block: str, rest: str, engine: str, axis: str, at: float, mine: dict[str, Any],
           base: dict[str, Any], floor: dict[str, float]) -> dict[str, Any]:
    shared = [q for q in QUANTITIES if q in mine and q in base
              and (mine[q] is not None or base[q] is not None)]
    diffs = {q: difference(q, mine[q], base[q], axis, at, floor[q]) for q in shared}
    worst = max(shared, key=lambda q: diffs[q], default=None)
    largest = diffs[worst] if worst else math.nan
    if largest == 0:
        worst = None  # every quantity the same: none to name
    note = _note(worst, mine[worst], base[worst]) if worst and math.isinf(largest) else ""
    return {"block": block, "coords": rest, "engine": engine, "axis": axis, "at": at,
            "difference": largest, "quantity": worst or "", "note": note,
            "beyond": bool(largest > TOLERANCE)}


def _with_first(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with ``first_beyond``: per block, coords, engine and side of the origin, the
    point nearest the origin whose difference exceeds the tolerance."""
    nearest: dict[tuple[str, str, str, bool], float] = {}
    for block, rest, engine, axis, at, beyond in zip(
            table["block"], table["coords"], table["engine"], table["axis"], table["at"],
            table["beyond"], strict=True):
        key = (str(block), str(rest), str(engine), float(at) > WORLD[str(axis)])
        if beyond and (key not in nearest or abs(math.log(abs(float(at)) or 1.0))
                       < abs(math.log(abs(nearest[key]) or 1.0))):
            nearest[key] = float(at)
    return table.assign(first_beyond=[
        nearest.get((str(b), str(r), str(e), float(t) > WORLD[str(a)]), math.nan)
        for b, r, e, a, t in zip(table["block"], table["coords"], table["engine"],
                                 table["axis"], table["at"], strict=True)])


def at_text(axis: str, at: float) -> str:
    """An offset or scale as the page writes it (a power of two below 1 as ``1/n``).

    >>> at_text("offset", 1e5), at_text("scale", 0.0009765625), at_text("scale", 32.0)
    ('1e+05', '1/1024', '32')
    """
    if axis == "scale" and 0 < at < 1 and float(round(1 / at)) == 1 / at:
        return f"1/{round(1 / at)}"
    if abs(at) >= 1e4 and float(f"{at:.3g}") == at:
        return f"{at:.3g}"
    return f"{at:g}"


def _cell(group: pd.DataFrame, axis: str) -> dict[str, Any]:
    """One block x engine: where it first leaves the tolerance on each side, and its largest
    difference (with the quantity and the point)."""
    finite = group[group["difference"].notna()]
    if finite.empty:
        return {"first": "no comparison", "beyond": False, "largest": ""}
    worst = finite.sort_values("difference", ascending=False, kind="stable").iloc[0]
    sides = []
    for above in (False, True):
        side = finite[(finite["at"] > WORLD[axis]) == above]
        if side.empty:
            continue
        hit = side["first_beyond"].dropna()
        reach = side["at"].max() if above else side["at"].min()
        sides.append(f"{axis} {at_text(axis, float(hit.iloc[0]))}" if len(hit)
                     else f"none to {at_text(axis, float(reach))}")
    largest = (f"{worst['difference']:.2g}" if math.isfinite(worst["difference"]) else "inf")
    named = worst["note"] or worst["quantity"]  # an infinite one says why
    where = f" at {at_text(axis, worst['at'])} ({named})" if named else ""
    return {"first": "; ".join(sides), "beyond": bool(finite["beyond"].any()),
            "largest": largest + where}


def section(table: pd.DataFrame, order: list[str]) -> dict[str, Any]:
    """The sub-section's context from :func:`points`: per block (and its other coords) a cell
    per engine, the exact reference first; every point for the folded table; the tolerance."""
    if table.empty:
        return {"blocks": [], "engines": [], "points": [], "tolerance": TOLERANCE}
    engines = [e for e in dict.fromkeys([EXACT, *order, *table["engine"]])
               if e in set(table["engine"])]
    blocks = []
    for (block, rest, axis), group in table.groupby(["block", "coords", "axis"], sort=False):
        other = ", ".join(f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}"
                          for k, v in json.loads(str(rest)).items())
        blocks.append({"block": block, "coords": other, "axis": axis,
                       "cells": {str(e): _cell(g, str(axis))
                                 for e, g in group.groupby("engine", sort=False)}})
    shown = table.assign(at_text=[at_text(a, t) for a, t in zip(table["axis"], table["at"],
                                                                  strict=True)])
    return {"blocks": blocks, "engines": engines, "tolerance": TOLERANCE,
            "points": shown.to_dict("records")}
