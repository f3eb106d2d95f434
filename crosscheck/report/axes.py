"""The one style of every log axis in the report, and what a log axis cannot draw by itself.

Every log axis of the speed, dynamics and stability charts is built by :func:`log_axis`:
decade ticks written as plotly's ``exponentformat="power"`` writes them (``1``, ``10``,
then ``10`` with a superscript exponent), thinned to at most :data:`MOST_TICKS`, with the
gridlines, fonts and title style of :func:`crosscheck.report.style.plotly_template`.

A log axis has no 0 and no infinity: :func:`limits` picks a floor (where exact answers are
drawn, tick ``0``) and a ceiling (where infinite errors or runs without a value are drawn,
tick ``inf``), and :func:`limit_marks` draws both as dotted lines with a label saying what
they hold.

Points that would hide one another (for example ``pybullet`` and ``pybullet-default`` with
the same answers) are found by :func:`coincident` and pulled apart along x by
:func:`spread`, a few per cent of the axis; the hover text keeps the true values.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

from crosscheck.report.style import ZERO_FLOOR

MINUS = "\u2212"
"""The minus sign of plotly's own power-format ticks."""
MOST_TICKS = 8
"""At most this many decade ticks on an axis (every k-th decade beyond that)."""
NEAR = 0.025
"""Points closer than this share of both axis spans hide each other (about a marker)."""
STEP = 0.03
"""Coincident points are drawn this share of the x span apart."""
MINOR_SPAN = 4.5
"""A log axis spanning at most this many decades also has minor ticks at 2, 3, ... 9."""
FLOOR_LABEL = "exact (error 0)"
LABEL_FONT = {"size": 11, "color": "#666"}


def power(k: int) -> str:
    """The tick label of ``10**k`` in plotly's power format.

    >>> [power(k) for k in (0, 1, 2)], power(-3) == f"10<sup>{MINUS}3</sup>"
    (['1', '10', '10<sup>2</sup>'], True)
    """
    if k in (0, 1):
        return "1" if k == 0 else "10"
    return f"10<sup>{MINUS if k < 0 else ''}{abs(k)}</sup>"


def decades(first: int, last: int, most: int = MOST_TICKS) -> list[int]:
    """The exponents of the decade ticks from ``first`` to ``last``: every k-th decade (k a
    multiple that keeps at most ``most``), on multiples of k.

    >>> decades(-18, 2)
    [-18, -15, -12, -9, -6, -3, 0]
    >>> decades(-7, -5)
    [-7, -6, -5]
    """
    step = max(1, math.ceil((last - first + 1) / most))
    return [k for k in range(first, last + 1) if k % step == 0]


MIN_DECADE, MAX_DECADE = -320, 308
"""The lowest and highest decades an error axis may reach (10.0 ** k is a double)."""


def limits(values: Iterable[float], failed: bool = False) -> tuple[float, float | None]:
    """Floor and ceiling of an error axis: the floor is :data:`ZERO_FLOOR`, or a decade below
    the smallest positive error when that is smaller; the ceiling (only when a value is
    infinite or NaN, or ``failed``) two decades above the largest finite one and at least 100.

    >>> limits([1e-3, 0.0])
    (1e-18, None)
    >>> limits([3e-21, math.inf])
    (1e-22, 100.0)

    Both stay within the doubles, whatever the errors (an engine may answer 1.8e308):

    >>> limits([5e-324, 1.7e308, math.nan])
    (1e-320, 1e+308)
    """
    values = list(values)
    finite = [v for v in values if 0 < v < math.inf]
    lowest = max(math.floor(math.log10(min(finite))) - 1, MIN_DECADE) if finite else 0
    floor = min(ZERO_FLOOR, 10.0 ** lowest) if finite else ZERO_FLOOR
    if not (failed or any(not math.isfinite(v) for v in values)):
        return floor, None
    top = max(math.ceil(math.log10(max(finite, default=1.0))), 0)
    return floor, 10.0 ** min(top + 2, MAX_DECADE)


