"""The speed-against-error chart reads at a glance: a scale-free error axis clipped to a fixed
range with off-scale answers counted, one panel per quantity, an accuracy line, and labels
that do not overlap in the figure's layout."""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from crosscheck.core.model import Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.report import speed_error
from crosscheck.results.run import read_results
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from crosscheck.truth.bounds import bound, length_magnitude
from tests import fakes
from tests.conftest import sphere


def record(case_id: str, engine: str, quantity: str, error: float, tolerance: float,
           kind: str = "sphere", query_s: float = 1e-5) -> Record:
    status = Status.AGREE if error <= tolerance else Status.DISAGREE
    return Record(case_id=case_id, source="cases/x.toml", kind=kind, dim=3, tags="",
                  engine=engine, quantity=quantity, value="0.0", truth="0.0", error=error,
                  tolerance=tolerance, status=status, category="", reason="", setup_s=1e-6,
                  query_s=query_s, query_iqr_s=0.0, loops=1, unstable=False)


def info(names: list[str]) -> RunInfo:
    return RunInfo(run_id="t", command="t", options=RunOptions(), machine={}, started="",
                   engines=tuple({"name": name} for name in names))


def chart_of(rows: list[Record], kind: str = "sphere") -> speed_error.SpeedChart:
    names = list(dict.fromkeys(r.engine for r in rows))
    return speed_error.speed_chart(pd.DataFrame([r.row() for r in rows]), kind, info(names), {})


def test_same_relative_error_plots_the_same_on_bodies_of_any_size() -> None:
    small, large = sphere(0.0, 3e-6, 1e-6, 1e-6, id="small"), sphere(0.0, 3e6, 1e6, 1e6,
                                                                     id="large")
    rows = []
    for case, engine in ((small, "on-small"), (large, "on-large")):
        tolerance = bound(case, "distance")  # the oracle's float64 bound of the case
        error = 1e-9 * length_magnitude(case)  # the same error relative to the case's size
        rows += [record(case.id, engine, "hit", 0.0, 0.0),
                 record(case.id, engine, "distance", error, tolerance)]
    points = {p.engine: p.errors["distance"].median for p in chart_of(rows).points}
    assert points["on-small"] == pytest.approx(points["on-large"], rel=1e-9)
    assert 1e6 < points["on-small"] < 1e7  # 1e-9 of the size is ~1e6 float64 bounds


def test_the_same_absolute_error_plots_apart_by_the_ratio_of_the_sizes(tmp_path: Path) -> None:
    cases = [sphere(0.0, 3.0, id="unit"), sphere(0.0, 3e6, 1e6, 1e6, id="big")]
    options = RunOptions(min_sample_s=0.001, samples=3, isolate=False)
    folder = tmp_path / "run"
    engines = [fakes.OffByOne()]  # a distance always 1.0 too large
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    frame = read_results(folder)
    per_case = {c.id: speed_error.speed_chart(frame[frame["case_id"] == c.id], "sphere",
                                         info(["fake-off"]), {}).points[0]
                for c in cases}
    unit, big = (per_case[c].errors["distance"].median for c in ("unit", "big"))
    assert unit / big == pytest.approx(length_magnitude(cases[1]) / length_magnitude(cases[0]))


def test_an_answer_of_minus_1_8e308_is_clipped_to_the_ceiling_and_counted() -> None:
    rows = [r for i, error in enumerate((1e-16, 2e-16, 1.8e308, math.inf))
            for r in (record(f"c{i}", "wild", "hit", 0.0, 0.0),
                      record(f"c{i}", "wild", "distance", error, 4e-16),
                      record(f"c{i}", "wild", "normal", 0.0, 1.7e-15))]
    chart = chart_of(rows)
    errors = chart.points[0].errors["distance"]
    assert (errors.off, errors.scored, chart.off_scale("distance")) == (2, 4, 2)
    assert chart.off_scale("normal") == 0
    fig = speed_error.figure(chart, ["wild"]).to_plotly_json()
    layout = fig["layout"]
    assert layout["yaxis"]["range"] == [math.log10(speed_error.FLOOR) - speed_error.PAD,
                                        math.log10(speed_error.CEILING) + speed_error.PAD]
    top = fig["data"][1]  # the largest error: on the ceiling, as an arrow
    assert list(top["y"]) == [speed_error.CEILING]
    assert top["marker"]["symbol"] == speed_error.OFF_SYMBOL
    assert "2 off scale" in fig["data"][0]["hovertext"][0]
    notes = {(a["text"], a["yref"]) for a in layout["annotations"]}
    assert (speed_error.off_label(2), "y") in notes and (speed_error.off_label(0), "y2") in notes
    drawn = [y for t in fig["data"] if t["type"] == "scatter" for y in t["y"]]
    assert all(speed_error.FLOOR <= y <= speed_error.CEILING for y in drawn)


