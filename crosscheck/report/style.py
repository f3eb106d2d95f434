"""The report's one look: one Jinja environment, one plotly template, one palette.

Every section renders through :func:`templates` and draws its charts with
:func:`plotly_template`, :data:`COLOURS` and :data:`SYMBOLS`, so an engine has
the same colour and marker on every chart of a page.

>>> templates() is templates()
True
>>> plotly_template()["layout"]["plot_bgcolor"]
'white'
"""

from __future__ import annotations

import base64
import functools
import gzip
import html
import json
from importlib import resources
from typing import Any

import plotly.graph_objects as go
import plotly.io as pio
from jinja2 import Environment, PackageLoader, select_autoescape

from crosscheck.report import bundle, repro_links, text

COLOURS = ("#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
           "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac")
"""One colour per engine, in the run's engine order."""
SYMBOLS = ("circle", "square", "diamond", "triangle-up", "triangle-down",
           "pentagon", "hexagon", "star", "cross", "hourglass")
"""One marker per engine, in the run's engine order."""
ZERO_FLOOR = 1e-18
"""Where an error of exactly 0 is drawn on a log axis (lower when a real error is smaller)."""
PLOT_CONFIG = {"displaylogo": False, "responsive": True}


@functools.cache
def templates() -> Environment:
    """The Jinja environment of every page (autoescaping on, templates in ``report/templates``;
    every template can write a time with ``seconds`` and ``median_iqr``, a count of
    instructions with ``instructions`` and ``instructions_iqr``, the command that prints a
    repro script with ``repro_command``, and inline the page's script with ``report_js``)."""
    env = Environment(loader=PackageLoader("crosscheck.report", "templates"),
                      autoescape=select_autoescape(default=True, default_for_string=True))
    env.globals.update(report_js=script, seconds=text.seconds, median_iqr=text.median_iqr,
                       instructions=text.instructions,
                       instructions_iqr=text.instructions_iqr,
                       repro_command=repro_links.command)
    return env


@functools.cache
def plotly_template() -> dict[str, Any]:
    """The plotly template of every chart, as a plain dict: ``plotly_white`` with one font,
    one axis style (a framed plot, outside ticks, light gridlines, no zero line) and plotly's
    ``power`` exponent format on every axis (log axes: see :mod:`crosscheck.report.axes`).

    >>> plotly_template()["layout"]["yaxis"]["exponentformat"]
    'power'
    """
    template = dict(pio.templates["plotly_white"].to_plotly_json())
    layout = dict(template["layout"])
    layout["font"] = {**layout.get("font", {}), "size": 12,
                      "family": "system-ui, -apple-system, 'Segoe UI', sans-serif"}
    for name in ("xaxis", "yaxis"):
        layout[name] = {**layout.get(name, {}), **chart_axis()}
    template["layout"] = layout
    return template


@functools.cache
def validated_template() -> dict[str, Any]:
    """:func:`plotly_template` exactly as a ``go.Figure`` writes it (merged into plotly's
    default template, in its key order), built once: validating it costs ~0.3 s a figure."""
    layout = go.Figure().update_layout(template=plotly_template()).to_plotly_json()["layout"]
    return dict(layout["template"])


def chart_axis() -> dict[str, Any]:
    """The style every chart axis shares (the template's ``xaxis`` and ``yaxis``)."""
    return {"exponentformat": "power", "showexponent": "all", "gridcolor": "#e6e6e6",
            "linecolor": "#555", "showline": True, "mirror": True, "ticks": "outside",
            "tickcolor": "#555", "ticklen": 4, "tickfont": {"size": 11}, "zeroline": False,
            "title": {"standoff": 10, "font": {"size": 12}}, "automargin": True}


def plot_div(figure: Any, div_id: str) -> str:
    """A figure (a plain dict or a ``go.Figure``) as a ``<div>`` followed by its figure,
    without plotly.js (the page inlines it once, packed).

    The figure's JSON is packed too (:func:`packed`), in a ``<script class="plotly-figure">``
    that runs nothing: the page's script (:func:`script`) draws it once plotly.js is unpacked
    and loaded and the chart comes near the viewport.  Figures are rendered without
    validation: ``go.Figure`` costs ~0.2-0.5 s each.

    Every trace must be one the cartesian bundle draws (:data:`bundle.TRACES`).

    >>> html = plot_div({"data": [], "layout": {"height": 300}}, "x")
    >>> html.startswith('<div id="x" class="plotly-graph-div" style="height:300px; width:100%;">')
    True
    >>> plot_div({"data": [{"type": "scatter3d"}], "layout": {}}, "y")
    Traceback (most recent call last):
    ValueError: chart y draws scatter3d, which plotly's cartesian bundle lacks
    """
    text = str(pio.to_json(figure, validate=False))
    content = json.loads(text)
    for trace in content.get("data", []):
        if (kind := trace.get("type", "scatter")) not in bundle.TRACES:
            raise ValueError(f"chart {div_id} draws {kind}, which plotly's cartesian bundle lacks")
    height = content.get("layout", {}).get("height")
    style = f"height:{height}px; width:100%;" if height else "height:100%; width:100%;"
    config = html.escape(json.dumps(PLOT_CONFIG))
    return (f'<div id="{div_id}" class="plotly-graph-div" style="{style}"></div>'
            f'<script type="application/octet-stream" class="plotly-figure" '
            f'data-config="{config}">{packed(text)}</script>')


@functools.cache
def script() -> str:
    """The page's one script (``static/report.js``), inlined into every page's head: it
    unpacks the payloads, draws the charts and fills the tables from data already judged,
    ranked and written in Python (its one global is ``window.crosscheck``).

    >>> "window.crosscheck = {}" in script() and "</script" not in script()
    True
    """
    return (resources.files("crosscheck.report") / "static" / "report.js").read_text(
        encoding="utf-8")


@functools.cache
def plotly_js() -> str:
    """The plotly.js bundle, to inline once in the page (see :func:`packed`): the cartesian
    partial bundle (:mod:`crosscheck.report.bundle`), else the wheel's full one."""
    return bundle.script()


def packed(text: str) -> str:
    """``text`` gzip-compressed and base64-encoded: what the page unpacks with the browser's
    ``DecompressionStream("gzip")`` (the alphabet needs no escaping inside a ``<script>``).

    >>> import base64, gzip
    >>> gzip.decompress(base64.b64decode(packed("Plotly"))).decode()
    'Plotly'
    """
    return base64.b64encode(gzip.compress(text.encode("utf-8"), compresslevel=9, mtime=0)
                            ).decode("ascii")


@functools.cache
def packed_plotly_js() -> str:
    """:func:`plotly_js`, packed (compressed once per process)."""
    return packed(plotly_js())


@functools.cache
def datatables() -> tuple[str, str]:
    """The DataTables bundle (an ES module: DataTables 2 with its extensions) and its CSS,
    packed, read from the installed ``itables`` package (never copied into this repository)."""
    folder = resources.files("itables") / "html"
    return (packed((folder / "dt_bundle.js").read_text(encoding="utf-8")),
            packed((folder / "dt_bundle.css").read_text(encoding="utf-8")))
