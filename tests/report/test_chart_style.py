"""One chart style across the report: log axes, floor and ceiling, coincident points, scene dt
labels and step-aligned impacts, on figures built from small synthetic frames."""

from __future__ import annotations

import itertools
import math
import re
from typing import Any

import pandas as pd
import pytest

from crosscheck.core.model import Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, SceneCase
from crosscheck.report import axes, dynamics, speed_error, stability, style
from crosscheck.report.stability import charts as stability_charts
from crosscheck.results.run import decoded
from crosscheck.results.runinfo import RunInfo
from crosscheck.truth import scenes

POWER = re.compile(r"^(1|10|10<sup>\u2212?\d+</sup>)$")
"""A decade tick as plotly's ``exponentformat="power"`` writes it."""


def log_axes(layout: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Every log axis of a figure's layout, by name."""
    return {name: axis for name, axis in layout.items()
            if re.fullmatch(r"[xy]axis\d*", name) and axis.get("type") == "log"}


def assert_one_style(layout: dict[str, Any]) -> None:
    """Every log axis: power format, decade ticks (plus 0 and inf), a title; the template's
    axes in the power format too."""
    found = log_axes(layout)
    assert found
    for name, axis in found.items():
        assert axis["exponentformat"] == "power", name
        assert axis["ticktext"], name
        for text, value in zip(axis["ticktext"], axis["tickvals"], strict=True):
            assert POWER.match(text) or text in ("0", "inf"), (name, text)
            if POWER.match(text):
                assert math.log10(value) == round(math.log10(value)), (name, value)
        if name in ("xaxis", "yaxis", "xaxis1", "yaxis1"):  # later panels share the first's
            assert axis["title"]["text"], name
    for name in ("xaxis", "yaxis"):
        assert layout["template"]["layout"][name]["exponentformat"] == "power"


def annotations(layout: dict[str, Any]) -> list[str]:
    return [str(a.get("text", "")) for a in layout.get("annotations", [])]


# --- the shared pieces ----------------------------------------------------------------------


def test_power_ticks_match_plotlys_power_format() -> None:
    assert [axes.power(k) for k in (-18, -1, 0, 1, 3)] == [
        "10<sup>\u221218</sup>", "10<sup>\u22121</sup>", "1", "10", "10<sup>3</sup>"]
    axis = axes.log_axis("t", -6.0, -4.0)
    assert axis["ticktext"] == ["10<sup>\u22126</sup>", "10<sup>\u22125</sup>",
                                "10<sup>\u22124</sup>"]


def test_floor_and_ceiling_ticks_keep_clear_of_decades() -> None:
    axis = axes.log_axis("e", -29.5, 2.5, floor=1e-29, ceiling=100.0)
    assert axis["ticktext"][0] == "0" and axis["ticktext"][-1] == "inf"
    exponents = [round(math.log10(v)) for v in axis["tickvals"][1:-1]]
    assert exponents and min(exponents) >= -28 + 1 and max(exponents) <= 2 - 1


def test_coincident_points_are_grouped_and_spread_apart() -> None:
    points = [(2e-6, 1e-12), (2e-6, 1e-12), (2.02e-6, 1e-12), (1e-4, 1e-12), (2e-6, 1e-3)]
    groups = axes.coincident(points, (2.0, 10.0))
    assert sorted(map(sorted, groups)) == [[0, 1, 2], [3], [4]]
    xs = axes.spread([x for x, _ in points], groups, 2.0)
    assert len({xs[0], xs[1], xs[2]}) == 3  # pulled apart
    assert xs[3] == 1e-4 and xs[4] == 2e-6  # points alone stay put
    logs = sorted(math.log10(xs[i]) for i in (0, 1, 2))
    assert all(b - a == pytest.approx(axes.STEP * 2.0) for a, b in itertools.pairwise(logs))


# --- speed against error --------------------------------------------------------------------


def row(case_id: str, engine: str, quantity: str, error: float, query_s: float,
        kind: str = "sphere") -> Record:
    status = Status.AGREE if error == 0 else Status.DISAGREE
    return Record(case_id=case_id, source="cases/x.toml", kind=kind, dim=3, tags="",
                  engine=engine, quantity=quantity, value="0.0", truth="0.0", error=error,
                  tolerance=1e-9, status=status, category="", reason="", setup_s=1e-6,
                  query_s=query_s, query_iqr_s=0.0, loops=1, unstable=False)


SPEED = {  # engine: distance errors of three cases, query time
    "tuned": ((0.0, 1e-12, 1e-9), 2e-6), "tuned-default": ((0.0, 1e-12, 1e-9), 2e-6),
    "exact": ((0.0, 0.0, 0.0), 1e-5), "slow": ((1e-3, 1e-3, math.inf), 1e-4)}


def speed_info() -> RunInfo:
    return RunInfo(run_id="t", command="t", options=RunOptions(), machine={}, started="",
                   engines=tuple({"name": name} for name in SPEED))


@pytest.fixture(scope="module")
def speed_figure() -> tuple[speed_error.SpeedChart, dict[str, Any]]:
    rows = [row(f"s{i}", engine, quantity, error if quantity == "distance" else 0.0, query_s)
            for engine, (errors, query_s) in SPEED.items()
            for i, error in enumerate(errors) for quantity in ("hit", "distance", "normal")]
    chart = speed_error.speed_chart(pd.DataFrame([r.row() for r in rows]), "sphere", speed_info(),
                               {})
    return chart, speed_error.figure(chart, list(SPEED)).to_plotly_json()


def test_speed_log_axes_share_the_style(speed_figure: tuple[Any, dict[str, Any]]) -> None:
    _, fig = speed_figure
    assert set(log_axes(fig["layout"])) == {"xaxis", "yaxis", "xaxis2", "yaxis2"}  # 2 panels
    assert_one_style(fig["layout"])
    assert "(s)" in fig["layout"]["xaxis"]["title"]["text"]  # time axis with its unit
    assert "float64 bound" in fig["layout"]["yaxis"]["title"]["text"]  # what one unit is


def test_speed_floor_and_ceiling_are_labelled(speed_figure: tuple[Any, dict[str, Any]]) -> None:
    chart, fig = speed_figure
    notes = [(a["text"], a["y"], a["yref"]) for a in fig["layout"]["annotations"]]
    for yref, quantity in (("y", "distance"), ("y2", "normal")):
        assert (speed_error.FLOOR_TEXT, math.log10(speed_error.FLOOR), yref) in notes
        label = speed_error.off_label(chart.off_scale(quantity))
        assert (label, math.log10(speed_error.CEILING), yref) in notes
    assert speed_error.off_label(1) == "off scale (above 10<sup>15</sup>): 1 answer"
    assert chart.off_scale("distance") == 1 and chart.off_scale("normal") == 0  # slow's inf
    lines = {(s["y0"], s["yref"]) for s in fig["layout"]["shapes"]}
    floor, ceiling = speed_error.FLOOR, speed_error.CEILING
    assert {(floor, "y"), (ceiling, "y"), (floor, "y2")} <= lines


def test_speed_coincident_engines_are_drawn_apart_and_named_in_the_hover(
        speed_figure: tuple[Any, dict[str, Any]]) -> None:
    chart, fig = speed_figure
    points = {t["legendgroup"]: t for t in fig["data"]
              if t["type"] == "scatter" and t.get("showlegend") is True}
    tuned, default = points["tuned"], points["tuned-default"]
    assert tuned["y"] == default["y"]  # the error axis keeps the true values
    assert tuned["x"][0] != default["x"][0]
    true_x = {p.engine: p.query_s for p in chart.plotted}["tuned"]
    assert abs(math.log10(tuned["x"][0] / true_x)) < 0.1  # a few per cent of the axis
    assert points["slow"]["x"][0] == {p.engine: p.query_s for p in chart.plotted}["slow"]
    assert "2 µs" in tuned["hovertext"][0] and "2 µs" in default["hovertext"][0]
    assert "drawn beside (same spot): tuned-default" in tuned["hovertext"][0]
    named = [t for t in annotations(fig["layout"]) if "tuned" in t or "slow" in t]
    assert named == []  # engines are named in the legend and the hover, never in labels


def test_speed_accuracy_is_a_labelled_line_on_every_panel(
        speed_figure: tuple[Any, dict[str, Any]]) -> None:
    chart, fig = speed_figure
    drawn = [(a["text"], a["y"]) for a in fig["layout"]["annotations"]]
    assert drawn.count(("accuracy: the float64 bound", 0.0)) == 2  # 1 bound, on both panels
    moved = speed_error.figure(chart, list(SPEED), accuracy={"distance": 1e6}).to_plotly_json()
    texts = {a["text"]: a["y"] for a in moved["layout"]["annotations"]}
    assert texts["accuracy: 1e+06 \u00d7 the float64 bound"] == 6.0
    assert texts["accuracy: the float64 bound"] == 0.0  # the normal panel keeps the default
    assert (1e6, "y") in {(s["y0"], s["yref"]) for s in moved["layout"]["shapes"]}


# --- dynamics -------------------------------------------------------------------------------


def scene(dt: float, right: float) -> SceneCase:
    """Two equal discs at -2 and ``right`` closing at 2: contact at t = (right + 1) / 2."""
    made = CASE_ADAPTER.validate_python({
        "id": f"s.dt={dt:g}", "description": "d", "kind": "sphere_scene", "dim": 2,
        "duration": 3.0, "dt": dt, "bodies": [
            {"center": [-2.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [1.0, 0.0]},
            {"center": [right, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [-1.0, 0.0]}]})
    assert isinstance(made, SceneCase)
    return made.model_copy(update={"origin": "s"})


def scene_rows(case: SceneCase, engine: str, error: float, wall: float) -> list[Record]:
    return [Record(case_id=case.id, source="x", kind="sphere_scene", dim=2, tags="",
                   engine=engine, quantity=q, value="1.0", truth="1.0",
                   error=error if q == "positions" else 0.0, tolerance=1e-9,
                   status=Status.AGREE if error == 0 else Status.DISAGREE, category="",
                   reason="", setup_s=0.0, query_s=wall, query_iqr_s=0.0, loops=1,
                   unstable=False, origin="s")
            for q in ("positions", "velocities", "momentum", "energy")]


ON_STEP, OFF_STEP = 0.1, 0.07
"""With the right disc at 2.0 the contact is at t = 1.5: a multiple of 0.1, not of 0.07."""


SCENE_RUNS = {  # engine: wall seconds per step, position error per dt
    "e": (1e-6, {ON_STEP: 0.0, OFF_STEP: 0.03, 0.01: 0.004}),
    "e-default": (1e-6, {ON_STEP: 0.0, OFF_STEP: 0.03, 0.01: 0.004}),
    "other": (1e-4, {ON_STEP: math.inf, OFF_STEP: 0.5, 0.01: 0.2})}


def scene_run() -> tuple[pd.DataFrame, dict[str, AnyCase]]:
    """The rows and cases of SCENE_RUNS on one scene at three time steps."""
    made = (scene(ON_STEP, 2.0), scene(OFF_STEP, 2.0), scene(0.01, 2.0123456789))
    records = [r for case in made for engine, (per_step, errors) in SCENE_RUNS.items()
               for r in scene_rows(case, engine, errors[case.dt or 0.0],
                                   per_step * case.step_count)]
    frame = pd.DataFrame([r.row() for r in records])
    return frame.join(decoded(frame)), {c.id: c for c in made}


@pytest.fixture(scope="module")
def scene_figure() -> tuple[pd.DataFrame, dict[str, Any]]:
    points = dynamics.scene_points(*scene_run())
    (chart,) = dynamics.charts(points, list(SCENE_RUNS))
    assert chart["aligned"] == len(SCENE_RUNS) and 'id="dyn-s"' in chart["html"]
    return points, dynamics.figure(points, "s", {n: i for i, n in enumerate(SCENE_RUNS)})


def test_scene_alignment_comes_from_the_exact_run() -> None:
    on, off = scene(ON_STEP, 2.0), scene(OFF_STEP, 2.0)
    impacts = scenes.truth(on).impacts or ()
    assert len(impacts) == 1 and impacts[0] == pytest.approx(1.5)
    assert scenes.aligned(on, impacts) and not scenes.aligned(off, impacts)


def test_dynamics_log_axes_share_the_style(scene_figure: tuple[Any, dict[str, Any]]) -> None:
    _, fig = scene_figure
    assert set(log_axes(fig["layout"])) == {"xaxis", "yaxis"}
    assert_one_style(fig["layout"])


def test_dynamics_direction_is_lower_left_like_the_speed_charts(
        scene_figure: tuple[pd.DataFrame, dict[str, Any]]) -> None:
    points, fig = scene_figure
    assert "lower left is better" in fig["layout"]["title"]["text"]
    assert "wall time per simulated second" in fig["layout"]["xaxis"]["title"]["text"]
    # the faster run (smaller wall time for the same simulated time) is drawn further left
    traces = {t["name"]: t for t in fig["data"]}
    slow, fast = traces["other"], traces["e"]
    assert max(fast["x"]) < min(slow["x"])
    assert (points["cost"] * points["rtf"]).round(12).eq(1.0).all()


def test_scene_points_carry_their_dt_as_text(scene_figure: tuple[Any, dict[str, Any]]) -> None:
    points, fig = scene_figure
    shown = {text for t in fig["data"] for text in t["text"] if text}
    for dt in points["dt"]:
        assert any(t.startswith(dynamics.dt_label(dt)) for t in shown), dt
    assert dynamics.dt_label(1 / 240) == "dt 1/240 s" and dynamics.dt_label(0.01) == "dt 10 ms"


def test_scene_floor_and_ceiling_are_labelled(scene_figure: tuple[Any, dict[str, Any]]) -> None:
    _, fig = scene_figure
    notes = annotations(fig["layout"])
    assert axes.FLOOR_LABEL in notes and "no value or infinite error" in notes
    axis = fig["layout"]["yaxis"]
    assert axis["ticktext"][0] == "0" and axis["ticktext"][-1] == "inf"
    ys = {y for t in fig["data"] for y in t["y"]}
    assert {axis["tickvals"][0], axis["tickvals"][-1]} <= ys  # 0 and inf drawn there


def test_aligned_scene_point_is_flagged(scene_figure: tuple[pd.DataFrame, dict[str, Any]]) -> None:
    points, fig = scene_figure
    assert points.loc[points["dt"] == ON_STEP, "aligned"].map(bool).all()
    assert not points.loc[points["dt"] != ON_STEP, "aligned"].map(bool).any()
    for trace in fig["data"]:
        for symbol, text, hover in zip(trace["marker"]["symbol"], trace["text"],
                                       trace["hovertext"], strict=True):
            flagged = "dt = 0.1 s" in hover
            assert (symbol == dynamics.ALIGNED_SYMBOL) == flagged
            assert ("step boundary" in hover) == flagged
            assert not text or ("on a step" in text) == flagged
    assert dynamics.ALIGNED_NOTE in annotations(fig["layout"])


def test_dynamics_coincident_variants_are_drawn_apart(
        scene_figure: tuple[pd.DataFrame, dict[str, Any]]) -> None:
    _, fig = scene_figure
    traces = {t["name"]: t for t in fig["data"]}
    one, two = traces["e"], traces["e-default"]
    assert one["y"] == two["y"]
    assert all(a != b for a, b in zip(one["x"], two["x"], strict=True))
    assert all("drawn beside e-default" in h for h in one["hovertext"])
    # one dt label for the pair drawn side by side, not two on top of each other
    for a, b in zip(one["text"], two["text"], strict=True):
        assert bool(a) != bool(b)


def test_dynamics_caption_gives_the_direction_and_the_flagged_runs() -> None:
    section = dynamics.section(*scene_run(), list(SCENE_RUNS))
    page = style.templates().from_string("{% include '_dynamics.html.j2' %}").render(
        dynamics=section)
    assert "<b>Lower left is better: faster and more accurate</b>" in page
    assert f"<b>{len(SCENE_RUNS)} run(s) here are\nflagged so.</b>" in page
    assert "<b>A circled x</b> marks a run where an impact" in page


# --- stability ------------------------------------------------------------------------------


def sweep_rows(engine: str, errors: list[float], statuses: list[str]) -> list[dict[str, Any]]:
    return [{"sweep": "sweep-gap", "axis": stability.AXES["gap"], "param": "gap", "value": v,
             "direction": "smaller", "kind": "sphere", "dim": 3, "engine": engine,
             "quantity": "distance", "status": s, "category": "", "error": e, "rel_error": e,
             "rel_tolerance": 1e-12, "case_id": f"gap-{v:g}"}
            for v, e, s in zip((1e-1, 1e-4, 1e-8, 1e-12), errors, statuses, strict=True)]


@pytest.fixture(scope="module")
def sweep_figure() -> dict[str, Any]:
    same = [0.0, 1e-16, 1e-13, 1e-9]
    statuses = ["agree", "agree", "disagree", "disagree"]
    rows = (sweep_rows("a", same, statuses) + sweep_rows("a-default", same, statuses)
            + sweep_rows("b", [1e-15, 1e-14, math.nan, math.inf],
                         ["agree", "agree", "crash", "disagree"]))
    return stability_charts.figure(pd.DataFrame(rows), "distance", ["a", "a-default", "b"])


def test_stability_log_axes_share_the_style(sweep_figure: dict[str, Any]) -> None:
    assert set(log_axes(sweep_figure["layout"])) == {"xaxis1", "yaxis1"}
    assert_one_style(sweep_figure["layout"])
    assert "lower is better" in sweep_figure["layout"]["yaxis1"]["title"]["text"]


def test_stability_floor_and_ceiling_are_labelled(sweep_figure: dict[str, Any]) -> None:
    notes = annotations(sweep_figure["layout"])
    assert axes.FLOOR_LABEL in notes and "failed or infinite error" in notes


def test_stability_coincident_engines_are_drawn_apart(sweep_figure: dict[str, Any]) -> None:
    traces = {t["name"]: t for t in sweep_figure["data"]}
    one, two, other = traces["a"], traces["a-default"], traces["b"]
    assert one["y"] == two["y"]
    assert all(x != y for x, y in zip(one["x"], two["x"], strict=True))
    assert sorted(other["x"]) == [1e-12, 1e-8, 1e-4, 1e-1]  # nobody beside b: true values
    assert "drawn beside a-default" in one["hovertext"][0]


def test_every_chart_uses_the_shared_template() -> None:
    template = style.plotly_template()
    assert template["layout"]["xaxis"]["exponentformat"] == "power"
    assert template["layout"]["yaxis"]["showline"] is True
    assert template["layout"]["plot_bgcolor"] == "white"
