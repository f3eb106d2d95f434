"""Speed against error: one log-log chart per kind, one point per engine variant.

For each kind, a point is one engine: x is its median time per query over the
cases of that kind it timed (``query_s``, one value per case x engine: the
median of its samples), with a horizontal whisker over the interquartile range
of those per-case times; y the median error over the cases it was scored on
(``agree`` or ``disagree``).  The error is the distance error for the detection
kinds and, for responses, the worse of the ``v1`` and ``v2`` errors of each
case; ``hit`` errors are 0 or 1, so the verdicts go to a side panel (share of
wrong verdicts) instead.  A vertical whisker runs from the median up to the
95th percentile (nearest rank) and a cross marks the largest error.  An engine
whose timings are mostly unstable (more than half of its timed cases, see
:mod:`crosscheck.report.speed`) is drawn hollow and named so in the legend,
never as a precise point.  A log axis has no 0 and no infinity: exact answers
are drawn at a labelled floor, infinite errors at a labelled ceiling.  Engines
that would hide one another are drawn side by side under one label naming them
all; every axis is styled by :mod:`crosscheck.report.axes`.

Every text that reaches plotly (engine names and settings, case ids and
descriptions) is HTML-escaped first: plotly renders its labels as HTML.
"""

from __future__ import annotations

import html
import math
import textwrap
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from crosscheck.core.model import Status
from crosscheck.core.schema import AnyCase
from crosscheck.report import axes, style
from crosscheck.report.speed import (
    UNSTABLE_SPREAD,
    Spread,
    binding,
    binding_note,
    case_times,
    seconds,
    with_iqr,
)
from crosscheck.report.style import COLOURS, SYMBOLS, plot_div, plotly_template
from crosscheck.results.runinfo import RunInfo


@dataclass(frozen=True, slots=True)
class Measure:
    """What the chart of one kind plots: error quantities, verdict quantities, labels."""

    errors: tuple[str, ...]
    verdicts: tuple[str, ...]
    error_label: str
    verdict_label: str


MEASURES: dict[str, Measure] = {
    kind: Measure(("distance",), ("hit",), "absolute error of the signed distance",
                  "wrong hit verdicts")
    for kind in ("aabb", "sphere")
} | {"sphere_response": Measure(("v1", "v2"), ("v1", "v2"),
                                "velocity error |v - v_true| (worse of v1, v2 per case)",
                                "cases with a velocity beyond tolerance")}


@dataclass(frozen=True, slots=True)
class Point:
    """One engine on the chart of one kind; NaN where there is nothing to measure."""

    engine: str
    about: str
    """The engine, its version and its settings (from run.json)."""
    cases: int
    time: Spread
    """Per-case query times over the timed cases: median (x), quartiles (whisker), count."""
    unstable: int
    """Timed cases whose own samples spread more than UNSTABLE_SPREAD of their median."""
    binding: Spread | None
    """The cheapest call into the engine's Python binding (None: not measured)."""
    binding_note: str
    """Why there is no binding overhead ('' when there is one)."""
    scored: int
    zeros: int
    median: float
    p95: float
    max: float
    worst: str
    """Id and description of the case with the largest error."""
    wrong: int
    verdicts: int
    failed: int

    @property
    def timed(self) -> int:
        return self.time.n

    @property
    def query_s(self) -> float:
        return self.time.median

    @property
    def mostly_unstable(self) -> bool:
        """More than half of the timed cases unstable: no precise point for this engine."""
        return self.unstable > self.timed / 2

    @property
    def binding_share(self) -> float | None:
        """The binding call's share of the median query time (None: unknown)."""
        if self.binding is None or not self.query_s > 0:
            return None
        return self.binding.median / self.query_s


