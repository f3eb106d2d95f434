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

import functools
from typing import Any

import plotly.io as pio
from jinja2 import Environment, PackageLoader, select_autoescape
from plotly.offline import get_plotlyjs

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
    """The Jinja environment of every page (autoescaping on, templates in ``report/templates``)."""
    return Environment(loader=PackageLoader("crosscheck.report", "templates"),
                       autoescape=select_autoescape(default=True, default_for_string=True))


@functools.cache
def plotly_template() -> dict[str, Any]:
    """The plotly template of every chart (``plotly_white``), as a plain dict."""
    return dict(pio.templates["plotly_white"].to_plotly_json())


def plot_div(figure: dict[str, Any], div_id: str) -> str:
    """A figure as a ``<div>`` and its script, without plotly.js (the page inlines it once).

    Figures are plain dicts rendered without validation: ``go.Figure`` costs ~0.2-0.5 s each.
    """
    return str(pio.to_html(figure, full_html=False, include_plotlyjs=False, validate=False,
                           div_id=div_id, config=PLOT_CONFIG))


def plotly_js() -> str:
    """The plotly.js bundle, to inline once in the page head."""
    return str(get_plotlyjs())
