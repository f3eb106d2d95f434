"""The stability study's charts, folded one per chart family, each fold headed by its headline.

A chart plots a relative error against the difficulty (:func:`figure`): the distance error
over the case's length scale, a velocity error over its velocity scale, the normal error in
radians (see :func:`crosscheck.report.stability.points.relative_error`).  Lower is better; x is the
difficulty, harder to the right (each axis title says so).  Exact answers sit on a labelled
floor, failures and infinite errors on a labelled ceiling, and engines with the same answer at
a point are drawn side by side (:mod:`crosscheck.report.axes`).  There is one chart per axis
x kind x charted quantity (:func:`charts`; the kind's ``charted`` quantities and their axis
labels are its spec's, :mod:`crosscheck.core.kinds`), one panel per sweep (a 2-D twin is a
panel of its own), one line per engine.

The report folds the charts of one axis x kind into one ``<details>`` (:func:`folds`); its
summary is the family's headline (:func:`headline`), computed from the threshold table.
Figures are plain dicts rendered without validation: ``go.Figure`` takes ~0.5 s per chart.
"""

from __future__ import annotations

import html
import math
import re
from collections.abc import Hashable, Iterable
from typing import Any

import pandas as pd
from markupsafe import Markup

from crosscheck.core.kinds import quantity_named, spec
from crosscheck.core.model import Status
from crosscheck.report import axes
from crosscheck.report.frames import records
from crosscheck.report.stability.points import DIRECTIONS
from crosscheck.report.stability.study import with_category
from crosscheck.report.style import COLOURS, SYMBOLS, plot_div, plotly_template

DASHES = ("solid", "dot", "dash", "longdash", "dashdot")
X_LABEL = {"offset": "offset added to every coordinate", "scale": "factor on every length",
           "gap": "gap / touching distance", "overlap": "overlap / touching distance",
           "mass_ratio": "mass ratio m_B / m_A", "speed": "factor on both velocities",
           "step_travel": "per-step travel |vb - va| dt / 2(ra + rb)"}
NAMED = 3
"""A headline names at most this many engines, then says how many more."""

# --- one figure -------------------------------------------------------------------------------


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
    lines = [f"{row['engine']}: {with_category(row['status'], row['category'])}",
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
    label = quantity_named(quantity).relative_label
    title = f"{label}, lower is better" + (f"<br>({', '.join(notes)})" if notes else "")
    return axes.log_axis(title, low, high, floor, ceiling)


def _drawn(on: pd.DataFrame, limits: tuple[float, float | None], spans: tuple[float, float]
           ) -> pd.DataFrame:
    """The points of one panel with where they are drawn: ``y`` at the floor or the ceiling
    when need be, ``x`` pulled apart where engines coincide (``apart`` names the others)."""
    rows = on.reset_index(drop=True)
    ys = [_y(r, *limits) for r in records(rows)]
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
        for point in records(drawn):
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


# --- the charts of a run, folded ----------------------------------------------------------------


def _chart(rows: pd.DataFrame, axis: str, kind: str, quantity: str,
           order: list[str]) -> dict[str, Any]:
    slug = re.sub(r"[^a-z0-9]+", "-", f"{axis}-{kind}-{quantity}")
    text = plot_div(figure(rows, quantity, order), f"stability-{slug}")
    extra = "" if quantity == spec(kind).headline else f" ({quantity})"
    return {"title": f"{axis} \u2014 {kind}{extra}", "axis": axis, "kind": kind,
            "quantity": quantity, "html": Markup(text)}


def charts(points: pd.DataFrame) -> list[dict[str, Any]]:
    """One chart per axis x kind x charted quantity: title, axis, kind, quantity and HTML.

    The HTML is a plotly <div> and script without plotly.js (the page inlines it once,
    see :func:`crosscheck.report.style.plotly_js`), marked safe for Jinja's autoescaping.
    """
    order = [str(e) for e in dict.fromkeys(points["engine"])]
    return [_chart(rows, str(axis), str(kind), quantity, order)
            for (axis, kind), on in points.groupby(["axis", "kind"], sort=False)
            for quantity in spec(str(kind)).charted
            if not (rows := on[on["quantity"] == quantity]).empty]


def _names(engines: Iterable[str]) -> str:
    """Engine names, at most :data:`NAMED` of them, then how many more.

    >>> _names(["a"]), _names(["a", "b", "c", "d", "e"])
    ('a', 'a, b, c and 2 more')
    """
    names = list(dict.fromkeys(engines))
    more = len(names) - NAMED
    return ", ".join(names[:NAMED]) + (f" and {more} more" if more > 0 else "")


def _count(table: pd.DataFrame, axis: str, kind: str, quantity: str
           ) -> tuple[pd.DataFrame, int]:
    """The breaking walks of ``quantity`` on the sweeps of ``axis`` x ``kind`` (easiest break
    first), and how many engines have a verdict there."""
    walks = table[(table["axis"] == axis) & (table["kind"] == kind)
                  & (table["quantity"] == quantity) & (table["state"] != "unjudged")]
    broken = walks[walks["state"].isin(["breaks", "already"])]
    return broken.sort_values("reached", kind="stable"), walks["engine"].nunique()


def headline(table: pd.DataFrame, axis: str, kind: str) -> str:
    """What one chart family shows, from the thresholds: how many engines break on its
    sweeps (in the kind's headline quantity) and which break first, and where; then the
    count for each other charted quantity."""
    quantity = spec(kind).headline
    broken, judged = _count(table, axis, kind, quantity)
    text = f"{axis}, {kind}: "
    if not judged:
        text += f"no verdict on {quantity}"
    elif broken.empty:
        text += f"no engine breaks ({judged} with a verdict on {quantity})"
    else:
        text += f"{broken['engine'].nunique()} of {judged} engines break"
        already = broken[broken["state"] == "already"]["engine"]
        if not already.empty:
            count = already.nunique()
            every = f"all {count}" if count == broken["engine"].nunique() else str(count)
            text += f", {every} at the easiest value ({_names(already)})"
        else:
            first = broken.iloc[0]
            same = broken[(broken["reached"] == first["reached"])
                          & (broken["param"] == first["param"])
                          & (broken["threshold"] == first["threshold"])]
            text += (f", first at {first['param']} {first['threshold']:.3g}"
                     f" ({_names(same['engine'])})")
    for other in spec(kind).charted[1:]:
        broken, judged = _count(table, axis, kind, other)
        if judged:
            text += f"; {other}: {broken['engine'].nunique()} of {judged} break"
    return text


def folds(points: pd.DataFrame, table: pd.DataFrame) -> list[dict[str, Any]]:
    """The charts grouped by axis x kind, each group with its :func:`headline` as summary."""
    grouped: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for chart in charts(points):
        grouped.setdefault((chart["axis"], chart["kind"]), []).append(chart)
    return [{"summary": headline(table, axis, kind), "charts": group}
            for (axis, kind), group in grouped.items()]
