"""The dynamics section of the report: accuracy against cost for stepped scenes.

Reads only stored rows (kind ``sphere_scene``) and the cases' inputs; it never
runs an engine.  For each scene block (the cases' ``origin``) there is one
chart, drawn the way the speed charts are (lower left is better): x is the
wall time of stepping per simulated second (``1 /`` the real-time factor of
published cross-engine simulator benchmarks), y the position error at the end,
both log scale, one curve per engine variant (and solver iteration count, when
swept) through its time steps, each point labelled with its ``dt``.  A point
whose exact run has an impact exactly on a step boundary is flagged (marker,
hover and caption; :func:`crosscheck.truth.scenes.aligned`): an engine that
resolves contacts a step late meets such an impact on time, so its error there
is an artefact of the alignment, not accuracy.  Those impact times are what the run
stored of the exact run (``scene_facts.jsonl``, :mod:`crosscheck.results.scene_facts`);
for a run before format 7 they are recomputed from the stored case.

The section is folded per scene: in view, a table of each scene x engine's most
accurate run (its position error in mean radii, time step and real-time factor;
:func:`headline`); folded under each scene's summary line, the table of every
run (position and velocity error, signed kinetic energy change as a fraction of
the initial energy: negative is lost, real-time factor, status) and its chart.
"""

from __future__ import annotations

import html
import math
from collections.abc import Hashable, Mapping
from types import SimpleNamespace
from typing import Any

import pandas as pd

from crosscheck.core.model import Status
from crosscheck.core.schema import DEFAULT_DT, AnyCase, SceneCase
from crosscheck.report import axes
from crosscheck.report.frames import records
from crosscheck.report.style import COLOURS, SYMBOLS, plot_div, plotly_template
from crosscheck.report.text import seconds
from crosscheck.results import scene_facts
from crosscheck.results.run import DECODED
from crosscheck.results.scene_facts import SceneFacts

_VALUE, _TRUTH = DECODED["value"], DECODED["truth"]
ALIGNED_SYMBOL = "circle-x"
"""The marker of a point whose exact run has an impact on a step boundary."""
ALIGNED_NOTE = ("circled x: an impact of the exact run falls on a step boundary (k dt); a "
                "step-late engine meets it on time, so its error there is no measure of accuracy")


def scene_points(frame: pd.DataFrame, cases: Mapping[str, AnyCase],
                 facts: Mapping[str, SceneFacts] | None = None) -> pd.DataFrame:
    """One row per scene case x engine: dt, iterations, rtf, errors and the energy change
    (``frame`` carries its decoded values: :func:`crosscheck.results.run.decoded`).

    ``facts``: what the run stored of each scene case's exact run (``scene_facts.jsonl``,
    :func:`crosscheck.results.scene_facts.read_facts`); a case without them (a run before
    format 7) has them recomputed, once per case."""
    rows = frame[(frame["kind"] == "sphere_scene") & (frame["status"] != Status.SKIP)]
    known = dict(facts or {})
    # the rows of each pair in one pass, in the order first met (a groupby and an itertuples
    # per pair cost more than the rest of the section)
    pairs: dict[tuple[str, str], dict[str, Any]] = {}
    for r in rows.itertuples(index=False):
        pairs.setdefault((str(r.case_id), str(r.engine)), {})[str(r.quantity)] = r
    out = []
    for (case_id, engine), by_q in pairs.items():
        case = cases.get(case_id)
        pos = by_q.get("positions")
        if pos is None or not isinstance(case, SceneCase) or pos.status == Status.SKIP:
            continue
        if case.id not in known:
            known[case.id] = scene_facts.recomputed(case)
        out.append(_point(case_id, engine, case, by_q, known[case.id]))
    return pd.DataFrame(out)


