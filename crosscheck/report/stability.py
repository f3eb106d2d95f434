"""The stability study: where along each sweep an engine first stops agreeing with the oracle.

A sweep (``cases/sweeps.toml``) varies one difficulty: the gap or overlap
relative to the size, the body scale, the distance from the origin, the mass
ratio or the approach speed.  For every engine x quantity, each sweep is walked
from its easiest value to its hardest; the *threshold* is the first value where
the answer breaks: status ``disagree``, ``error``, ``crash`` or ``timeout``.
``skip`` and ``undefined`` neither break nor agree: they are stepped over.
The scale sweep is walked twice from 1, towards tiny and towards huge bodies.

The matrix (:func:`matrix`) has a cell per engine x ``column``, one walk of one sweep
(``headline`` marks the row it shows).  A 3-D sweep's 2-D twin (``twin_2d`` in the case
file: the same sweep in a plane) has columns of its own beside its 3-D sweep's (its
``family``), so a 3-D column only holds 3-D rows.  The cell is the kind's headline quantity
(the distance; ``v2`` for responses); an engine that reports no distance along a detection
walk (pymunk gives none for separated bodies) is shown by its ``hit`` walk, and the cell
says so.  An engine with no verdict in a column (skip or undefined everywhere, or no rows)
has a grey "no verdict" cell.  The charts are :mod:`crosscheck.report.stability_charts`.

A fast-body scene point (``step_travel`` at one ``dt``, with its impact ``phase``) is a point
of the ``step_travel`` sweep of that ``dt``; its headline quantity is ``velocities`` (a
pass-through exchanges none), and it breaks only where the impact is missed
(:func:`_missed_impacts_only`): the threshold is the travel at which the engine first lets
the bodies pass through each other, at any phase.

A moved or resized scene (an ``offset`` or ``scale`` sweep of a scene with gravity or walls,
:mod:`crosscheck.cases.world_sweep`, at one ``dt``) is a point of that sweep at its ``dt``,
as a fast-body point is: the ``offset`` column of dynamics is the first offset at which the
engine's scene rows stop agreeing (its headline quantity, ``velocities``, as every scene).

The ``time horizon`` axis (:func:`horizons`) is no sweep: for each long scene (a run of
:data:`LONG_SCENE_S` or more, the gas) at each ``dt``, the cell is the engine's ``divergence``,
the simulated seconds until its trajectory left the case's stated tolerance (``diverge_at``
mean radii) of the exact one; "none" when it never did within the run.

Over 400 lines: the walk, the threshold table and the matrix read the same point records
and are kept together so the cell rule has one home.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.core.model import Status
from crosscheck.core.schema import (
    DEFAULT_DT,
    AabbCase,
    AnyCase,
    ResponseCase,
    SceneCase,
    SphereCase,
)
from crosscheck.report.frames import records
from crosscheck.results.store import read_run
from crosscheck.truth.categories import length_scale, velocity_scale
from crosscheck.truth.scene_rules import PASSED_THROUGH

_GAP = "gap or overlap relative to size"
AXES: dict[str, str] = {"offset": "distance from origin", "scale": "body scale", "gap": _GAP,
                        "overlap": _GAP, "mass_ratio": "mass ratio", "speed": "approach speed",
                        "step_travel": "per-step travel (fast bodies)"}
"""Sweep parameter -> the axis of difficulty it probes."""
HORIZON_AXIS = "time horizon"
"""The axis of :func:`horizons` (no sweep: parameter ``time_horizon``)."""

HEADLINE = {"aabb": "distance", "sphere": "distance", "sphere_response": "v2", "sphere_toi": "toi",
            "sphere_scene": "velocities"}
"""The quantity the threshold table shows for each kind."""
FALLBACK = {"aabb": "hit", "sphere": "hit"}
"""What the table shows for an engine whose headline quantity has no verdict on a walk."""


@dataclass(frozen=True, slots=True)
class Direction:
    """One walk along a sweep: which values it covers and which way difficulty grows."""

    name: str
    harder_up: bool
    """True: larger values are harder."""
    low: float = -math.inf
    high: float = math.inf


_UP, _DOWN = Direction("larger", True), Direction("smaller", False)
DIRECTIONS: dict[str, tuple[Direction, ...]] = {
    "offset": (_UP,), "gap": (_DOWN,), "overlap": (_DOWN,), "mass_ratio": (_UP,), "speed": (_DOWN,),
    "step_travel": (_UP,), "time_horizon": (Direction("longer", True),),
    "scale": (Direction("tiny", False, high=1.0), Direction("huge", True, low=1.0))}
POINT_COLUMNS = ["sweep", "family", "axis", "param", "value", "direction", "kind", "dim", "engine",
                 "quantity", "status", "category", "error", "rel_error", "rel_tolerance",
                 "case_id"]
TABLE_COLUMNS = ["sweep", "family", "axis", "param", "direction", "harder", "kind", "dim", "engine",
                 "quantity", "headline", "column", "threshold", "status", "category", "verdict",
                 "state", "cell", "reached", "recovers", "recovered_at", "checked", "easiest",
                 "hardest", "points"]

# --- points ---------------------------------------------------------------------------------


def _scales(cases: Mapping[str, AnyCase], ids: set[str]) -> dict[str, tuple[float, float]]:
    """Length and velocity scale of each case (NaN for a case the run did not store)."""
    out = dict.fromkeys(ids, (math.nan, math.nan))
    for case_id in ids & cases.keys():
        case = cases[case_id]
        if isinstance(case, AabbCase | SphereCase | ResponseCase):
            out[case_id] = (length_scale(case), velocity_scale(case))
    return out


def relative_error(quantity: str, error: float, scales: tuple[float, float]) -> float:
    """Distance error / length scale, velocity error / velocity scale, normal and hit as is.

    >>> relative_error("distance", 3e-9, (2.0, 0.0)), relative_error("normal", 0.5, (9, 9))
    (1.5e-09, 0.5)
    """
    scale = {"distance": scales[0], "v1": scales[1], "v2": scales[1]}.get(quantity, 1.0)
    return error / scale if scale > 0 else math.nan


SCENE_CONTEXT = ("dt", "iterations", "phase")
"""Coordinates of a fast-body scene point that are not its difficulty: each time step (and
iteration count) is a sweep of its own; the impact phases of one travel are walked together,
so the travel breaks where any phase breaks."""
SCENE_SWEEPS = ("step_travel", "offset", "scale")
"""The difficulties a scene point may sweep beside its :data:`SCENE_CONTEXT`: fast bodies,
and a scene with gravity or walls moved from the origin or resized."""


def _single_parameter(coords: str) -> tuple[str, float, str] | None:
    """``(param, value, context)`` of a one-parameter sweep point's coordinates, else None.

    A fast-body scene point (``step_travel``, with its ``dt`` and ``phase``) is a point of
    the ``step_travel`` sweep at its ``dt`` (the context, which names the sweep).

    >>> _single_parameter('{"gap": 1e-09}'), _single_parameter(""), _single_parameter('{"dt": 0.1}')
    (('gap', 1e-09, ''), None, None)
    >>> _single_parameter('{"dt": 0.0166667, "step_travel": 2.0, "phase": 0.5}')
    ('step_travel', 2.0, 'dt=0.0166667')
    >>> _single_parameter('{"dt": 0.0166667, "offset": 1000.0}')
    ('offset', 1000.0, 'dt=0.0166667')
    """
    if not coords:
        return None
    point = json.loads(coords)
    context = ""
    swept = [p for p in SCENE_SWEEPS if p in point]
    if len(swept) == 1 and set(point) <= {*swept, *SCENE_CONTEXT} and len(point) > 1:
        context = ",".join(f"{k}={point[k]:.6g}" for k in ("dt", "iterations") if k in point)
        point = {swept[0]: point[swept[0]]}
    if len(point) != 1:
        return None
    ((param, value),) = point.items()
    return (param, float(value), context) if param in DIRECTIONS else None


def _missed_impacts_only(rows: pd.DataFrame) -> pd.DataFrame:
    """On the ``step_travel`` axis a point breaks only where the impact is missed: a row
    whose reason names the bodies passing through each other (:data:`PASSED_THROUGH`), or
    a failed one.  Any other disagreement there (the step lag of an impact resolved a step
    late, a speed cap, a restitution threshold) counts as the impact caught: it is
    ``agree`` in the walk, its category cleared."""
    fast = rows["param"] == "step_travel"
    if not fast.any():
        return rows
    missed = rows["reason"].fillna("").str.contains(PASSED_THROUGH, regex=False)
    caught = fast & (rows["status"] == "disagree") & ~missed
    out = rows.copy()
    out.loc[caught, "status"] = "agree"
    out.loc[caught, "category"] = ""
    return out


def _family(case_id: str, origin: str, cases: Mapping[str, AnyCase]) -> str:
    """The sweep column a point is shown in: a 2-D twin's is its 3-D case's sweep.

    >>> _family("g.2d.gap=0.1", "g.2d", {})
    'g.2d'
    """
    case = cases.get(case_id)
    original = cases.get(case.from_3d) if case is not None and case.from_3d else None
    return original.origin if original is not None and original.origin else origin


def sweep_points(frame: pd.DataFrame, cases: Mapping[str, AnyCase]) -> pd.DataFrame:
    """One row per sweep case x engine x quantity (x walk: scale 1 is in both scale walks).

    A sweep point is a case with one sweep coordinate (``coords``) that is not a
    swapped twin; its sweep is the block it came from (``origin``), its ``family``
    the 3-D sweep of a 2-D twin (read from ``cases``), else its sweep.
    """
    parsed: dict[str, tuple[str, float, str] | None] = {}  # each case's coords on every row
    found = [None if twin else parsed[text] if (text := str(coords)) in parsed
             else parsed.setdefault(text, _single_parameter(text))
             for coords, twin in zip(frame["coords"].tolist(), frame["twin_of"].tolist(),
                                     strict=True)]
    keep = [f is not None and kind in HEADLINE
            for f, kind in zip(found, frame["kind"].tolist(), strict=True)]
    if not any(keep):
        return pd.DataFrame(columns=POINT_COLUMNS)
    chosen = [f for f, k in zip(found, keep, strict=True) if k and f is not None]
    rows = frame[keep].drop(columns=["value"]).assign(
        param=[p for p, _, _ in chosen], value=[v for _, v, _ in chosen])
    rows["sweep"] = [f"{origin} ({context})" if context else origin
                     for origin, (_, _, context) in zip(rows["origin"], chosen, strict=True)]
    rows["family"] = [_family(str(c), str(s), cases)
                      for c, s in zip(rows["case_id"], rows["sweep"], strict=True)]
    rows["axis"] = rows["param"].map(AXES)
    scales = _scales(cases, set(rows["case_id"]))
    for column, of in (("rel_error", "error"), ("rel_tolerance", "tolerance")):
        rows[column] = [relative_error(q, float(x), scales[c]) for q, x, c
                        in zip(rows["quantity"], rows[of], rows["case_id"], strict=True)]
    rows = _missed_impacts_only(rows)
    walks = [rows[(rows["param"] == p) & rows["value"].between(d.low, d.high)].assign(
        direction=d.name) for p, ds in DIRECTIONS.items() for d in ds]
    points = pd.concat(walks).sort_index(kind="stable").reset_index(drop=True)
    points["category"] = points["category"].fillna("")
    return points[POINT_COLUMNS]


# --- thresholds -----------------------------------------------------------------------------


def _direction(param: str, name: str) -> Direction:
    return next(d for d in DIRECTIONS[param] if d.name == name)


def with_category(status: str, category: str) -> str:
    return f"{status}, {category}" if category else status


def _holds(checked: float, judged: bool) -> dict[str, Any]:
    """The verdict of a walk that never breaks."""
    if not judged:
        return {"state": "unjudged", "reached": math.nan, "cell": "\u2013",
                "verdict": "no verdict (skip or undefined at every value)"}
    return {"state": "none", "reached": 1.0, "cell": "none",
            "verdict": f"none in range (checked to {checked:.3g})"}


def _breaks(at: float, status: str, category: str, first: bool,
            again: float | None) -> dict[str, Any]:
    """The verdict of a walk that breaks at ``at`` (``first``: at its easiest value)."""
    what = with_category(status, category)
    verdict = (f"already at the easiest value {at:.3g} ({what})" if first
               else f"breaks at {at:.3g} ({what})")
    return {"threshold": at, "status": status, "category": category,
            "state": "already" if first else "breaks", "cell": f"{at:.3g}",
            "recovers": again is not None, "recovered_at": math.nan if again is None else again,
            "verdict": verdict + ("" if again is None else f"; agrees again at {again:.3g}")}


def walk(rows: pd.DataFrame) -> dict[str, Any]:
    """The threshold of one sweep walk x engine x quantity (rows: its points, any order)."""
    return _walk(records(rows))


def _easy_first(points: list[dict[Hashable, Any]], up: bool) -> list[dict[Hashable, Any]]:
    """``points`` by value (descending unless ``up``), ties in their order, NaN last: as
    pandas' stable ``sort_values``."""
    nan = [p for p in points if math.isnan(p["value"])]
    return sorted((p for p in points if not math.isnan(p["value"])),
                  key=lambda p: p["value"], reverse=not up) + nan