@dataclass(frozen=True, slots=True)
class SpeedChart:
    """The points of one kind and how to draw them on log axes."""

    kind: str
    measure: Measure
    points: list[Point]
    floor: float
    ceiling: float | None
    """Where infinite errors are drawn, or None when there are none."""

    @property
    def plotted(self) -> list[Point]:
        return [p for p in self.points if p.scored and p.timed]

    @property
    def errors(self) -> list[float]:
        """The median, 95th percentile and largest error of every plotted engine."""
        return [v for p in self.plotted for v in (p.median, p.p95, p.max)]

    @property
    def not_timed(self) -> list[Point]:
        return [p for p in self.points if p.scored and not p.timed]

    @property
    def not_scored(self) -> list[Point]:
        return [p for p in self.points if not p.scored]

    @property
    def timings(self) -> tuple[int, int]:
        """Unstable and all timed cases of the plotted engines."""
        return sum(p.unstable for p in self.plotted), sum(p.timed for p in self.plotted)

    def y(self, value: float) -> float:
        """Where an error is drawn: 0 at the floor, infinity at the ceiling."""
        if value == 0.0:
            return self.floor
        return self.ceiling if math.isinf(value) and self.ceiling else value


def error_stats(errors: pd.Series) -> tuple[float, float, float]:
    """Median, 95th percentile (nearest rank) and max of non-negative errors (inf allowed)."""
    values = np.sort(errors.dropna().to_numpy(dtype=float))
    if not len(values):
        return math.nan, math.nan, math.nan
    p95 = values[math.ceil(0.95 * len(values)) - 1]
    return float(np.median(values)), float(p95), float(values[-1])


def _about(engine: str, info: RunInfo) -> str:
    for entry in info.engines:
        if entry.get("name") == engine:
            return f"{entry.get('engine')} {entry.get('version')}: {entry.get('settings')}"
    return ""


def _worst(errors: pd.Series, cases: Mapping[str, AnyCase]) -> str:
    if errors.empty:
        return ""
    case_id = str(errors.idxmax())
    case = cases.get(case_id)
    return f"{case_id}: {case.description if case else ''}"


def point(rows: pd.DataFrame, measure: Measure, info: RunInfo,
          cases: Mapping[str, AnyCase]) -> Point:
    """The point of one engine, from its rows of one kind."""
    engine = str(rows["engine"].iloc[0])
    scored = rows[rows["status"].isin(Status.members("scored"))]
    errors = scored[scored["quantity"].isin(measure.errors)].groupby("case_id")["error"].max()
    verdicts = scored[scored["quantity"].isin(measure.verdicts)]
    time, unstable = case_times(rows)
    median, p95, top = error_stats(errors)
    return Point(
        engine=engine, about=_about(engine, info), cases=rows["case_id"].nunique(),
        time=time, unstable=unstable, binding=binding(info, engine),
        binding_note=binding_note(info, engine), scored=len(errors),
        zeros=int((errors == 0).sum()), median=median, p95=p95, max=top,
        worst=_worst(errors, cases), verdicts=verdicts["case_id"].nunique(),
        wrong=verdicts.loc[verdicts["status"] == Status.DISAGREE, "case_id"].nunique(),
        failed=rows.loc[rows["status"].isin(Status.members("failed")), "case_id"].nunique())


def speed_chart(frame: pd.DataFrame, kind: str, info: RunInfo,
                cases: Mapping[str, AnyCase]) -> SpeedChart:
    """The speed-against-error data of one kind: one point per engine with rows of it."""
    measure = MEASURES[kind]
    rows = frame[frame["kind"] == kind]
    points = [point(group, measure, info, cases)
              for _, group in rows.groupby("engine", sort=False)]
    plotted = [p for p in points if p.scored and p.timed]
    return SpeedChart(kind, measure, points,
                      *axes.limits(v for p in plotted for v in (p.median, p.p95, p.max)))


def speed_charts(frame: pd.DataFrame, info: RunInfo,
                 cases: Mapping[str, AnyCase]) -> list[SpeedChart]:
    """One chart per kind present in the results, in the order of MEASURES."""
    present = set(frame["kind"])
    return [speed_chart(frame, kind, info, cases) for kind in MEASURES if kind in present]


def _esc(text: str, width: int = 70) -> str:
    """Plain text as plotly label HTML: escaped, wrapped with <br>."""
    return "<br>".join(html.escape(line) for line in textwrap.wrap(text, width))


def _share(part: int, whole: int) -> str:
    return f"{part} of {whole} ({part / whole:.0%})" if whole else "none"


def _binding_line(p: Point) -> str:
    if p.binding is None:
        return f"binding call: {html.escape(p.binding_note)}"
    share = f", {p.binding_share:.0%} of the median query" if p.binding_share else ""
    return f"binding call (cheapest call into it): {with_iqr(p.binding)}{share}"