def _point(case_id: str, engine: str, case: SceneCase, by_q: dict[str, Any],
           facts: SceneFacts) -> dict[str, Any]:
    pos, energy = by_q["positions"], by_q.get("energy")
    dt = float(case.dt or DEFAULT_DT)
    steps = case.step_count
    wall = float(pos.query_s)
    iterations = case.iterations
    return {
        "scene": case.origin or case_id, "case_id": case_id, "engine": engine,
        "variant": engine + (f" (iterations {iterations})" if iterations else ""),
        "dt": dt, "iterations": iterations, "steps": steps, "status": str(pos.status),
        "simulated_s": steps * dt, "wall_s": wall,
        "rtf_spread": _rtf_spread(steps * dt, wall, float(pos.query_iqr_s)),
        "rtf": steps * dt / wall if wall > 0 else math.nan,
        "cost": wall / (steps * dt) if wall > 0 else math.nan,
        "aligned": facts.aligned,
        "position_error": float(pos.error),
        "velocity_error": _error(by_q.get("velocities")),
        "momentum_error": _error(by_q.get("momentum")),
        "energy_change": _energy_change(energy, case),
    }


def _rtf_spread(simulated: float, wall: float, iqr: float) -> str:
    """The real-time factor over the wall time's interquartile range ('' for one run).

    >>> _rtf_spread(1.0, 0.01, 0.002), _rtf_spread(1.0, 0.0005, 0.0002)
    ('90.9-111', '1,667-2,500')
    """
    if not (iqr > 0 and wall > iqr / 2):
        return ""
    low, high = simulated / (wall + iqr / 2), simulated / (wall - iqr / 2)
    return f"{factor(low)}-{factor(high)}"


def _error(row: Any) -> float:
    return float(row.error) if row is not None else math.nan


def _energy_change(row: Any, case: SceneCase) -> float:
    """(engine's final energy - reference's final energy) / initial energy, signed."""
    if row is None or not row.value or not row.truth:
        return math.nan
    try:
        value, truth = float(getattr(row, _VALUE)), float(getattr(row, _TRUTH))
    except (TypeError, ValueError):
        return math.nan
    e0 = math.fsum(0.5 * b.mass * math.fsum(v * v for v in b.velocity) for b in case.bodies)
    return (value - truth) / e0 if e0 > 0 else math.nan


def _nan_last(value: float | None) -> tuple[bool, float]:
    """A sort key that puts NaN (or None) after every number, as pandas' ``sort_values`` does.

    >>> sorted([2.0, None, math.nan, 1.0], key=_nan_last)[:2]
    [1.0, 2.0]
    """
    return (True, 0.0) if value is None or math.isnan(value) else (False, float(value))


def _most_accurate(runs: list[dict[Hashable, Any]]) -> dict[Hashable, Any]:
    """The run with the smallest finite position error (ties: the fastest; a NaN real-time
    factor last); the first run when none has one."""
    finite = [r for r in runs if math.isfinite(float(r["position_error"]))]
    if not finite:
        return runs[0]
    return min(finite, key=lambda r: (float(r["position_error"]),
                                      *_nan_last(-r["rtf"])))


def _run(row: Mapping[Hashable, Any]) -> dict[str, Any]:
    """One run as the template shows it (``step`` and ``factor``: its time step and real-time
    factor as text)."""
    keys = ("case_id", "engine", "variant", "dt", "steps", "position_error",
            "velocity_error", "energy_change", "rtf", "rtf_spread", "status")
    iterations = row["iterations"]
    return {key: row[key] for key in keys} | {
        "iterations": int(iterations) if pd.notna(iterations) else None,
        "step": step(float(row["dt"])), "factor": factor(float(row["rtf"])),
        "aligned": bool(row["aligned"])}