def _walk(points: list[dict[Hashable, Any]]) -> dict[str, Any]:
    """:func:`walk` of records, in plain Python (a DataFrame per walk costs ~4x)."""
    first = points[0]
    way = _direction(str(first["param"]), str(first["direction"]))
    ordered = _easy_first(points, way.harder_up)
    values, statuses = [p["value"] for p in ordered], [p["status"] for p in ordered]
    judged = [i for i, s in enumerate(statuses) if s in Status.members("judged")]
    agreed = [i for i in judged if statuses[i] == Status.AGREE]
    broken = next((i for i in judged if statuses[i] in Status.members("breaking")), None)
    out: dict[str, Any] = {
        "threshold": math.nan, "status": "", "category": "", "recovers": False,
        "recovered_at": math.nan, "checked": values[agreed[-1]] if agreed else math.nan,
        "easiest": values[0], "hardest": values[-1], "points": len(judged)}
    if broken is None:
        return out | _holds(out["checked"], bool(judged))
    again = next((values[i] for i in agreed if i > broken), None)
    reached = sum(i < broken for i in judged) / len(judged)
    return out | {"reached": reached} | _breaks(
        values[broken], statuses[broken], ordered[broken]["category"], broken == 0, again)


def thresholds(points: pd.DataFrame) -> pd.DataFrame:
    """One row per sweep walk x engine x quantity: the threshold, its verdict text, recovery.

    ``column`` is the walk's sweep and direction: a 2-D twin's walks are columns of their
    own.  ``headline`` marks the one row per engine x ``column`` the matrix shows
    (:func:`_shown`); a 2-D twin's rows come after its 3-D sweep's.
    """
    rows = []
    walks: dict[tuple[Any, ...], list[dict[Hashable, Any]]] = {}  # groupby's, in plain Python
    for point in records(points):
        key = (point["sweep"], point["direction"], point["engine"], point["quantity"])
        if not any(isinstance(k, float) and math.isnan(k) for k in key):
            walks.setdefault(key, []).append(point)
    for (sweep, direction, engine, quantity), group in walks.items():
        first = group[0]
        way = _direction(str(first["param"]), str(direction))
        rows.append({
            "sweep": sweep, "family": str(first.get("family", sweep)), "axis": first["axis"],
            "param": first["param"], "direction": direction,
            "harder": f"{'larger' if way.harder_up else 'smaller'} is harder",
            "kind": str(first["kind"]), "dim": first["dim"], "engine": engine,
            "quantity": quantity, "headline": False,
            "column": f"{sweep} ({direction})", **_walk(group)})
    table = pd.DataFrame(rows, columns=TABLE_COLUMNS)
    table = table.iloc[(table["sweep"] != table["family"]).argsort(kind="stable")]
    return _shown(table.reset_index(drop=True))


