"""The dynamics section of the report: accuracy against speed for stepped scenes.

Reads only stored rows (kind ``sphere_scene``) and the cases' inputs; it never
runs an engine.  For each scene block (the cases' ``origin``) there is one
chart, in the manner of published cross-engine simulator benchmarks: the
real-time factor (simulated seconds per wall second of stepping) on x, the
error at the end on y, both log scale, one curve per engine variant (and
solver iteration count, when swept) through its time steps.  The table gives
each scene x engine at the time step nearest to 1/240 s: position error (mean
radii), signed kinetic energy change (fraction of the initial energy: negative
is lost) and the real-time factor.
"""

from __future__ import annotations

import html
import json
import math
from collections.abc import Mapping
from typing import Any

import pandas as pd

from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.report.style import COLOURS, SYMBOLS, plot_div, plotly_template

FLOOR = 1e-17
"""Errors of exactly 0 are drawn at this floor on the log axis."""
HEADLINE_DT = 1.0 / 240.0


def scene_points(frame: pd.DataFrame, cases: Mapping[str, AnyCase]) -> pd.DataFrame:
    """One row per scene case x engine: dt, iterations, rtf, errors and the energy change."""
    rows = frame[(frame["kind"] == "sphere_scene") & (frame["status"] != "skip")]
    out = []
    for (case_id, engine), group in rows.groupby(["case_id", "engine"], sort=False):
        case = cases.get(str(case_id))
        by_q = {str(r.quantity): r for r in group.itertuples(index=False)}
        pos = by_q.get("positions")
        if pos is None or not isinstance(case, SceneCase) or str(pos.status) == "skip":
            continue
        out.append(_point(str(case_id), str(engine), case, by_q))
    return pd.DataFrame(out)


def _point(case_id: str, engine: str, case: SceneCase, by_q: dict[str, Any]) -> dict[str, Any]:
    pos, energy = by_q["positions"], by_q.get("energy")
    dt = float(case.dt or HEADLINE_DT)
    steps = max(1, round(float(case.duration) / dt))
    wall = float(pos.query_s)
    iterations = case.iterations
    return {
        "scene": case.origin or case_id, "case_id": case_id, "engine": engine,
        "variant": engine + (f" (iterations {iterations})" if iterations else ""),
        "dt": dt, "iterations": iterations, "steps": steps, "status": str(pos.status),
        "simulated_s": steps * dt, "wall_s": wall,
        "rtf_spread": _rtf_spread(steps * dt, wall, float(pos.query_iqr_s)),
        "rtf": steps * dt / wall if wall > 0 else math.nan,
        "position_error": float(pos.error),
        "velocity_error": _error(by_q.get("velocities")),
        "momentum_error": _error(by_q.get("momentum")),
        "energy_change": _energy_change(energy, case),
    }


def _rtf_spread(simulated: float, wall: float, iqr: float) -> str:
    """The real-time factor over the wall time's interquartile range ('' for one run).

    >>> _rtf_spread(1.0, 0.01, 0.002)
    '90.9-111'
    """
    if not (iqr > 0 and wall > iqr / 2):
        return ""
    low, high = simulated / (wall + iqr / 2), simulated / (wall - iqr / 2)
    return f"{low:.3g}-{high:.3g}"


def _error(row: Any) -> float:
    return float(row.error) if row is not None else math.nan


def _energy_change(row: Any, case: SceneCase) -> float:
    """(engine's final energy - reference's final energy) / initial energy, signed."""
    if row is None or not row.value or not row.truth:
        return math.nan
    try:
        value, truth = float(json.loads(row.value)), float(json.loads(row.truth))
    except (TypeError, ValueError):
        return math.nan
    e0 = math.fsum(0.5 * b.mass * math.fsum(v * v for v in b.velocity) for b in case.bodies)
    return (value - truth) / e0 if e0 > 0 else math.nan


def headline(points: pd.DataFrame) -> list[dict[str, Any]]:
    """Per scene x variant, the run at the time step nearest 1/240 s."""
    if points.empty:
        return []
    rows = []
    for (scene, variant), group in points.groupby(["scene", "variant"], sort=False):
        best = group.iloc[(group["dt"] - HEADLINE_DT).abs().argsort().iloc[0]]
        rows.append({"scene": scene, "variant": variant, "dt": best["dt"],
                     "position_error": best["position_error"],
                     "energy_change": best["energy_change"], "rtf": best["rtf"],
                     "status": best["status"]})
    return rows


def charts(points: pd.DataFrame, order: list[str]) -> list[dict[str, str]]:
    """One chart per scene: error against real-time factor, a curve per engine variant.

    Figures are plain dicts rendered without validation (``go.Figure`` costs ~0.2 s each).
    """
    if points.empty:
        return []
    names = dict.fromkeys([*order, *points["engine"]])
    styles = {n: i for i, n in enumerate(names)}
    out = []
    for scene, group in points.groupby("scene", sort=False):
        data = [_curve(curve.sort_values("dt"), str(variant), styles)
                for variant, curve in group.groupby("variant", sort=False)]
        layout = {
            "template": plotly_template(), "height": 420,
            "title": {"text": html.escape(str(scene))},
            "margin": {"t": 50, "b": 40, "l": 40, "r": 20}, "hoverlabel": {"align": "left"},
            "xaxis": {"type": "log",
                      "title": {"text": "real-time factor (simulated s per wall s)"}},
            "yaxis": {"type": "log",
                      "title": {"text": "position error at the end (mean radii)"}}}
        out.append({"scene": str(scene),
                    "html": plot_div({"data": data, "layout": layout}, f"dyn-{scene}")})
    return out


def _curve(curve: pd.DataFrame, variant: str, styles: dict[str, int]) -> dict[str, Any]:
    style = styles[str(curve["engine"].iloc[0])]
    return {
        "type": "scatter", "mode": "lines+markers", "name": html.escape(variant),
        "x": curve["rtf"].tolist(), "y": curve["position_error"].clip(lower=FLOOR).tolist(),
        "line": {"color": COLOURS[style % len(COLOURS)],
                 "dash": "dot" if curve["iterations"].notna().any() else "solid"},
        "marker": {"symbol": SYMBOLS[style % len(SYMBOLS)], "size": 9},
        "hovertext": [_hover(r) for r in curve.itertuples(index=False)], "hoverinfo": "text"}


def _hover(r: Any) -> str:
    return "<br>".join([
        f"<b>{html.escape(str(r.variant))}</b> dt = {r.dt:.3g} s ({r.steps} steps)",
        f"real-time factor {r.rtf:.3g} (stepping {r.wall_s:.3g} s)",
        f"position error {r.position_error:.3g} mean radii",
        f"velocity error {r.velocity_error:.3g} of the top initial speed",
        f"energy change {r.energy_change:+.3g} of the initial energy",
        f"momentum error {r.momentum_error:.3g}"])


def section(frame: pd.DataFrame, cases: Mapping[str, AnyCase],
            order: list[str]) -> dict[str, Any]:
    """What the report template needs: the headline table and the charts."""
    points = scene_points(frame, cases)
    return {"table": headline(points), "charts": charts(points, order),
            "runs": len(points)}