def headline(group: pd.DataFrame) -> dict[str, Any]:
    """One scene's runs: per engine its most accurate run (``best``, in run order), with
    ``top`` set on the engines whose error is the scene's smallest as the page shows it (three
    digits: an exact tie is common, and a speed difference among tied runs is mostly noise);
    ``tied`` (those engines), ``top`` (the fastest of them) and every run (``runs``, by
    engine, solver iterations and time step)."""
    by_engine: dict[str, list[dict[Hashable, Any]]] = {}  # groupby's, in plain Python
    for row in records(group):
        by_engine.setdefault(str(row["engine"]), []).append(row)
    best = {engine: _run(_most_accurate(runs)) for engine, runs in by_engine.items()}
    errors = [r["position_error"] for r in best.values() if math.isfinite(r["position_error"])]
    smallest = f"{min(errors):.3g}" if errors else None
    for run in best.values():
        run["top"] = f"{run['position_error']:.3g}" == smallest
    tied = [engine for engine, run in best.items() if run["top"]]
    fastest = sorted(tied, key=lambda e: -best[e]["rtf"] if math.isfinite(best[e]["rtf"])
                     else math.inf)
    ordered = [row for runs in by_engine.values() for row in sorted(
        runs, key=lambda r: (*_nan_last(r["iterations"]), *_nan_last(r["dt"])))]
    return {"best": best, "tied": tied, "top": best[fastest[0]] if fastest else None,
            "runs": [_run(r) for r in ordered],
            "aligned": sum(bool(r["aligned"]) for r in ordered)}


def factor(rtf: float) -> str:
    """A real-time factor as the page writes it: three digits, whole numbers from 100 up.

    >>> factor(0.01234), factor(12.345), factor(123456.7), factor(math.nan)
    ('0.0123', '12.3', '123,457', 'n/a')
    """
    if not math.isfinite(rtf):
        return "n/a"
    return f"{rtf:,.0f}" if rtf >= 100 else f"{rtf:.3g}"


def summary_line(scene: dict[str, Any]) -> str:
    """A scene's headline in words, for its folded block (``scene``: a :func:`headline`).

    >>> top = {"variant": "e", "dt": 0.01, "position_error": 0.0042, "rtf": 1234.5}
    >>> summary_line({"runs": [top], "best": {"e": top}, "tied": ["e"], "top": top,
    ...               "aligned": 0})
    'most accurate: e at dt 10 ms, error 0.0042 mean radii, real-time factor 1,234 (1 run)'
    >>> summary_line({"runs": [top, top], "best": {"e": top, "f": top}, "tied": ["e", "f"],
    ...               "top": top, "aligned": 1})[:69]
    'as accurate: e and f, error 0.0042 mean radii; the fastest of them, e'
    """
    top, tied, runs = scene["top"], scene["tied"], len(scene["runs"])
    if top is None:
        words = "no run has a finite position error"
    else:
        run = (f"{top['variant']} at dt {step(float(top['dt']))}", f"error "
               f"{top['position_error']:.3g} mean radii", f"real-time factor "
               f"{factor(float(top['rtf']))}")
        words = (f"most accurate: {run[0]}, {run[1]}, {run[2]}" if len(tied) == 1 else
                 f"as accurate: {', '.join(tied[:-1])} and {tied[-1]}, {run[1]}; the fastest "
                 f"of them, {run[0]}, {run[2]}")
    engines = len(scene["best"])
    words += f" ({runs} run{'s' * (runs != 1)}" + (f" of {engines} engines" if engines > 1 else "")
    if scene["aligned"]:
        words += f"; {scene['aligned']} with an impact on a step boundary"
    return words + ")"


def step(dt: float) -> str:
    """A time step as the page writes it: with an SI prefix, or ``1/n s`` for a step of a
    whole rate that three digits would round.

    >>> step(1 / 240), step(1e-3), step(0.05), step(1e-5)
    ('1/240 s', '1 ms', '50 ms', '10 µs')
    """
    rate = round(1.0 / dt)
    if float(f"{dt:.3g}") != dt and abs(rate * dt - 1.0) < 1e-9:
        return f"1/{rate} s"
    return seconds(dt)


def dt_label(dt: float) -> str:
    """A time step as its chart label.

    >>> dt_label(1 / 240), dt_label(1e-3)
    ('dt 1/240 s', 'dt 1 ms')
    """
    return f"dt {step(dt)}"