def _shown(table: pd.DataFrame) -> pd.DataFrame:
    """Mark (``headline``) the row the matrix shows for each engine x column: its headline
    quantity's walk, or the fallback quantity's when only that one has a verdict (its
    verdict then says so)."""
    rows_of = records(table)
    cells: dict[tuple[Any, Any], list[int]] = {}  # groupby's, in plain Python
    for i, record in enumerate(rows_of):
        cells.setdefault((record["engine"], record["column"]), []).append(i)
    headline, verdicts = table["headline"].tolist(), table["verdict"].tolist()
    for rows in cells.values():
        walks = [rows_of[i] for i in rows]
        kind = str(walks[0]["kind"])
        chosen = _choice(walks, kind)
        headline[rows[chosen]] = True
        verdicts[rows[chosen]] = cell_verdict(walks[chosen])
    return table.assign(headline=headline, verdict=verdicts)


def _choice(walks: list[dict[Hashable, Any]], kind: str) -> int:
    """The position of the walk shown: the headline quantity's, unless it has no verdict and
    the fallback quantity's has one."""
    def find(quantity: str | None, judged: bool) -> list[int]:
        return [i for i, w in enumerate(walks) if w["quantity"] == quantity
                and (w["state"] != "unjudged" or not judged)]
    headline, fallback = HEADLINE.get(kind), FALLBACK.get(kind)
    return (find(headline, True) or find(fallback, True) or find(headline, False) or [0])[0]