def shown_floor(values: Iterable[float], floor: float) -> float | None:
    """The floor when a value sits on it (an error of exactly 0), else None: an axis reaches
    down to its floor only when something is drawn there.

    >>> shown_floor([0.0, 1e-3], 1e-18), shown_floor([1e-3], 1e-18)
    (1e-18, None)
    """
    return floor if any(v == 0 for v in values) else None


def error_range(values: Iterable[float], floor: float | None,
                ceiling: float | None) -> tuple[float, float]:
    """log10 of the ends of an error axis: beyond the floor (when shown, else the decade below
    the smallest positive value) and beyond the ceiling (when there is one, else the decade
    above the largest finite value, at least a decade above the bottom) by half a decade or
    5% of the span, whichever is more.

    >>> error_range([2e-3, 0.5], None, None), error_range([0.0, 0.5], 1e-18, 100.0)
    ((-3.5, 0.5), (-19.0, 3.0))
    """
    logs = [math.log10(v) for v in values if 0 < v < math.inf]
    if floor:
        low = math.log10(floor)
    elif logs:
        low = math.floor(min(logs))
    else:
        low = (math.log10(ceiling) if ceiling else 0.0) - 2
    high = math.log10(ceiling) if ceiling else max([low + 1, *(math.ceil(v) for v in logs)])
    pad = max(0.5, 0.05 * (high - low))  # room for the floor's and the ceiling's labels
    return low - pad, high + pad


def _clear(ks: list[int], first: int, last: int, floor: bool, ceiling: bool) -> list[int]:
    """The decade ticks ``ks`` without those too close to the floor's ``0`` or the ceiling's
    ``inf`` to read apart (closer than a decade, or than half the tick step)."""
    gap = max(1.0, 0.5 * (ks[1] - ks[0] if len(ks) > 1 else 1))
    return [k for k in ks if not (floor and k - first < gap) and not (ceiling and last - k < gap)]


def log_axis(title: str, low: float, high: float, floor: float | None = None,
             ceiling: float | None = None) -> dict[str, Any]:
    """A log axis over ``[low, high]`` (log10 of its ends) in the report's one style: decade
    ticks in the power format, tick ``0`` at the floor and ``inf`` at the ceiling (if any).

    >>> axis = log_axis("error", -18.5, 2.5, floor=1e-18, ceiling=100.0)
    >>> axis["ticktext"][0], axis["ticktext"][-1], axis["exponentformat"]
    ('0', 'inf', 'power')
    >>> [round(math.log10(v)) for v in axis["tickvals"]]
    [-18, -15, -12, -9, -6, -3, 0, 2]
    """
    first = math.ceil(low) if floor is None else round(math.log10(floor))
    last = math.floor(high) if ceiling is None else round(math.log10(ceiling))
    ticks = {10.0**k: power(k) for k in _clear(decades(first, last), first, last,
                                               floor is not None, ceiling is not None)}
    if floor:
        ticks = {floor: "0"} | ticks
    if ceiling:
        ticks[ceiling] = "inf"
    axis = {"type": "log", "range": [low, high], "tickmode": "array", "tickvals": list(ticks),
            "ticktext": list(ticks.values()), "exponentformat": "power", "showexponent": "all",
            "title": {"text": title}}
    if abs(high - low) <= MINOR_SPAN:
        axis["minor"] = {"dtick": "D1", "ticks": "outside", "ticklen": 2, "showgrid": True,
                         "gridcolor": "#f3f3f3"}
    return axis


def data_range(values: Iterable[float], pad: float = 0.15) -> tuple[float, float]:
    """log10 of the ends of a data axis: every positive finite value with ``pad`` decades to
    spare, widened to whole decades so that at least two decade ticks show.

    >>> data_range([2e-6, 3e-6])
    (-6.0, -5.0)
    """
    logs = [math.log10(v) for v in values if 0 < v < math.inf] or [0.0]
    return float(math.floor(min(logs) - pad)), float(math.ceil(max(logs) + pad))


