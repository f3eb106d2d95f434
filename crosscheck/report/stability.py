"""The stability study: where along each sweep an engine first stops agreeing with the oracle.

A sweep (``cases/sweeps.toml``) varies one difficulty: the gap or overlap
relative to the size, the body scale, the distance from the origin, the mass
ratio or the approach speed.  For every engine x quantity, each sweep is walked
from its easiest value to its hardest; the *threshold* is the first value where
the answer breaks: status ``disagree``, ``error``, ``crash`` or ``timeout``.
``skip`` and ``undefined`` neither break nor agree: they are stepped over.
The scale sweep is walked twice from 1, towards tiny and towards huge bodies.

The matrix shows one cell per engine x sweep column (``headline``).  A 3-D sweep
and its 2-D twin (``twin_2d`` in the case file: the same sweep in a plane) share
a column, its ``family``: a 2-D engine's cell is its 2-D walk, and an engine with
both walks shows the one that breaks sooner, its verdict naming both.  The cell is
the kind's headline quantity (the distance; ``v2`` for responses); an engine that
reports no distance along a detection walk (pymunk gives none for separated
bodies) is shown by its ``hit`` walk, and the verdict says so.

Charts plot a relative error against the difficulty: the distance error over
the case's length scale, a velocity error over its velocity scale, the normal
error in radians (see :func:`relative_error`).  Lower is better; x is the
difficulty, harder to the right (each axis title says so).  Exact answers sit on
a labelled floor, failures and infinite errors on a labelled ceiling, and engines
with the same answer at a point are drawn side by side (:mod:`crosscheck.report.axes`).

Over 400 lines because the study's three stages (points, thresholds and the matrix
cells, charts) read one set of tables (``AXES``, ``DIRECTIONS``, ``HEADLINE``,
the labels); the charts (from ``# --- charts``) are the part to move out first.
"""

from __future__ import annotations

import html
import json
import math
import re
from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd
from markupsafe import Markup

from crosscheck.core.model import Status
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SphereCase
from crosscheck.report import axes
from crosscheck.report.style import COLOURS, SYMBOLS, plot_div, plotly_template
from crosscheck.results.store import read_run
from crosscheck.truth.categories import length_scale, velocity_scale

_GAP = "gap or overlap relative to size"
AXES: dict[str, str] = {"offset": "distance from origin", "scale": "body scale", "gap": _GAP,
                        "overlap": _GAP, "mass_ratio": "mass ratio", "speed": "approach speed"}
"""Sweep parameter -> the axis of difficulty it probes."""

HEADLINE = {"aabb": "distance", "sphere": "distance", "sphere_response": "v2"}
"""The quantity the threshold table shows for each kind."""
FALLBACK = {"aabb": "hit", "sphere": "hit"}
"""What the table shows for an engine whose headline quantity has no verdict on a walk."""
CHARTED = {"aabb": ("distance", "normal"), "sphere": ("distance", "normal"),
           "sphere_response": ("v2",)}
DASHES = ("solid", "dot", "dash", "longdash", "dashdot")


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
    "scale": (Direction("tiny", False, high=1.0), Direction("huge", True, low=1.0))}
X_LABEL = {"offset": "offset added to every coordinate", "scale": "factor on every length",
           "gap": "gap / touching distance", "overlap": "overlap / touching distance",
           "mass_ratio": "mass ratio m_B / m_A", "speed": "factor on both velocities"}
Y_LABEL = {"distance": "|distance error| / length scale", "normal": "normal error (radians)",
           "v1": "|v1 error| / velocity scale", "v2": "|v2 error| / velocity scale"}
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