def cell_verdict(shown: dict[Hashable, Any]) -> str:
    """The walk's verdict, naming its quantity when it is not the kind's headline one.

    >>> walk = {"kind": "sphere", "quantity": "hit", "verdict": "none in range"}
    >>> cell_verdict(walk), cell_verdict(walk | {"quantity": "distance"})
    ('hit: none in range (distance: no verdict)', 'none in range')
    """
    headline = HEADLINE.get(str(shown["kind"]))
    if shown["quantity"] == headline:
        return str(shown["verdict"])
    return f"{shown['quantity']}: {shown['verdict']} ({headline}: no verdict)"


# --- the time horizon ---------------------------------------------------------------------------

LONG_SCENE_S = 30.0
"""A scene of at least this many simulated seconds is long: the time horizon axis shows it."""


def _seconds(text: Any) -> float:
    try:
        value = json.loads(str(text))
    except (TypeError, ValueError):
        return math.nan
    return float(value) if isinstance(value, int | float) else math.nan


def _horizon(row: dict[Hashable, Any], duration: float) -> dict[str, Any]:
    """The cell of one divergence row: when the trajectory left the tolerance (``breaks``),
    or that it never did (``none``), or no verdict; ``reached`` the share of the run."""
    status, seconds = str(row["status"]), _seconds(row["value"])
    out: dict[str, Any] = {"threshold": math.nan, "status": "", "category": "",
                           "recovers": False, "recovered_at": math.nan, "checked": math.nan,
                           "easiest": 0.0, "hardest": duration, "points": 1}
    if status in Status.members("failed"):
        return out | _breaks(0.0, status, "", True, None) | {"reached": 0.0, "cell": status}
    if status not in Status.members("judged") or not math.isfinite(seconds):
        return out | _holds(math.nan, False) | {"points": 0}
    if seconds >= duration:
        return out | {"checked": duration} | _holds(duration, True) | {
            "verdict": f"never left the tolerance (to the end, {duration:.3g} s)"}
    return out | {"checked": seconds, "reached": seconds / duration} | _breaks(
        seconds, status, str(row.get("category") or ""), False, None) | {
        "cell": f"{seconds:.3g} s",
        "verdict": f"left the tolerance at {seconds:.3g} s of {duration:.3g} s"}