def _timing_lines(p: Point) -> list[str]:
    flag = " <b>(timing unstable)</b>" if p.mostly_unstable else ""
    return [
        f"median query per call: {seconds(p.query_s)}, IQR over cases "
        f"{seconds(p.time.q1)} to {seconds(p.time.q3)} (timed on {p.timed} of {p.cases} cases)",
        f"{p.unstable} of {p.timed} timings unstable (IQR &gt; {UNSTABLE_SPREAD:.0%} of median)"
        f"{flag}",
        _binding_line(p)]


def hover(p: Point, measure: Measure) -> str:
    """The hover text of a point (escaped HTML)."""
    return "<br>".join([
        f"<b>{html.escape(p.engine)}</b>", _esc(p.about), *_timing_lines(p),
        f"error: median {p.median:.3g}, 95th percentile {p.p95:.3g}, max {p.max:.3g}",
        f"scored cases: {p.scored} ({p.zeros} exactly 0)",
        f"{html.escape(measure.verdict_label)}: {_share(p.wrong, p.verdicts)}",
        f"failed (error, crash, timeout): {p.failed} cases",
    ])


def _style(index: int) -> dict[str, Any]:
    return {"color": COLOURS[index % len(COLOURS)], "symbol": SYMBOLS[index % len(SYMBOLS)]}


def _marker(p: Point, style: dict[str, Any]) -> dict[str, Any]:
    """A filled marker, or a hollow one when the engine's timings are mostly unstable."""
    if p.mostly_unstable:
        return {"size": 13, "color": style["color"], "symbol": f"{style['symbol']}-open",
                "line": {"width": 2, "color": style["color"]}}
    return {"size": 13, "line": {"width": 1, "color": "#333"}, **style}


def _legend_name(p: Point) -> str:
    return html.escape(p.engine) + (" (timing unstable)" if p.mostly_unstable else "")


def _add_point(fig: go.Figure, chart: SpeedChart, p: Point, style: dict[str, Any],
               x: float) -> None:
    """The point of one engine drawn at ``x`` (its median time, unless pulled apart from a
    coincident point); the hover gives the true numbers."""
    y = chart.y(p.median)
    fig.add_trace(go.Scatter(
        x=[x], y=[y], mode="markers", name=_legend_name(p),
        legendgroup=html.escape(p.engine), hovertext=[hover(p, chart.measure)], hoverinfo="text",
        marker=_marker(p, style),
        error_y={"type": "data", "symmetric": False, "array": [chart.y(p.p95) - y],
                 "arrayminus": [0.0], "color": style["color"], "thickness": 2, "width": 7},
        error_x={"type": "data", "symmetric": False, "array": [p.time.q3 - p.time.median],
                 "arrayminus": [p.time.median - p.time.q1], "color": style["color"],
                 "thickness": 1.5, "width": 5},
    ), row=1, col=1)
    fig.add_trace(go.Scatter(
        x=[x], y=[chart.y(p.max)], mode="markers", showlegend=False,
        legendgroup=html.escape(p.engine), hoverinfo="text",
        hovertext=[f"<b>{html.escape(p.engine)}</b>: max error {p.max:.3g}<br>"
                   f"worst case: {_esc(p.worst[:160])}"],
        marker={"symbol": "x-thin", "size": 11, "line": {"width": 2, "color": style["color"]}},
    ), row=1, col=1)


def _add_verdicts(fig: go.Figure, chart: SpeedChart, styles: dict[str, dict[str, Any]]) -> None:
    shown = [p for p in chart.points if p.verdicts]
    fig.add_trace(go.Bar(
        x=[p.wrong / p.verdicts for p in shown], y=[html.escape(p.engine) for p in shown],
        orientation="h", marker_color=[styles[p.engine]["color"] for p in shown],
        text=[f"{p.wrong}/{p.verdicts}" for p in shown], textposition="outside",
        hoverinfo="text", showlegend=False,
        hovertext=[f"{html.escape(p.engine)}: {_share(p.wrong, p.verdicts)}" for p in shown],
    ), row=1, col=2)
    fig.update_xaxes(range=[0, 1.35], tickvals=[0, 0.5, 1], tickformat=".0%", row=1, col=2)
    fig.update_yaxes(autorange="reversed", row=1, col=2)