def charts(points: pd.DataFrame, order: list[str]) -> list[dict[str, Any]]:
    """One chart per scene: position error against cost, a curve per engine variant.

    Figures are plain dicts rendered without validation (``go.Figure`` costs ~0.2 s each).
    """
    if points.empty:
        return []
    names = dict.fromkeys([*order, *points["engine"]])
    styles = {n: i for i, n in enumerate(names)}
    return [{"scene": str(scene), "aligned": int(group["aligned"].map(bool).sum()),
             "html": plot_div(figure(group, str(scene), styles), f"dyn-{scene}")}
            for scene, group in points.groupby("scene", sort=False)]


def _at(error: float, floor: float, ceiling: float | None) -> float:
    """Where an error is drawn: 0 at the floor, infinite or none at the ceiling."""
    if error == 0:
        return floor
    return error if math.isfinite(error) else ceiling or math.nan


def _y(rows: pd.DataFrame) -> tuple[list[float], float | None, float | None]:
    """Where each position error is drawn, and the floor and ceiling when something sits there
    (0 at the floor; infinite or no error at the ceiling)."""
    shown = rows["cost"].gt(0) & rows["cost"].lt(math.inf)
    errors = rows.loc[shown, "position_error"].astype(float)
    failed = rows.loc[shown, "status"].isin(Status.members("failed"))
    floor, ceiling = axes.limits(errors, bool(failed.any()))
    ys = [_at(e, floor, ceiling) if on else math.nan
          for e, on in zip(rows["position_error"].astype(float), shown, strict=True)]
    return ys, axes.shown_floor(errors, floor), ceiling


def _sides(rows: pd.DataFrame, ys: list[float], floor: float | None,
           ceiling: float | None) -> list[str]:
    """Where each point's label goes: above for every other variant, below for the others
    (neighbouring curves label both sides), always inside the floor and the ceiling."""
    variants = {v: n for n, v in enumerate(dict.fromkeys(rows["variant"]))}
    return ["bottom center" if y == ceiling or (variants[v] % 2 and y != floor)
            else "top center" for v, y in zip(rows["variant"], ys, strict=True)]