def horizons(frame: pd.DataFrame, cases: Mapping[str, AnyCase]) -> pd.DataFrame:
    """Threshold-table rows of the ``time horizon`` axis (see the module docstring): one per
    long scene block x ``dt`` x engine, every one a headline row of its own column."""
    rows = frame[(frame["kind"] == "sphere_scene") & (frame["quantity"] == "divergence")]
    out = []
    for row in records(rows):
        case = cases.get(str(row["case_id"]))
        if not isinstance(case, SceneCase) or set(case.coords) - {"dt", "iterations"}:
            continue
        duration = case.step_count * (case.dt or DEFAULT_DT)
        if duration < LONG_SCENE_S:
            continue
        context = ",".join(f"{k}={case.coords[k]:.6g}" for k in ("dt", "iterations")
                           if k in case.coords)
        sweep = f"{case.origin or case.id} ({context})" if context else case.origin or case.id
        out.append({
            "sweep": sweep, "family": sweep, "axis": HORIZON_AXIS,
            "param": "time_horizon", "direction": "longer", "harder": "longer is harder",
            "kind": "sphere_scene", "dim": int(row["dim"]), "engine": row["engine"],
            "quantity": "divergence", "headline": True, "column": f"{sweep} (longer)",
            **_horizon(row, duration)})
    return pd.DataFrame(out, columns=TABLE_COLUMNS)


def with_horizons(table: pd.DataFrame, frame: pd.DataFrame,
                  cases: Mapping[str, AnyCase]) -> pd.DataFrame:
    """The threshold table with the :func:`horizons` rows after it."""
    extra = horizons(frame, cases)
    if extra.empty:
        return table
    if table.empty:
        return extra.reset_index(drop=True)
    return pd.concat([table, extra], ignore_index=True)


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
    headline = HEADLINE.get(str(row["kind"]))
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


# --- files ------------------------------------------------------------------------------------

def analyse(directory: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The sweep points and the threshold table of the run in ``directory``."""
    stored = read_run(directory)
    points = sweep_points(stored.results, stored.cases)
    return points, with_horizons(thresholds(points), stored.results, stored.cases)


def save(points: pd.DataFrame, table: pd.DataFrame, target: Path) -> dict[str, Path]:
    target.mkdir(parents=True, exist_ok=True)
    paths = {name: target / f"{name}.csv" for name in ("stability", "stability_points")}
    table.to_csv(paths["stability"], index=False)
    points.to_csv(paths["stability_points"], index=False)
    return paths


def write(directory: Path, target: Path | None = None) -> dict[str, Path]:
    """Read the run in ``directory``; write stability.csv and stability_points.csv there
    (or to ``target``); return their paths."""
    return save(*analyse(directory), target or directory)
