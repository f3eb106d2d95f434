"""The stability study's walks: the threshold of each engine along each sweep, the time
horizon of the long scenes, and the study's files (``stability.csv``,
``stability_points.csv``)."""

import math
from collections.abc import Hashable, Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.core.kinds import spec
from crosscheck.core.model import Status
from crosscheck.core.schema import (
    DEFAULT_DT,
    AnyCase,
    SceneCase,
)
from crosscheck.report.frames import records
from crosscheck.report.stability.points import (
    DIRECTIONS,
    HORIZON_AXIS,
    TABLE_COLUMNS,
    Direction,
    sweep_points,
)
from crosscheck.results.run import DECODED, Run, read_run

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
    headline, fallback = spec(kind).headline, spec(kind).fallback
    return (find(headline, True) or find(fallback, True) or find(headline, False) or [0])[0]


def cell_verdict(shown: dict[Hashable, Any]) -> str:
    """The walk's verdict, naming its quantity when it is not the kind's headline one.

    >>> walk = {"kind": "sphere", "quantity": "hit", "verdict": "none in range"}
    >>> cell_verdict(walk), cell_verdict(walk | {"quantity": "distance"})
    ('hit: none in range (distance: no verdict)', 'none in range')
    """
    headline = spec(str(shown["kind"])).headline
    if shown["quantity"] == headline:
        return str(shown["verdict"])
    return f"{shown['quantity']}: {shown['verdict']} ({headline}: no verdict)"


# --- the time horizon ---------------------------------------------------------------------------

LONG_SCENE_S = 30.0
"""A scene of at least this many simulated seconds is long: the time horizon axis shows it."""


def _seconds(value: Any) -> float:
    """A divergence row's seconds from its decoded value (NaN: none, or not finite)."""
    return (float(value) if isinstance(value, int | float) and math.isfinite(value)
            else math.nan)


def _horizon(row: dict[Hashable, Any], duration: float) -> dict[str, Any]:
    """The cell of one divergence row: when the trajectory left the tolerance (``breaks``),
    or that it never did (``none``), or no verdict; ``reached`` the share of the run."""
    status, seconds = str(row["status"]), _seconds(row[DECODED["value"]])
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
    long scene block x ``dt`` x engine, every one a headline row of its own column (``frame``
    carries its decoded values: :func:`crosscheck.results.run.decoded`)."""
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


# --- files ------------------------------------------------------------------------------------

def analyse(run: Run | Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The sweep points and the threshold table of a run (a folder: read first)."""
    stored = run if isinstance(run, Run) else read_run(run)
    points = sweep_points(stored.results, stored.cases)
    rows = stored.results.join(stored.decoded)
    return points, with_horizons(thresholds(points), rows, stored.cases)


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