def error_range(chart: SpeedChart) -> tuple[float, float]:
    """log10 of the ends of the error axis (the floor, when shown, and the ceiling included)."""
    return axes.error_range(chart.errors, axes.shown_floor(chart.errors, chart.floor),
                            chart.ceiling)


def time_range(chart: SpeedChart) -> tuple[float, float]:
    """log10 of the ends of the time axis: whole decades over every whisker, so that small
    differences do not look large."""
    times = [t for p in chart.plotted for t in (p.time.q1, p.time.q3, p.query_s)]
    return axes.data_range(times)


def _error_axis(fig: go.Figure, chart: SpeedChart) -> None:
    floor = axes.shown_floor(chart.errors, chart.floor)
    marks = [*(["0"] if floor else []), *(["inf"] if chart.ceiling else [])]
    title = f"median {chart.measure.error_label}" + (
        f"<br>({' and '.join(marks)} on the dotted lines)" if marks else "")
    fig.update_yaxes(axes.log_axis(title, *error_range(chart), floor, chart.ceiling),
                     row=1, col=1)
    shapes, labels = axes.limit_marks(floor, chart.ceiling, "infinite error")
    for shape in shapes:
        fig.add_shape(shape)
    for label in labels:
        fig.add_annotation(label)


def _time_axis(fig: go.Figure, chart: SpeedChart) -> None:
    fig.update_xaxes(axes.log_axis("median time per call through the Python binding (s; "
                                   "whisker: IQR over cases)", *time_range(chart)), row=1, col=1)


def drawn_x(chart: SpeedChart) -> tuple[list[float], list[list[int]]]:
    """Where each plotted point is drawn along x, and the groups of coincident points."""
    low, high = time_range(chart)
    bottom, top = error_range(chart)
    plotted = chart.plotted
    groups = axes.coincident([(p.query_s, chart.y(p.median)) for p in plotted],
                             (high - low, top - bottom))
    return axes.spread([p.query_s for p in plotted], groups, high - low), groups


def _label_groups(fig: go.Figure, chart: SpeedChart, groups: list[list[int]]) -> None:
    """One label over each group of coincident points, naming every engine in it."""
    for group in (g for g in groups if len(g) > 1):
        members = [chart.plotted[i] for i in group]
        middle = sum(math.log10(p.query_s) for p in members) / len(members)
        fig.add_annotation(
            text="same point: " + ", ".join(html.escape(p.engine) for p in members),
            x=middle, y=math.log10(chart.y(members[0].median)),
            xref="x", yref="y", yshift=16, showarrow=False, font=axes.LABEL_FONT)


def figure(chart: SpeedChart, order: list[str], template: bool = True) -> go.Figure:
    """The chart of one kind: speed against error (left), wrong verdicts (right).

    ``order`` fixes each engine's colour and symbol, the same on every chart."""
    fig = make_subplots(rows=1, cols=2, column_widths=[0.7, 0.3], horizontal_spacing=0.16,
                        subplot_titles=("speed against error (lower left is better)",
                                        chart.measure.verdict_label))
    names = dict.fromkeys([*order, *(p.engine for p in chart.points)])
    styles = {name: _style(i) for i, name in enumerate(names)}
    xs, groups = drawn_x(chart)
    for p, x in zip(chart.plotted, xs, strict=True):
        _add_point(fig, chart, p, styles[p.engine], x)
    _label_groups(fig, chart, groups)
    _add_verdicts(fig, chart, styles)
    _error_axis(fig, chart)
    _time_axis(fig, chart)
    fig.update_layout(height=480, hoverlabel={"align": "left"},
                      margin={"t": 40, "b": 40, "l": 40, "r": 20},
                      legend={"title_text": "engine (cross: max error;<br>"
                                            "hollow: timing unstable)"})
    return fig.update_layout(template=plotly_template()) if template else fig


def figure_html(chart: SpeedChart, order: list[str]) -> str:
    """The chart as a <div> with its script; plotly.js must be on the page once already."""
    content = figure(chart, order, template=False).to_plotly_json()  # a go.Figure validates
    content["layout"]["template"] = style.validated_template()  # a template in ~0.3 s
    return plot_div(content, f"speed-{chart.kind}")