def _single_parameter(coords: str) -> tuple[str, float] | None:
    """``(param, value)`` of a one-parameter sweep point's coordinates, else None.

    >>> _single_parameter('{"gap": 1e-09}'), _single_parameter(""), _single_parameter('{"dt": 0.1}')
    (('gap', 1e-09), None, None)
    """
    if not coords:
        return None
    point = json.loads(coords)
    if len(point) != 1:
        return None
    ((param, value),) = point.items()
    return (param, float(value)) if param in DIRECTIONS else None


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
    found = [None if twin else _single_parameter(str(coords))
             for coords, twin in zip(frame["coords"], frame["twin_of"], strict=True)]
    keep = [f is not None and kind in HEADLINE
            for f, kind in zip(found, frame["kind"], strict=True)]
    if not any(keep):
        return pd.DataFrame(columns=POINT_COLUMNS)
    chosen = [f for f, k in zip(found, keep, strict=True) if k and f is not None]
    rows = frame[keep].drop(columns=["value"]).assign(
        param=[p for p, _ in chosen], value=[v for _, v in chosen])
    rows["sweep"] = rows["origin"]
    rows["family"] = [_family(str(c), str(o), cases)
                      for c, o in zip(rows["case_id"], rows["origin"], strict=True)]
    rows["axis"] = rows["param"].map(AXES)
    scales = _scales(cases, set(rows["case_id"]))
    for column, of in (("rel_error", "error"), ("rel_tolerance", "tolerance")):
        rows[column] = [relative_error(q, float(x), scales[c]) for q, x, c
                        in zip(rows["quantity"], rows[of], rows["case_id"], strict=True)]
    walks = [rows[(rows["param"] == p) & rows["value"].between(d.low, d.high)].assign(
        direction=d.name) for p, ds in DIRECTIONS.items() for d in ds]
    points = pd.concat(walks).sort_index(kind="stable").reset_index(drop=True)
    points["category"] = points["category"].fillna("")
    return points[POINT_COLUMNS]


# --- thresholds -----------------------------------------------------------------------------


def _direction(param: str, name: str) -> Direction:
    return next(d for d in DIRECTIONS[param] if d.name == name)


def _with_category(status: str, category: str) -> str:
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
    what = _with_category(status, category)
    verdict = (f"already at the easiest value {at:.3g} ({what})" if first
               else f"breaks at {at:.3g} ({what})")
    return {"threshold": at, "status": status, "category": category,
            "state": "already" if first else "breaks", "cell": f"{at:.3g}",
            "recovers": again is not None, "recovered_at": math.nan if again is None else again,
            "verdict": verdict + ("" if again is None else f"; agrees again at {again:.3g}")}


def walk(rows: pd.DataFrame) -> dict[str, Any]:
    """The threshold of one sweep walk x engine x quantity (rows: its points, any order)."""
    return _walk(rows.to_dict("records"))


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

    ``headline`` marks the one row per engine x ``column`` the matrix shows
    (:func:`_shown`); a 2-D twin's rows come after its 3-D sweep's.
    """
    rows = []
    walks: dict[tuple[Any, ...], list[dict[Hashable, Any]]] = {}  # groupby's, in plain Python
    for point in points.to_dict("records"):
        key = (point["sweep"], point["direction"], point["engine"], point["quantity"])
        if not any(isinstance(k, float) and math.isnan(k) for k in key):
            walks.setdefault(key, []).append(point)
    for (sweep, direction, engine, quantity), group in walks.items():
        first = group[0]
        way = _direction(str(first["param"]), str(direction))
        family = str(first.get("family", sweep))
        rows.append({
            "sweep": sweep, "family": family, "axis": first["axis"], "param": first["param"],
            "direction": direction,
            "harder": f"{'larger' if way.harder_up else 'smaller'} is harder",
            "kind": str(first["kind"]), "dim": first["dim"], "engine": engine,
            "quantity": quantity, "headline": False,
            "column": f"{family} ({direction})", **_walk(group)})
    table = pd.DataFrame(rows, columns=TABLE_COLUMNS)
    table = table.iloc[(table["sweep"] != table["family"]).argsort(kind="stable")]
    return _shown(table.reset_index(drop=True))


def _shown(table: pd.DataFrame) -> pd.DataFrame:
    """Mark (``headline``) the row the matrix shows for each engine x column; name its dimension
    and the quantity in its verdict when the column holds more than one walk or falls back.
    """
    records: list[dict[Hashable, Any]] = table.to_dict("records")
    cells: dict[tuple[Any, Any], list[int]] = {}  # groupby's, in plain Python
    for i, record in enumerate(records):
        cells.setdefault((record["engine"], record["column"]), []).append(i)
    headline, verdicts = table["headline"].tolist(), table["verdict"].tolist()
    for rows in cells.values():
        walks = [records[i] for i in rows]
        kind = str(walks[0]["kind"])
        chosen = _choice(walks, kind)
        headline[rows[chosen]] = True
        verdicts[rows[chosen]] = _cell_verdict(walks[chosen], walks, kind)
    return table.assign(headline=headline, verdict=verdicts)


def _choice(walks: list[dict[Hashable, Any]], kind: str) -> int:
    """The position of the walk shown: the headline quantity's that breaks soonest (the
    fallback quantity's if the headline one has no verdict in any dimension)."""
    def judged(quantity: str | None) -> list[int]:
        return [i for i, w in enumerate(walks)
                if w["quantity"] == quantity and w["state"] != "unjudged"]
    candidates = (judged(HEADLINE.get(kind)) or judged(FALLBACK.get(kind))
                  or [i for i, w in enumerate(walks) if w["quantity"] == HEADLINE.get(kind)]
                  or [0])
    reached = [float(walks[i]["reached"]) for i in candidates]
    return candidates[min(range(len(candidates)),
                          key=lambda j: math.inf if math.isnan(reached[j]) else reached[j])]