def drawn(group: pd.DataFrame) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The points of one scene with where they are drawn (``x``, ``y``: floor, ceiling and
    coincident points pulled apart), their dt label (``label``: once for points drawn side
    by side) and ``apart`` (the variants drawn beside them); and the two axes."""
    rows = group.reset_index(drop=True)
    ys, floor, ceiling = _y(rows)
    low, high = axes.data_range(rows["cost"])
    bottom, top = axes.error_range(ys, floor, ceiling)
    groups = axes.coincident(list(zip(rows["cost"], ys, strict=True)), (high - low, top - bottom))
    labels = [dt_label(dt) + (" (on a step)" if on else "")
              for dt, on in zip(rows["dt"], rows["aligned"], strict=True)]
    rows = rows.assign(x=axes.spread(rows["cost"].tolist(), groups, high - low), y=ys,
                       apart=axes.beside(groups, rows["variant"].astype(str).tolist()),
                       label=axes.once(groups, labels), side=_sides(rows, ys, floor, ceiling))
    return rows, {
        "xaxis": axes.log_axis("wall time per simulated second (s; 1 / real-time factor)",
                               low, high),
        "yaxis": axes.log_axis("position error at the end (mean radii)", bottom, top, floor,
                               ceiling),
        "marks": axes.limit_marks(floor, ceiling, "no value or infinite error")}


def figure(group: pd.DataFrame, scene: str, styles: dict[str, int]) -> dict[str, Any]:
    """The chart of one scene (a plain plotly figure): a curve per variant through its time
    steps, each point labelled with its dt; the floor, the ceiling and aligned points
    labelled."""
    rows, parts = drawn(group)
    shapes, notes = parts["marks"]
    if rows["aligned"].map(bool).any():  # a caption line under the title
        notes = [*notes, {"text": ALIGNED_NOTE, "xref": "paper", "yref": "paper", "x": 0,
                          "y": 1, "yshift": 6, "xanchor": "left", "yanchor": "bottom",
                          "showarrow": False, "font": axes.LABEL_FONT | {"color": "#b22222"}}]
    layout = {
        "template": plotly_template(), "height": 460, "hoverlabel": {"align": "left"},
        "title": {"text": f"{html.escape(scene)} (lower left is better)"},
        "margin": {"t": 80, "b": 40, "l": 40, "r": 20}, "xaxis": parts["xaxis"],
        "yaxis": parts["yaxis"], "shapes": shapes, "annotations": notes}
    data = [_curve(curve.sort_values("dt"), str(variant), styles)
            for variant, curve in rows.groupby("variant", sort=False)]
    return {"data": data, "layout": layout}


def _curve(curve: pd.DataFrame, variant: str, styles: dict[str, int]) -> dict[str, Any]:
    style = styles[str(curve["engine"].iloc[0])]
    colour, symbol = COLOURS[style % len(COLOURS)], SYMBOLS[style % len(SYMBOLS)]
    flagged = curve["aligned"].map(bool).tolist()
    return {
        "type": "scatter", "mode": "lines+markers+text", "name": html.escape(variant),
        "x": curve["x"].tolist(), "y": curve["y"].tolist(),
        "text": curve["label"].tolist(), "textposition": curve["side"].tolist(),
        "textfont": {"size": 9, "color": colour}, "cliponaxis": False,
        "line": {"color": colour,
                 "dash": "dot" if curve["iterations"].notna().any() else "solid"},
        "marker": {"symbol": [ALIGNED_SYMBOL if f else symbol for f in flagged],
                   "size": [13 if f else 9 for f in flagged], "color": colour,
                   "line": {"color": ["#b22222" if f else colour for f in flagged],
                            "width": [2 if f else 0 for f in flagged]}},
        "hovertext": [_hover(SimpleNamespace(**{str(k): v for k, v in r.items()}))
                      for r in records(curve)], "hoverinfo": "text"}


def _hover(r: Any) -> str:
    lines = [
        f"<b>{html.escape(str(r.variant))}</b> dt = {r.dt:.3g} s ({r.steps} steps)",
        f"wall time per simulated second {r.cost:.3g} s (real-time factor {r.rtf:.3g}; "
        f"stepping {r.wall_s:.3g} s)",
        f"position error {r.position_error:.3g} mean radii",
        f"velocity error {r.velocity_error:.3g} of the top initial speed",
        f"energy change {r.energy_change:+.3g} of the initial energy",
        f"momentum error {r.momentum_error:.3g}"]
    if r.aligned:
        lines.append(f"<b>impact on a step boundary</b> (t = {r.aligned[0]:.6g} s = k dt): a "
                     "step-late engine meets it on time;<br>this error does not show its step lag")
    if r.apart:
        lines.append(f"drawn beside {html.escape(r.apart)} (same place)")
    return "<br>".join(lines)


def section(frame: pd.DataFrame, cases: Mapping[str, AnyCase], order: list[str],
            facts: Mapping[str, SceneFacts] | None = None) -> dict[str, Any]:
    """What the report template needs: per scene its :func:`headline`, its summary line and
    its chart; the engines (in run order) and the number of runs (``facts``: as for
    :func:`scene_points`)."""
    points = scene_points(frame, cases, facts)
    if points.empty:
        return {"scenes": [], "engines": [], "charts": [], "runs": 0}
    drawn_charts = charts(points, order)
    scenes_out = []
    for (scene, group), chart in zip(points.groupby("scene", sort=False), drawn_charts,
                                     strict=True):
        built = headline(group) | {"scene": str(scene), "chart": chart["html"]}
        scenes_out.append(built | {"summary": summary_line(built)})
    engines = [e for e in dict.fromkeys([*order, *points["engine"]])
               if e in set(points["engine"])]
    return {"scenes": scenes_out, "engines": engines, "charts": drawn_charts,
            "runs": len(points)}
