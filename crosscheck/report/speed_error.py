"""Speed against error: one chart per kind, one panel per quantity, one point per engine.

The data (per kind, per engine, per quantity) is :mod:`crosscheck.report.speed_points`:
errors are in units of each case's float64 bound (scale-free), clipped to a fixed range.
Each panel draws, per engine, x its median cost per query with a horizontal whisker over
the interquartile range of its per-case costs (instructions per query when every engine of
the chart was counted, else wall-clock seconds: the axis title says which), y its median
error with a vertical whisker up to the 95th percentile (nearest rank) and a cross at the
largest error.  Errors below the floor (exact answers among them) sit on a labelled floor
line; errors above the ceiling sit on the ceiling line, the largest drawn as an arrow
instead of a cross, and are counted in the ceiling's label and in the hover.  The accuracy
asked for (by default the float64 bound itself, 1) is drawn as a labelled line: an engine
under it and to the left is accurate enough and cheap.  The last panel counts the wrong verdicts.

Labels never overlap: engines are named in the legend and the hover only, never beside
their points; each panel's three labels (floor, ceiling, accuracy) sit at fixed places of
the fixed error axis.  Engines that would hide one another are drawn side by side (their
hover names the others).  On a wall-clock axis, an engine whose timings are mostly unstable
(see :mod:`crosscheck.report.speed`) is drawn hollow and named so in the legend; a count is
exact, so a counted axis draws none hollow.  The hover gives both measures where both exist.

Every text that reaches plotly (engine names and settings, case ids and descriptions) is
HTML-escaped first: plotly renders its labels as HTML.
"""

from __future__ import annotations

import html
import math
import textwrap
from collections.abc import Mapping
from typing import Any

import plotly.graph_objects as go
from plotly.subplots import make_subplots

from crosscheck.core.kinds import quantity_named
from crosscheck.report import axes, style
from crosscheck.report.speed import UNSTABLE_SPREAD
from crosscheck.report.speed_points import (
    CEILING,
    FLOOR,
    MEASURES,
    UNIT,
    Errors,
    Measure,
    Point,
    SpeedChart,
    error_stats,
    in_tolerances,
    speed_chart,
    speed_charts,
)
from crosscheck.report.style import COLOURS, SYMBOLS, plot_div, plotly_template
from crosscheck.report.text import instructions, seconds, with_iqr

__all__ = ["CEILING", "FLOOR", "MEASURES", "Errors", "Measure", "Point", "SpeedChart",
           "error_stats", "figure", "figure_html", "hover", "in_tolerances", "speed_chart",
           "speed_charts"]

ACCURACY = 1.0
"""The accuracy line drawn by default, in units of the case's float64 bound."""
PAD = 1.0
"""Decades of room beyond the floor and the ceiling (for their labels)."""
HEIGHT = 640
"""The figure's height in pixels: the panels, and the legend in rows beneath them."""
OFF_SYMBOL = "arrow-bar-up"
"""The marker of a largest error that is off scale (drawn on the ceiling)."""
FLOOR_TEXT = f"exact, or below {axes.power(round(math.log10(FLOOR)))}"
ERROR_TITLE = f"median error \u00f7 the {UNIT}<br>(whisker: 95th percentile; cross: max)"


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


def _count_lines(p: Point) -> list[str]:
    """The counted instructions per query, when the engine was counted (else none)."""
    c = p.counted
    if not c.n:
        return []
    own = "" if math.isnan(p.in_engine) else (
        f"<br>of which inside the engine's own code: {instructions(p.in_engine)} (median)")
    return [f"instructions per query (callgrind): {instructions(c.median)}, IQR over cases "
            f"{instructions(c.q1)} to {instructions(c.q3)} (counted on {c.n} of {p.cases} "
            f"cases){own}"]


def _timing_lines(p: Point) -> list[str]:
    flag = " <b>(timing unstable)</b>" if p.mostly_unstable else ""
    return [
        f"median query per call: {seconds(p.query_s)}, IQR over cases "
        f"{seconds(p.time.q1)} to {seconds(p.time.q3)} (timed on {p.timed} of {p.cases} cases)",
        f"{p.unstable} of {p.timed} timings unstable (IQR &gt; {UNSTABLE_SPREAD:.0%} of median)"
        f"{flag}",
        _binding_line(p)]


def _error_lines(errors: Errors, quantity: str) -> list[str]:
    ceiling = f"{CEILING:.0e}".replace("+", "")
    return [
        f"{quantity_named(quantity).title} error \u00f7 {UNIT}: median "
        f"{errors.median:.3g}, 95th percentile {errors.p95:.3g}, max {errors.max:.3g}",
        f"scored cases: {errors.scored} ({errors.zeros} exactly 0)",
        f"<b>{errors.off} off scale</b> (above {ceiling} bounds, infinite or NaN)"
        if errors.off else "none off scale"]