def _cell_verdict(shown: dict[Hashable, Any], walks: list[dict[Hashable, Any]], kind: str) -> str:
    """The shown walk's verdict, with its quantity if it is not the headline one, and its
    dimension if its column has walks in both (then also the other's verdict, if it has one).

    >>> walk = {"quantity": "hit", "dim": 2, "verdict": "none in range", "state": "none"}
    >>> _cell_verdict(walk, [walk, walk | {"dim": 3, "verdict": "breaks at 1"}], "sphere")
    'in 2-D: hit: none in range (distance: no verdict); in 3-D: breaks at 1'
    """
    verdict = str(shown["verdict"])
    headline = HEADLINE.get(kind)
    if shown["quantity"] != headline:
        verdict = f"{shown['quantity']}: {verdict} ({headline}: no verdict)"
    if len({w["dim"] for w in walks}) < 2:
        return verdict
    others = [w for w in walks if w["quantity"] == shown["quantity"]
              and w["dim"] != shown["dim"] and w["state"] != "unjudged"]
    return "; ".join([f"in {shown['dim']}-D: {verdict}",
                      *(f"in {w['dim']}-D: {w['verdict']}" for w in others)])


# --- charts ---------------------------------------------------------------------------------
# Figures are plain dicts rendered without validation: go.Figure takes ~0.5 s per chart.


def _limits(rows: pd.DataFrame) -> tuple[float, float | None, float | None]:
    """Where 0 is drawn, whether it shows (None: no exact answer drawn), and where failures
    and inf are drawn (None: there are none)."""
    drawn = rows[~rows["status"].isin(Status.members("neutral"))]
    values = drawn["rel_error"].to_numpy(dtype=float)
    failed = bool(drawn["status"].isin(Status.members("failed")).any()
                  or (values == math.inf).any())
    floor, ceiling = axes.limits(values[values < math.inf], failed)
    return floor, axes.shown_floor(values, floor), ceiling


def _y(row: dict[Hashable, Any], floor: float, ceiling: float | None) -> float:
    if row["status"] in Status.members("failed") or row["rel_error"] == math.inf:
        return ceiling or math.nan
    return floor if row["rel_error"] == 0 else float(row["rel_error"])


def _hover(row: dict[Hashable, Any]) -> str:
    lines = [f"{row['engine']}: {_with_category(row['status'], row['category'])}",
             row["case_id"], f"{row['param']} = {row['value']:.6g}", f"error {row['error']:.3g}",
             f"relative error {row['rel_error']:.3g}"]
    if row.get("apart"):
        lines.append(f"drawn beside {row['apart']} (same place)")
    return "<br>".join(html.escape(line) for line in lines)