def limit_marks(floor: float | None, ceiling: float | None, ceiling_label: str,
                xref: str = "x", yref: str = "y") -> tuple[list[dict[str, Any]],
                                                            list[dict[str, Any]]]:
    """The dotted lines (shapes) and labels (annotations) of the floor and the ceiling of the
    error axis ``yref``, across the plot of ``xref``.

    A shape on a log axis takes the value itself, an annotation its log10.
    """
    shapes, notes = [], []
    for y, label, anchor in ((floor, FLOOR_LABEL, "top"), (ceiling, ceiling_label, "bottom")):
        if not y:
            continue
        shapes.append({"type": "line", "xref": f"{xref} domain", "x0": 0, "x1": 1,
                       "yref": yref, "y0": y, "y1": y,
                       "line": {"dash": "dot", "color": "#888", "width": 1}})
        notes.append({"text": label, "xref": f"{xref} domain", "x": 1, "yref": yref,
                      "y": math.log10(y), "xanchor": "right", "yanchor": anchor,
                      "showarrow": False, "font": LABEL_FONT})
    return shapes, notes


def _log(point: tuple[float, float]) -> tuple[float, float] | None:
    x, y = point
    return (math.log10(x), math.log10(y)) if 0 < x < math.inf and 0 < y < math.inf else None


def coincident(points: Sequence[tuple[float, float]], spans: tuple[float, float],
               near: float = NEAR) -> list[list[int]]:
    """Groups of the indices of points that hide one another on log axes: within ``near`` of
    the x span and of the y span (both in decades) of the first point of their group.
    Every point is in one group (most alone, and always a point that cannot be drawn),
    in input order.

    >>> coincident([(1.0, 1e-3), (1.01, 1e-3), (10.0, 1e-3)], (2.0, 10.0))
    [[0, 1], [2]]
    """
    logs = [_log(p) for p in points]
    groups: list[list[int]] = []
    for i, here in enumerate(logs):
        for group in groups:
            first = logs[group[0]]
            if here and first and abs(here[0] - first[0]) <= near * spans[0] \
                    and abs(here[1] - first[1]) <= near * spans[1]:
                group.append(i)
                break
        else:
            groups.append([i])
    return groups


def spread(xs: Sequence[float], groups: Iterable[list[int]], span: float,
           step: float = STEP) -> list[float]:
    """Where to draw each x on a log axis of ``span`` decades: the points of a group (of
    :func:`coincident`) side by side, ``step`` of the span apart, in order of their true x,
    centred on their mean; points alone stay where they are.

    >>> [round(x, 3) for x in spread([1.0, 1.0, 5.0], [[0, 1], [2]], 1.0, 0.1)]
    [0.891, 1.122, 5.0]
    """
    out = list(xs)
    for group in groups:
        if len(group) < 2:
            continue
        ordered = sorted(group, key=lambda i: (xs[i], i))
        middle = sum(math.log10(xs[i]) for i in group) / len(group)
        for j, i in enumerate(ordered):
            out[i] = 10.0 ** (middle + (j - (len(group) - 1) / 2) * step * span)
    return out


def beside(groups: Iterable[list[int]], names: Sequence[str]) -> list[str]:
    """For each point, the names of the others of its group of :func:`coincident` ('' alone).

    >>> beside([[0, 2], [1]], ["a", "b", "c"])
    ['c', '', 'a']
    """
    out = [""] * len(names)
    for group in groups:
        for i in group:
            out[i] = ", ".join(names[j] for j in group if j != i)
    return out


def once(groups: Iterable[list[int]], texts: Sequence[str]) -> list[str]:
    """Each point's text, blank where an earlier point of its group already shows that text
    (one label for points drawn side by side that would all say the same).

    >>> once([[0, 1, 2]], ["dt 1 ms", "dt 1 ms", "dt 2 ms"])
    ['dt 1 ms', '', 'dt 2 ms']
    """
    out = list(texts)
    for group in groups:
        seen: set[str] = set()
        for i in group:
            out[i] = "" if texts[i] in seen else texts[i]
            seen.add(texts[i])
    return out