def hover(p: Point, measure: Measure, quantity: str | None = None) -> str:
    """The hover text of a point on the panel of ``quantity`` (the first by default)."""
    quantity = quantity or measure.errors[0]
    return "<br>".join([
        f"<b>{html.escape(p.engine)}</b>", _esc(p.about), *_count_lines(p), *_timing_lines(p),
        *_error_lines(p.errors[quantity], quantity),
        f"{html.escape(measure.verdict_label)}: {_share(p.wrong, p.verdicts)}",
        f"failed (error, crash, timeout): {p.failed} cases",
    ])


def _style(index: int) -> dict[str, Any]:
    """The colour and marker of the ``index``-th engine: past the palette's length the marker
    moves on by one, so that no two of up to 100 engines look alike."""
    symbol = (index + index // len(COLOURS)) % len(SYMBOLS)
    return {"color": COLOURS[index % len(COLOURS)], "symbol": SYMBOLS[symbol]}


def _marker(hollow: bool, style: dict[str, Any]) -> dict[str, Any]:
    """A filled marker, or a hollow one (the engine's timings are mostly unstable)."""
    if hollow:
        return {"size": 12, "color": style["color"], "symbol": f"{style['symbol']}-open",
                "line": {"width": 2, "color": style["color"]}}
    return {"size": 12, "line": {"width": 1, "color": "#333"}, **style}


def _legend_name(p: Point, hollow: bool) -> str:
    return html.escape(p.engine) + (" (timing unstable)" if hollow else "")


def _add_point(fig: go.Figure, chart: SpeedChart, p: Point, quantity: str, col: int,
               style: dict[str, Any], x: float, extra: str) -> None:
    """The point of one engine on one panel, drawn at ``x`` (its median cost, unless pulled
    apart from a coincident point; the hover gives the true numbers)."""
    errors, y = p.errors[quantity], SpeedChart.y(p.errors[quantity].median)
    group, first, cost, hollow = html.escape(p.engine), col == 1, chart.x(p), chart.hollow(p)
    fig.add_trace(go.Scatter(
        x=[x], y=[y], mode="markers", name=_legend_name(p, hollow), legendgroup=group,
        showlegend=first, hovertext=[hover(p, MEASURE_OF[quantity], quantity) + extra],
        hoverinfo="text", marker=_marker(hollow, style),
        error_y={"type": "data", "symmetric": False, "array": [SpeedChart.y(errors.p95) - y],
                 "arrayminus": [0.0], "color": style["color"], "thickness": 2, "width": 6},
        error_x={"type": "data", "symmetric": False, "array": [cost.q3 - cost.median],
                 "arrayminus": [cost.median - cost.q1], "color": style["color"],
                 "thickness": 1.5, "width": 4},
    ), row=1, col=col)
    off = SpeedChart.clipped(errors.max)
    fig.add_trace(go.Scatter(
        x=[x], y=[SpeedChart.y(errors.max)], mode="markers", showlegend=False,
        legendgroup=group, hoverinfo="text",
        hovertext=[f"<b>{group}</b>: max error {errors.max:.3g} \u00f7 bound"
                   f"{f' ({errors.off} off scale)' if off else ''}<br>"
                   f"worst case: {_esc(errors.worst[:160])}"],
        marker={"symbol": OFF_SYMBOL if off else "x-thin", "size": 11,
                "color": style["color"], "line": {"width": 2, "color": style["color"]}},
    ), row=1, col=col)


MEASURE_OF = {q: m for m in MEASURES.values() for q in m.errors}


def _add_verdicts(fig: go.Figure, chart: SpeedChart, styles: dict[str, dict[str, Any]],
                  col: int) -> None:
    shown = [p for p in chart.points if p.verdicts]
    fig.add_trace(go.Bar(
        x=[p.wrong / p.verdicts for p in shown], y=[html.escape(p.engine) for p in shown],
        orientation="h", marker_color=[styles[p.engine]["color"] for p in shown],
        text=[f"{p.wrong}/{p.verdicts}" for p in shown], textposition="outside",
        hoverinfo="text", showlegend=False,
        hovertext=[f"{html.escape(p.engine)}: {_share(p.wrong, p.verdicts)}" for p in shown],
    ), row=1, col=col)
    fig.update_xaxes(range=[0, 1.75], tickvals=[0, 0.5, 1], tickformat=".0%", row=1, col=col)
    # the engine names on the right, in the page's margin: never over the panel beside
    fig.update_yaxes(autorange="reversed", side="right", row=1, col=col)


def error_range() -> tuple[float, float]:
    """log10 of the ends of every error axis: the floor and the ceiling, PAD beyond."""
    return math.log10(FLOOR) - PAD, math.log10(CEILING) + PAD


def time_range(chart: SpeedChart) -> tuple[float, float]:
    """log10 of the ends of the cost axis: whole decades over every whisker, so that small
    differences do not look large."""
    costs = [chart.x(p) for p in chart.plotted]
    return axes.data_range([v for c in costs for v in (c.q1, c.q3, c.median)])


def off_label(count: int) -> str:
    """The ceiling's label: where off-scale errors are, and how many there are."""
    top = axes.power(round(math.log10(CEILING)))
    return f"off scale (above {top}): {count} answer{'' if count == 1 else 's'}"


def accuracy_label(accuracy: float) -> str:
    return ("accuracy: the float64 bound" if accuracy == ACCURACY
            else f"accuracy: {accuracy:g} \u00d7 the float64 bound")


def _line(fig: go.Figure, col: int, y: float, text: str, left: bool, above: bool,
          dash: str, colour: str) -> None:
    """A horizontal line across the panel ``col`` at ``y``, labelled at one end."""
    suffix = "" if col == 1 else str(col)
    fig.add_shape({"type": "line", "xref": f"x{suffix} domain", "x0": 0, "x1": 1,
                   "yref": f"y{suffix}", "y0": y, "y1": y,
                   "line": {"dash": dash, "color": colour, "width": 1.5}})
    fig.add_annotation({"text": text, "xref": f"x{suffix} domain", "x": 0 if left else 1,
                        "yref": f"y{suffix}", "y": math.log10(y),
                        "xanchor": "left" if left else "right",
                        "yanchor": "bottom" if above else "top", "showarrow": False,
                        "font": {**axes.LABEL_FONT, "color": colour}})


def _panel_axes(fig: go.Figure, chart: SpeedChart, quantity: str, col: int,
                accuracy: float) -> None:
    title = ERROR_TITLE if col == 1 else ""
    fig.update_yaxes(axes.log_axis(title, *error_range()), row=1, col=col)
    fig.update_xaxes(axes.log_axis(chart.x_title, *time_range(chart)), row=1, col=col)
    _line(fig, col, FLOOR, FLOOR_TEXT, left=False, above=False, dash="dot", colour="#666")
    _line(fig, col, CEILING, off_label(chart.off_scale(quantity)), left=False, above=True,
          dash="dot", colour="#666")
    _line(fig, col, accuracy, accuracy_label(accuracy), left=True, above=True, dash="dash",
          colour="#2a7d2a")


def drawn_x(chart: SpeedChart, quantity: str) -> tuple[list[float], list[list[int]]]:
    """Where each plotted point is drawn along x on a panel, and the groups of coincident
    points."""
    low, high = time_range(chart)
    bottom, top = error_range()
    plotted = chart.plotted
    xs = [chart.x(p).median for p in plotted]
    groups = axes.coincident([(x, SpeedChart.y(p.errors[quantity].median))
                              for x, p in zip(xs, plotted, strict=True)],
                             (high - low, top - bottom))
    return axes.spread(xs, groups, high - low), groups


def _panel(fig: go.Figure, chart: SpeedChart, quantity: str, col: int,
           styles: dict[str, dict[str, Any]]) -> None:
    xs, groups = drawn_x(chart, quantity)
    names = [html.escape(p.engine) for p in chart.plotted]
    for p, x, others in zip(chart.plotted, xs, axes.beside(groups, names), strict=True):
        extra = f"<br>drawn beside (same spot): {others}" if others else ""
        _add_point(fig, chart, p, quantity, col, styles[p.engine], x, extra)


def figure(chart: SpeedChart, order: list[str], template: bool = True,
           accuracy: Mapping[str, float] | None = None) -> go.Figure:
    """The chart of one kind: one speed-against-error panel per quantity, then the wrong
    verdicts.  ``order`` fixes each engine's colour and symbol, the same on every chart;
    ``accuracy`` (in float64 bounds, per quantity) places the accuracy lines."""
    quantities = chart.measure.errors
    titles = [quantity_named(q).title for q in quantities]
    fig = make_subplots(rows=1, cols=len(quantities) + 1, horizontal_spacing=0.09,
                        column_widths=[*([0.74 / len(quantities)] * len(quantities)), 0.26],
                        subplot_titles=(*titles, chart.measure.verdict_label))
    names = dict.fromkeys([*order, *(p.engine for p in chart.points)])
    styles = {name: _style(i) for i, name in enumerate(names)}
    for col, quantity in enumerate(quantities, start=1):
        _panel(fig, chart, quantity, col, styles)
        _panel_axes(fig, chart, quantity, col, (accuracy or {}).get(quantity, ACCURACY))
    _add_verdicts(fig, chart, styles, len(quantities) + 1)
    hollow = "" if chart.by_counts else "; hollow: timing unstable"
    fig.update_layout(height=HEIGHT, hoverlabel={"align": "left"},
                      margin={"t": 40, "b": 40, "l": 40, "r": 20},
                      legend={"title_text": "engine (cross: max error; arrow: off scale"
                                            f"{hollow})", "title_side": "top",
                              "orientation": "h", "x": 0, "xanchor": "left",
                              "y": -0.16, "yanchor": "top"})
    return fig.update_layout(template=plotly_template()) if template else fig


def figure_html(chart: SpeedChart, order: list[str]) -> str:
    """The chart as a <div> with its script; plotly.js must be on the page once already."""
    content = figure(chart, order, template=False).to_plotly_json()  # a go.Figure validates
    content["layout"]["template"] = style.validated_template()  # a template in ~0.3 s
    return plot_div(content, f"speed-{chart.kind}")