def _trace(rows: list[dict[Hashable, Any]], index: int, panel: int,
           first: bool) -> dict[str, Any]:
    """One engine's line on the sweep panel ``panel`` (1, 2, ...), at the drawn ``x``, ``y``
    (``rows``: its points as records; values are unique per line, so the order is pandas')."""
    engine = html.escape(str(rows[0]["engine"]))
    shown = sorted(rows, key=lambda r: (math.isnan(r["value"]), r["value"]))
    colour = COLOURS[index % len(COLOURS)]
    return {
        "type": "scatter", "xaxis": f"x{panel}", "yaxis": f"y{panel}", "name": engine,
        "x": [r["x"] for r in shown], "y": [r["y"] for r in shown],
        "mode": "lines+markers", "legendgroup": engine, "showlegend": first,
        "hoverinfo": "text", "hovertext": [_hover(r) for r in shown],
        "line": {"color": colour, "width": 1.5, "dash": DASHES[index % len(DASHES)]},
        "marker": {"color": colour, "size": 8, "symbol": [
            "x" if r["status"] in Status.members("breaking") else SYMBOLS[index % len(SYMBOLS)]
            for r in shown]}}


def _y_axis(quantity: str, values: list[float], floor: float | None,
            ceiling: float | None) -> dict[str, Any]:
    low, high = axes.error_range(values, floor, ceiling)
    notes = ([f"0 drawn at {floor:.0e}"] if floor else []) + (
        [f"failures at {ceiling:.0e}"] if ceiling else [])
    title = f"{Y_LABEL[quantity]}, lower is better" + (f"<br>({', '.join(notes)})" if notes
                                                        else "")
    return axes.log_axis(title, low, high, floor, ceiling)


def _drawn(on: pd.DataFrame, limits: tuple[float, float | None], spans: tuple[float, float]
           ) -> pd.DataFrame:
    """The points of one panel with where they are drawn: ``y`` at the floor or the ceiling
    when need be, ``x`` pulled apart where engines coincide (``apart`` names the others)."""
    rows = on.reset_index(drop=True)
    ys = [_y(r, *limits) for r in rows.to_dict("records")]
    groups = axes.coincident(list(zip(rows["value"], ys, strict=True)), spans)
    return rows.assign(x=axes.spread(rows["value"].tolist(), groups, spans[0]), y=ys,
                       apart=axes.beside(groups, rows["engine"].astype(str).tolist()))


def _panel(n: int, count: int, param: str, sweep: str,
           span: tuple[float, float]) -> dict[str, Any]:
    """Axes (in a grid of at most 3 columns), title, tolerance line and label of panel ``n``;
    ``span``: log10 of the ends of its x axis."""
    cols = min(3, count)
    rows = math.ceil(count / cols)
    width, height = (1 - 0.05 * (cols - 1)) / cols, (1 - 0.15 * (rows - 1)) / rows
    row, col = divmod(n - 1, cols)
    x0, y1 = col * (width + 0.05), 1 - row * (height + 0.15)
    harder = "away from 1" if param == "scale" else "to the right"
    x_axis = axes.log_axis(f"{X_LABEL[param]} (harder {harder})", *span)
    if not any(d.harder_up for d in DIRECTIONS[param]):
        x_axis["range"] = x_axis["range"][::-1]
    return {
        "x": x_axis | {"domain": [x0, x0 + width], "anchor": f"y{n}"},
        "y": {"domain": [y1 - height, y1], "anchor": f"x{n}", "showticklabels": col == 0},
        "title": {"text": html.escape(sweep), "x": x0 + width / 2, "y": y1, "xref": "paper",
                  "yref": "paper", "xanchor": "center", "yanchor": "bottom", "showarrow": False},
        "line": {"type": "line", "xref": f"x{n} domain", "x0": 0, "x1": 1, "yref": f"y{n}",
                 "line": {"dash": "dot", "color": "#888"}},
        "label": {"text": "tolerance", "xref": f"x{n} domain", "x": 0, "yref": f"y{n}",
                  "xanchor": "left", "yanchor": "bottom", "showarrow": False,
                  "font": axes.LABEL_FONT}}