def test_one_panel_per_quantity_and_the_verdicts_apart() -> None:
    detection = chart_of([r for q, tol in (("hit", 0.0), ("distance", 1e-9), ("normal", 1e-9))
                          for r in [record("c", "e", q, 0.0, tol)]])
    response = chart_of([record("r", "e", q, 1e-6, 1e-9, kind="sphere_response")
                         for q in ("v1", "v2")], kind="sphere_response")
    for chart, titles in ((detection, ["signed distance", "normal (angle)", "wrong hit verdicts"]),
                          (response, ["velocity v1", "velocity v2",
                                      "cases with a velocity beyond tolerance"])):
        fig = speed_error.figure(chart, ["e"]).to_plotly_json()
        panels = {t.get("xaxis", "x") for t in fig["data"] if t["type"] == "scatter"}
        assert panels == {"x", "x2"}
        assert [a["text"] for a in fig["layout"]["annotations"][:3]] == titles
        assert [t.get("xaxis") for t in fig["data"] if t["type"] == "bar"] == ["x3"]


# --- labels never overlap -------------------------------------------------------------------

WIDTHS = (900, 1400)
"""Page widths at which the chart is laid out (a laptop and the browser test's window)."""


def plain(text: str) -> list[str]:
    """The lines of a label as they show (tags removed)."""
    return [re.sub(r"<[^>]+>", "", line) for line in text.split("<br>")]


def box(note: dict[str, Any], layout: dict[str, Any], width: int) -> tuple[float, ...]:
    """An estimate of a label's box in pixels (x0, y0, x1, y1): glyphs 0.62 of the font size
    wide, lines 1.3 high, placed by its anchors on the axes' domains and ranges."""
    margin, size = layout["margin"], note.get("font", {}).get("size", 16)
    inner = (width - margin["l"] - margin["r"], layout["height"] - margin["t"] - margin["b"])
    xdomain = [0.0, 1.0] if note["xref"] == "paper" else \
        layout[f"xaxis{note['xref'].split()[0][1:]}"]["domain"]
    x = margin["l"] + inner[0] * (xdomain[0] + note["x"] * (xdomain[1] - xdomain[0]))
    if note["yref"] == "paper":
        y = note["y"]
    else:
        yaxis = layout[f"yaxis{note['yref'][1:]}"]
        low, high = yaxis["range"]
        y = yaxis["domain"][0] + (note["y"] - low) / (high - low) * (
            yaxis["domain"][1] - yaxis["domain"][0])
    y = margin["t"] + inner[1] * (1 - y)
    lines = plain(note["text"])
    w, h = 0.62 * size * max(map(len, lines)), 1.3 * size * len(lines)
    x0 = {"left": x, "right": x - w, "center": x - w / 2}[note.get("xanchor", "center")]
    y0 = {"top": y, "bottom": y - h, "middle": y - h / 2}[note.get("yanchor", "middle")]
    return x0, y0, x0 + w, y0 + h


def x_titles(layout: dict[str, Any]) -> list[dict[str, Any]]:
    """Each x axis title as a label: centred under its panel, a tick label's height below."""
    return [{"text": axis["title"]["text"], "xref": f"x{name[5:]} domain", "x": 0.5,
             "yref": "paper", "y": -0.06, "xanchor": "center", "yanchor": "top",
             "font": {"size": 12}}
            for name, axis in layout.items() if name.startswith("xaxis")
            and axis.get("title", {}).get("text")]


def overlap(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def many(kind: str, quantities: tuple[str, ...]) -> speed_error.SpeedChart:
    """Fifteen engines with errors across the whole axis, off scale ones among them."""
    errors = (0.0, 1e-20, 1e-15, 1e-9, 1e-3, 1.0, 1e300, math.inf)
    return chart_of([record(f"c{i}", f"engine-{e}", q, errors[(e + i) % len(errors)], 1e-15,
                            kind, 1e-6 * (1 + e))
                     for e in range(15) for i in range(3) for q in quantities], kind)


@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize(("kind", "quantities"), [("sphere", ("hit", "distance", "normal")),
                                                  ("sphere_response", ("v1", "v2"))])
def test_labels_do_not_overlap(kind: str, quantities: tuple[str, ...], width: int) -> None:
    chart = many(kind, quantities)
    assert chart.off_scale(chart.measure.errors[0]) > 0
    layout = speed_error.figure(chart, []).to_plotly_json()["layout"]
    labels = [*layout["annotations"], *x_titles(layout)]
    boxes = [box(note, layout, width) for note in labels]
    assert len(boxes) == 3 + 3 * 2 + 2  # the panels' titles; floor, ceiling, accuracy per
    # panel; the time axes' titles
    for (i, a), (j, b) in itertools.combinations(enumerate(boxes), 2):
        assert not overlap(a, b), (labels[i]["text"], labels[j]["text"])
    assert layout["yaxis3"]["side"] == "right"  # the verdict bars' engine names: in the margin


def test_the_overlap_check_can_fail() -> None:
    layout = speed_error.figure(many("sphere", ("hit", "distance")), []).to_plotly_json()["layout"]
    floor, *_ = (n for n in layout["annotations"] if n["text"] == speed_error.FLOOR_TEXT)
    near = {**floor, "text": "another label", "y": floor["y"] + 0.2}
    assert overlap(box(floor, layout, 900), box(near, layout, 900))