def figure(rows: pd.DataFrame, quantity: str, order: list[str]) -> dict[str, Any]:
    """Error against difficulty for one axis x kind: a panel per sweep, a line per engine."""
    rows = rows[rows["quantity"] == quantity].drop_duplicates(["sweep", "engine", "value"])
    sweeps = list(dict.fromkeys(rows["sweep"]))
    floor, zero_at, ceiling = _limits(rows)
    tolerance = float(rows["rel_tolerance"].replace(0.0, math.nan).median())
    y_axis = _y_axis(quantity, [*rows["rel_error"], tolerance], zero_at, ceiling)
    layout: dict[str, Any] = {
        "template": plotly_template(), "height": 260 + 200 * math.ceil(len(sweeps) / 3),
        "hoverlabel": {"align": "left"}, "margin": {"t": 50, "b": 40, "l": 40, "r": 20},
        "legend": {"title": {"text": "engine (x: breaks)"}}, "annotations": [], "shapes": []}
    data: list[dict[str, Any]] = []
    for n, sweep in enumerate(sweeps, start=1):
        on = rows[rows["sweep"] == sweep]
        span = axes.data_range(on["value"], pad=0.1)
        panel = _panel(n, len(sweeps), str(on["param"].iloc[0]), str(sweep), span)
        shared = {"matches": "y", "title": {"text": ""}} if n > 1 else {}
        layout |= {f"xaxis{n}": panel["x"], f"yaxis{n}": panel["y"] | y_axis | shared}
        _marks(layout, panel, n, tolerance, (zero_at, ceiling))
        drawn = _drawn(on[~on["status"].isin(Status.members("neutral"))], (floor, ceiling),
                       (span[1] - span[0], y_axis["range"][1] - y_axis["range"][0]))
        shown = {trace["name"] for trace in data}
        lines: dict[str, list[dict[Hashable, Any]]] = {}
        for point in drawn.to_dict("records"):
            lines.setdefault(str(point["engine"]), []).append(point)
        data += [_trace(line, order.index(engine), n, html.escape(engine) not in shown)
                 for engine, line in lines.items()]
    return {"data": data, "layout": layout}


def _marks(layout: dict[str, Any], panel: dict[str, Any], n: int, tolerance: float,
           limits: tuple[float | None, float | None]) -> None:
    """Panel ``n``'s title, its tolerance line and its floor and ceiling lines, labelled."""
    layout["annotations"].append(panel["title"])
    if tolerance > 0:  # a shape takes the value on a log axis, an annotation its log10
        layout["shapes"].append(panel["line"] | {"y0": tolerance, "y1": tolerance})
        layout["annotations"].append(panel["label"] | {"y": math.log10(tolerance)})
    shapes, notes = axes.limit_marks(*limits, "failed or infinite error", f"x{n}", f"y{n}")
    layout["shapes"] += shapes
    layout["annotations"] += notes


def _chart(rows: pd.DataFrame, axis: str, kind: str, quantity: str,
           order: list[str]) -> dict[str, Any]:
    slug = re.sub(r"[^a-z0-9]+", "-", f"{axis}-{kind}-{quantity}")
    text = plot_div(figure(rows, quantity, order), f"stability-{slug}")
    extra = "" if quantity == HEADLINE[kind] else f" ({quantity})"
    return {"title": f"{axis} \u2014 {kind}{extra}", "quantity": quantity, "html": Markup(text)}


def charts(points: pd.DataFrame) -> list[dict[str, Any]]:
    """One chart per axis x kind (plus the normal for detection kinds): title and HTML.

    The HTML is a plotly <div> and script without plotly.js (the page inlines it once,
    see :func:`crosscheck.report.style.plotly_js`), marked safe for Jinja's autoescaping.
    """
    order = [str(e) for e in dict.fromkeys(points["engine"])]
    return [_chart(rows, str(axis), str(kind), quantity, order)
            for (axis, kind), on in points.groupby(["axis", "kind"], sort=False)
            for quantity in CHARTED[str(kind)]
            if not (rows := on[on["quantity"] == quantity]).empty]


# --- files ------------------------------------------------------------------------------------

def analyse(directory: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The sweep points and the threshold table of the run in ``directory``."""
    stored = read_run(directory)
    points = sweep_points(stored.results, stored.cases)
    return points, thresholds(points)


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
