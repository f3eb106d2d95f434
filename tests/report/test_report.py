"""The HTML report: speed-against-error charts, case-group matrix, self-containment, escaping."""

from __future__ import annotations

import base64
import gzip
import json
import math
import re
from collections.abc import Iterable
from dataclasses import asdict, replace
from html.parser import HTMLParser
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pandas as pd
import pytest

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.report import render as report
from crosscheck.report import speed, speed_error, style, summary_tables, text
from crosscheck.results.run import read_results
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.store import ResultsStore
from crosscheck.results.timings import FILE, TimingRecord
from crosscheck.run.launch import launch, new_info
from crosscheck.truth.bounds import bound
from tests import fakes
from tests.conftest import sphere

EVIL = "<script>alert('pwned')</script>"
NEAR, TRAPS = "cases/near_touching.toml", "cases/float_traps.toml"


def rec(case_id: str, engine: str, quantity: str, status: str = "agree", error: float = 0.0,
        query_s: float = 1e-5, kind: str = "sphere", source: str = NEAR) -> Record:
    return Record(case_id=case_id, source=source, kind=kind, dim=3, tags="", engine=engine,
                  quantity=quantity, value="0.0", truth="0.0", error=error, tolerance=1e-9,
                  status=Status(status), category="", reason="", setup_s=1e-6, query_s=query_s,
                  query_iqr_s=0.0, loops=1, unstable=False)


def detection(case_id: str, engine: str, distance: float, query_s: float,
              source: str = NEAR, hit: str = "agree", normal: float = 0.0) -> list[Record]:
    """hit, distance and normal rows of one sphere case; an error above 1e-9 is a disagree."""
    def status(error: float) -> str:
        return "agree" if error <= 1e-9 else "disagree"
    hit_error = 0.0 if hit == "agree" else 1.0
    return [rec(case_id, engine, "hit", hit, hit_error, query_s, source=source),
            rec(case_id, engine, "distance", status(distance), distance, query_s, source=source),
            rec(case_id, engine, "normal", status(normal), normal, query_s, source=source)]


def every(case_id: str, engine: str, status: str, source: str = TRAPS) -> list[Record]:
    return [rec(case_id, engine, q, status, math.nan, math.nan, source=source)
            for q in ("hit", "distance", "normal")]


FAST = [  # per case: distance error, query time, case file, hit status, normal error
    ("s1", 0.0, 1e-6, NEAR, "agree", 0.5), ("s2", 1e-12, 2e-6, NEAR, "agree", 0.0),
    ("s3", 2e-12, 3e-6, TRAPS, "agree", 0.0), ("s4", 5e-3, 4e-6, TRAPS, "agree", 0.0),
    ("s5", 1.0, 1e-4, TRAPS, "disagree", 0.0),
]


def records() -> list[Record]:
    rows = [r for case_id, distance, query_s, source, hit, normal in FAST
            for r in detection(case_id, "fast", distance, query_s, source, hit, normal)]
    rows += [r for c, *_ in FAST for r in detection(c, "exact", 0.0, 5e-6)]
    rows += [r for c, *_ in FAST for r in detection(c, "untimed", 0.0, math.nan)]
    rows += [r for c, *_ in FAST for r in every(c, "skipper", "skip")]
    rows += [r for c in ("s3", "s4") for r in every(c, "crashy", "crash")]
    for case_id, v1, v2 in (("r1", 1e-3, 3e-3), ("r2", 0.0, 1e-9)):
        for quantity, err in (("v1", v1), ("v2", v2)):
            status = "agree" if err <= 1e-9 else "disagree"
            rows.append(rec(case_id, "fast", quantity, status, err, 2e-5, "sphere_response",
                            "cases/response.toml"))
    return rows


def write_run(directory: Path, rows: list[Record], settings: str = "default",
              timing: dict[str, Any] | None = None,
              timings: Iterable[TimingRecord] = ()) -> Path:
    """A run folder: results, run.json (with ``timing``), cases and ``timings.jsonl``."""
    store = ResultsStore(directory)
    store.append(rows)
    store.write_run_info(info_of(settings, timing))
    store.close()
    (directory / FILE).write_text("".join(t.to_json() + "\n" for t in timings))
    cases = [stored_case(r.case_id, r.kind, r.source) for r in rows
             if r.engine == "fast" and r.quantity in ("hit", "v1")]
    (directory / "cases.jsonl").write_text("".join(json.dumps(c) + "\n" for c in cases))
    return directory


@pytest.fixture
def rendered(tmp_path: Path) -> str:
    directory = write_run(tmp_path / "run", records(), settings=f"tuned {EVIL}")
    return report.render(directory)["report"].read_text(encoding="utf-8")


def info_of(settings: str = "default", timing: dict[str, Any] | None = None) -> RunInfo:
    """The run.json of the fake runs here: six fake engines, timed (``timing``: run.json's
    timing record, None as in a run without a timing phase)."""
    return RunInfo(
        run_id="test", command="test", started="", finished="", cases_run=7,
        options=RunOptions(quick=False, min_sample_s=0.001, samples=3),
        machine={"packages": {}}, timing=timing,
        engines=tuple({"name": name, "engine": "fake", "version": "0", "settings": settings,
                       "conventions": asdict(Conventions()), "capabilities": []}
                      for name in ("fast", "exact", "untimed", "skipper", "crashy", "noisy")))


NOISY = {("s1", "fast"), ("s1", "noisy"), ("s2", "noisy"), ("s4", "noisy")}
"""The unstable timings of :func:`timed`: fast 1 of 5, noisy 3 of 5 (mostly unstable)."""


def timed(rows: list[Record]) -> tuple[list[Record], list[TimingRecord]]:
    """The rows with their timing columns filled as the timing phase fills them, and the
    timing record of every timed case x engine: five samples around its query_s, spread
    2% of it, or 70% for the pairs in NOISY (unstable)."""
    made: dict[tuple[str, str], TimingRecord] = {}
    for r in rows:
        if not math.isnan(r.query_s) and (r.case_id, r.engine) not in made:
            noisy = (r.case_id, r.engine) in NOISY
            factors = (0.5, 0.8, 1.0, 1.5, 2.0) if noisy else (0.98, 0.99, 1.0, 1.01, 1.02)
            values = tuple(r.query_s * f for f in factors)
            made[r.case_id, r.engine] = TimingRecord(r.case_id, r.engine, r.kind, "call", 100,
                                                     2e-8, values)
    filled = [replace(r, query_iqr_s=t.spread.iqr, unstable=t.spread.unstable)
              if (t := made.get((r.case_id, r.engine))) else r for r in rows]
    return filled, list(made.values())


def stick(median: float) -> dict[str, Any]:
    """A stored yardstick measurement: median, quartiles (IQR 2% of it) and its samples."""
    return {"median_s": median, "q1_s": 0.99 * median, "q3_s": 1.01 * median,
            "values": [0.99 * median, median, 1.01 * median]}


def timing_info(python_end: float = 1.25e-3) -> dict[str, Any]:
    """run.json's timing record: the yardstick's Python loop ends ``python_end`` s from 1 ms."""
    return {
        "method": "30 cases per engine x kind drawn at random (seed 0); 5 samples each",
        "sampled": 17, "pinned": "engine worker on core 1, harness on core 0",
        "yardstick": {"start": {"numpy": stick(2e-3), "python": stick(1e-3)},
                      "end": {"numpy": stick(2.04e-3), "python": stick(python_end)}},
        "binding": {"fast": stick(1e-7), "exact": stick(5e-7), "noisy": stick(1e-6),
                    "untimed": {"none": "no cheap call"}}}


def timed_records() -> tuple[list[Record], list[TimingRecord]]:
    """records() plus a noisy engine, with their timing records."""
    noisy = [r for c, *_ in FAST for r in detection(c, "noisy", 1e-3, 8e-6)]
    return timed(records() + noisy)


def timed_run(directory: Path, timing: dict[str, Any] | None = None) -> Path:
    rows, timings = timed_records()
    return write_run(directory, rows, timing=timing or timing_info(), timings=timings)


def stored_case(case_id: str, kind: str, source: str) -> dict[str, Any]:
    """A valid stored case (cases.jsonl line) of ``kind``; s5's description is hostile text."""
    body: dict[str, Any] = {"center": [0.0, 0.0, 0.0], "radius": 0.5}
    if kind == "sphere_response":
        body |= {"mass": 1.0, "velocity": [1.0, 0.0, 0.0]}
    return {"id": case_id, "description": EVIL if case_id == "s5" else f"case {case_id}",
            "kind": kind, "dim": 3, "tags": [], "source": source, "a": body,
            "b": body | {"center": [2.0, 0.0, 0.0]}}


def described(**descriptions: str) -> dict[str, AnyCase]:
    """Typed cases with these descriptions, by id."""
    return {case_id: sphere(0.0, 2.0, id=case_id).model_copy(update={"description": text})
            for case_id, text in descriptions.items()}


def chart_of(frame: pd.DataFrame, kind: str, cases: dict[str, AnyCase] | None = None
             ) -> speed_error.SpeedChart:
    return speed_error.speed_chart(frame, kind, info_of(), cases or {})


def by_engine(chart: speed_error.SpeedChart) -> dict[str, speed_error.Point]:
    return {p.engine: p for p in chart.points}


FRAME = pd.DataFrame([r.row() for r in records()])


def test_one_point_per_engine_per_kind() -> None:
    made = speed_error.speed_charts(FRAME, info_of(), {})
    kinds = {c.kind: [p.engine for p in c.points] for c in made}
    assert kinds == {"sphere": ["fast", "exact", "untimed", "skipper", "crashy"],
                     "sphere_response": ["fast"]}


def test_x_is_median_query_time_per_case_and_y_median_error_per_quantity() -> None:
    fast = by_engine(chart_of(FRAME, "sphere"))["fast"]
    assert fast.query_s == pytest.approx(3e-6)  # median of five cases, not their mean
    assert fast.timed == fast.cases == 5
    distance, normal = fast.errors["distance"], fast.errors["normal"]
    assert distance.median == pytest.approx(2e-12 / 1e-9)  # in tolerances (1e-9 here)
    assert (distance.p95, distance.max, distance.zeros) == (1 / 1e-9, 1 / 1e-9, 1)
    assert (normal.median, normal.max, normal.zeros) == (0.0, pytest.approx(0.5 / 1e-9), 4)
    assert (fast.wrong, fast.verdicts) == (1, 5)


def test_x_deduplicates_case_engine_rows() -> None:
    # The slowest case repeated must not weigh more: its rows outnumber all others' here.
    slow = FRAME[(FRAME["case_id"] == "s5") & (FRAME["engine"] == "fast")]
    heavy = pd.concat([FRAME, *[slow] * 4])
    assert by_engine(chart_of(heavy, "sphere"))["fast"].query_s == pytest.approx(3e-6)


def test_error_stats_median_nearest_rank_95th_percentile_and_max() -> None:
    assert speed_error.error_stats(pd.Series([float(v) for v in range(20)])) == (9.5, 18.0, 19.0)
    assert speed_error.error_stats(pd.Series([1.0, 2.0, math.inf])) == (2.0, math.inf, math.inf)
    assert all(math.isnan(v) for v in speed_error.error_stats(pd.Series([], dtype=float)))


def test_response_errors_are_read_per_velocity() -> None:
    fast = by_engine(chart_of(FRAME, "sphere_response"))["fast"]
    assert fast.errors["v1"].median == pytest.approx(1e-3 / 2 / 1e-9)
    assert fast.errors["v2"].median == pytest.approx((3e-3 + 1e-9) / 2 / 1e-9)
    assert (fast.scored, fast.wrong, fast.verdicts) == (2, 1, 2)


def test_zero_errors_sit_at_the_labelled_floor() -> None:
    chart = chart_of(FRAME, "sphere")
    exact = by_engine(chart)["exact"]
    assert exact.errors["distance"].median == 0.0
    fig = speed_error.figure(chart, list(dict.fromkeys(FRAME["engine"])))
    drawn = {t.name: t.y[0] for t in fig.data if t.type == "scatter" and t.showlegend is True}
    assert drawn["exact"] == speed_error.FLOOR
    assert drawn["fast"] == pytest.approx(2e-3)
    assert sum(a.text == speed_error.FLOOR_TEXT for a in fig.layout.annotations) == 2  # per panel


def test_errors_below_the_floor_are_drawn_on_it() -> None:
    tiny = pd.DataFrame([r.row() for r in detection("s1", "a", 3e-21, 1e-6)
                         + detection("s2", "a", 0.0, 1e-6) + detection("s3", "a", 2e-9, 1e-6)])
    errors = by_engine(chart_of(tiny, "sphere"))["a"].errors["distance"]
    assert (errors.below, errors.zeros, errors.off) == (2, 1, 0)
    assert speed_error.SpeedChart.y(3e-21 / 1e-9) == speed_error.FLOOR
    assert speed_error.SpeedChart.y(2.0) == 2.0


def test_infinite_errors_sit_at_the_ceiling_counted() -> None:
    rows = [r for c, err in (("s1", 1e-9), ("s2", 1e-9), ("s3", math.inf))
            for r in detection(c, "a", err, 1e-6)]
    chart = chart_of(pd.DataFrame([r.row() for r in rows]), "sphere")
    assert chart.y(math.inf) == speed_error.CEILING and chart.off_scale("distance") == 1
    fig = speed_error.figure(chart, ["a"])
    whisker_top = fig.data[0].y[0] + fig.data[0].error_y.array[0]
    assert fig.data[0].y[0] == pytest.approx(1.0) and whisker_top == speed_error.CEILING
    assert fig.data[1].y[0] == speed_error.CEILING
    assert fig.data[1].marker.symbol == speed_error.OFF_SYMBOL
    assert speed_error.off_label(1) in [a.text for a in fig.layout.annotations]
    assert "1 off scale" in fig.data[0].hovertext[0]


def test_untimed_and_unscored_engines_are_listed_not_plotted(rendered: str) -> None:
    chart = chart_of(FRAME, "sphere")
    assert [p.engine for p in chart.plotted] == ["fast", "exact"]
    assert [p.engine for p in chart.not_timed] == ["untimed"]
    assert [p.engine for p in chart.not_scored] == ["skipper", "crashy"]
    listed = rendered.split("<b>Not timed</b>")[1].split("</li>")[0]
    assert "untimed" in listed and "fast" not in listed


def test_quick_run_draws_no_chart_and_inlines_no_plotly(tmp_path: Path) -> None:
    quick = [r for r in records() if r.engine != "fast"]
    quick = [Record(**{**r.row(), "status": r.status, "query_s": math.nan}) for r in quick]
    html = report.render(write_run(tmp_path / "q", quick))["report"].read_text()
    assert FIGURE not in html and "* plotly.js" not in html
    assert 'id="plotly-js"' not in html
    speed = part(html, '<h2>Speed against error</h2>', "</section>")
    assert "Nothing to draw." in speed and "<details" not in speed  # one line, no open fold


def test_case_group_matrix_counts() -> None:
    counts = summary_tables.group_counts(FRAME).set_index(["engine", "group"])
    assert counts.loc[("fast", "float_traps"), ["agree", "disagree"]].tolist() == [6, 3]
    assert counts.loc[("fast", "near_touching"), ["agree", "disagree"]].tolist() == [5, 1]
    assert counts.loc[("crashy", "float_traps"), "crash"] == 6
    matrix = summary_tables.group_matrix(FRAME)
    assert [g["name"] for g in matrix["groups"]] == ["near_touching", "float_traps", "response"]
    assert [g["cases"] for g in matrix["groups"]] == [2, 3, 2]
    cells = {row["engine"]: row["cells"] for row in matrix["rows"]}
    fast_traps = cells["fast"][1]
    assert (fast_traps["agree"], fast_traps["scored"]) == (6, 9)
    assert cells["crashy"][1]["failed"] == {"crash": 6} and cells["crashy"][1]["share"] == 0.0
    assert cells["skipper"][1]["skipped"] and cells["skipper"][1]["share"] is None
    assert cells["skipper"][1]["colour"] == summary_tables.share_colour(None)
    assert cells["fast"][0]["share"] == pytest.approx(5 / 6)
    colour = summary_tables.share_colour
    assert cells["exact"][0]["colour"] == colour(1.0) != colour(0.0)


def test_matrix_cells_are_rendered(rendered: str) -> None:
    matrix = rendered.split('id="matrix"')[1].split("</table>")[0]
    assert "<b>6 / 9</b>" in matrix and "<small>6 crash</small>" in matrix
    assert "skipped" in matrix and "float_traps" in matrix


class _Tags(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.fetching: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        found = dict(attrs)
        for name in ("src", "href"):
            url = found.get(name) or ""
            if tag in ("script", "link", "img", "iframe") and url and not url.startswith("#"):
                self.fetching.append(f"{tag} {name}={url}")


def packed_scripts(html: str) -> dict[str, str]:
    """The page's packed payloads (gzip + base64 in octet-stream scripts), unpacked, by id."""
    found = re.findall(r'<script type="application/octet-stream" id="([^"]+)">([^<]*)</script>',
                       html)
    return {name: gzip.decompress(base64.b64decode(text)).decode() for name, text in found}


FIGURE = '<script type="application/octet-stream" class="plotly-figure"'
"""A chart's packed figure, drawn by the page's one script."""


def test_report_is_self_contained_with_plotly_once(rendered: str) -> None:
    payloads = packed_scripts(rendered)
    assert payloads["plotly-js"] == style.plotly_js()  # inlined once, compressed
    assert sum(p.count("* plotly.js") for p in payloads.values()) == 1
    assert "* plotly.js" not in rendered  # not a second, uncompressed copy
    raw = re.search(r'id="plotly-js">([^<]*)<', rendered)
    assert raw and len(raw.group(1)) < len(style.plotly_js()) / 2  # gzip + base64 of it
    tags = _Tags()
    tags.feed(rendered)
    assert tags.fetching == []
    for kind in ("sphere", "sphere_response"):
        assert rendered.count(f'id="speed-{kind}"') == 1
    # the charts run no script of their own: each is a div and its packed figure, drawn by
    # the page's one script (in the head, before any of them)
    figures = rendered.count(FIGURE)
    assert figures >= 2 and figures == len(re.findall(r'<div id="[^"]+" class="plotly-graph-div"',
                                                      rendered))
    assert rendered.index("window.crosscheck = {}") < rendered.index(FIGURE)
    assert "Plotly.newPlot" not in rendered.split("window.crosscheck = {}", 1)[1].split(
        "</script>", 1)[1]


def test_script_in_text_is_escaped_everywhere_including_hover(rendered: str) -> None:
    assert EVIL not in rendered
    assert "\\u003cscript" not in rendered  # no raw tag inside the plotly figure JSON
    assert "&lt;script&gt;alert" in rendered
    chart = chart_of(FRAME, "sphere", described(s5=EVIL))
    fig = speed_error.figure(chart, ["fast", "exact"])
    hovers = [h for t in fig.data if t.hovertext for h in t.hovertext]
    assert any("worst case: s5: &lt;script&gt;" in h for h in hovers)
    assert not any("<script" in h for h in hovers)
    point = by_engine(speed_error.speed_chart(FRAME, "sphere", info_of(EVIL), {}))["fast"]
    assert "&lt;script&gt;" in speed_error.hover(point, chart.measure)
    assert "<script" not in speed_error.hover(point, chart.measure)


def test_chart_from_a_real_run_of_fakes(tmp_path: Path) -> None:
    cases = [sphere(0.0, 2.0 + i, id=f"apart-{i}") for i in range(3)]
    engines = [fakes.AlwaysRight(), fakes.OffByOne()]
    options = RunOptions(min_sample_s=0.001, samples=5, isolate=False)
    folder = tmp_path / "run"
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    frame = read_results(folder)
    points = by_engine(chart_of(frame, "sphere"))
    for engine, error in (("fake-right", 0.0), ("fake-off", 1.0)):
        times = frame[frame["engine"] == engine].drop_duplicates("case_id")["query_s"]
        assert times.notna().all() and points[engine].query_s == times.median()
        assert points[engine].time.q1 <= points[engine].query_s <= points[engine].time.q3
        in_bounds = [error / bound(c, "distance") for c in cases]  # scale-free errors
        assert points[engine].errors["distance"].median == pytest.approx(np.median(in_bounds))
    median = points["fake-right"].errors["distance"].median
    assert speed_error.SpeedChart.y(median) == speed_error.FLOOR
    section = part(report.render(folder)["report"].read_text(encoding="utf-8"),
                   '<h2 id="timing">', "<h2")
    assert 'id="yardstick"' in section and 'id="binding"' in section


TIMED = pd.DataFrame([r.row() for r in timed_records()[0]])


@pytest.fixture
def timed_html(tmp_path: Path) -> str:
    return report.render(timed_run(tmp_path / "timed"))["report"].read_text(encoding="utf-8")


def timed_chart() -> speed_error.SpeedChart:
    return speed_error.speed_chart(TIMED, "sphere", info_of(timing=timing_info()), {})


def part(html: str, start: str, end: str) -> str:
    return html.split(start)[1].split(end)[0]


def test_every_speed_point_has_a_horizontal_iqr_whisker_and_its_vertical_one() -> None:
    fig = speed_error.figure(timed_chart(), list(dict.fromkeys(TIMED["engine"])))
    points = {t.legendgroup: t for t in fig.data if t.type == "scatter" and t.error_x.array}
    assert set(points) == {"fast", "exact", "noisy"}
    for engine, trace in points.items():
        rows = TIMED[(TIMED["engine"] == engine) & (TIMED["kind"] == "sphere")]
        q1, median, q3 = np.percentile(rows.drop_duplicates("case_id")["query_s"], [25, 50, 75])
        assert trace.x[0] == pytest.approx(median) and trace.error_x.symmetric is False
        assert trace.error_x.array[0] == pytest.approx(q3 - median)
        assert trace.error_x.arrayminus[0] == pytest.approx(median - q1)
        assert len(trace.error_y.array) == 1  # the error whisker up to the 95th percentile
    assert points["fast"].error_x.array[0] > 0  # fast's five cases differ in speed


def test_unstable_share_in_hover_and_caption(timed_html: str) -> None:
    fast = by_engine(timed_chart())["fast"]
    assert (fast.unstable, fast.timed) == (1, 5)
    assert "1 of 5 timings unstable (IQR &gt; 10% of median)" in speed_error.hover(
        fast, timed_chart().measure)
    sphere_part = part(timed_html, 'id="speed-sphere-section"', 'id="speed-sphere-times"')
    assert "4 of 15 timings unstable (IQR &gt;\n10% of median)" in sphere_part
    assert "0 of 2 timings unstable" in part(timed_html, '"speed-sphere_response-section"', "<h2")


def test_mostly_unstable_engine_is_hollow_and_labelled(timed_html: str) -> None:
    chart = timed_chart()
    points = by_engine(chart)
    assert points["noisy"].mostly_unstable and not points["fast"].mostly_unstable
    fig = speed_error.figure(chart, ["fast", "exact", "untimed", "skipper", "crashy", "noisy"])
    named = {t.name: t.marker.symbol for t in fig.data if t.showlegend is not False}
    assert named["noisy (timing unstable)"].endswith("-open") and "noisy" not in named
    assert not named["fast"].endswith("-open")
    table = part(timed_html, 'id="speed-sphere-times"', "</table>")
    assert "noisy <b>(timing unstable)</b>" in table and "fast <b>" not in table


def test_caption_says_times_are_per_call_through_python_bindings_with_overhead(
        timed_html: str) -> None:
    assert "Times are per-call costs through each\nengine's Python binding" in timed_html
    assert "formula such as <code>reference</code> pays\nthe interpreter" in timed_html
    points = by_engine(timed_chart())
    assert points["fast"].binding_share == pytest.approx(1e-7 / 3e-6)
    hover = speed_error.hover(points["fast"], timed_chart().measure)
    assert "binding call (cheapest call into it): 100 ± 2 ns, 3% of the median" in hover
    assert "binding call: none: no cheap call" in speed_error.hover(points["untimed"],
                                                               timed_chart().measure)
    table = part(timed_html, 'id="speed-sphere-times"', "</table>")
    assert "<td>fast</td>" in table and "100 ± 2 ns" in table and "3 ± 2 µs" in table


def test_timing_section_method_sample_yardstick_drift_and_warning(timed_html: str) -> None:
    assert timed_html.index("Speed against error") < timed_html.index('<h2 id="timing">')
    assert timed_html.index('<h2 id="timing">') < timed_html.index('<h2 id="results">')
    section = part(timed_html, '<h2 id="timing">', "<h2")
    assert timing_info()["method"] in section and "17 case &times; engine pairs" in section
    assert "holds 17, of which 4 unstable" in section and "harness on core 0" in section
    assert "Warning: the machine's speed\nchanged during timing (python drifted +25%)" in section
    yardstick = part(section, 'id="yardstick"', "</table>")
    assert "1.020" in yardstick and "1.250" in yardstick  # numpy and python, end / start
    assert "1 ± 0.02 ms" in yardstick and "1.25 ± 0.025 ms" in yardstick
    binding = part(section, 'id="binding"', "</table>")
    assert "<td>fast</td><td class=\"num\">100 ± 2 ns</td>" in binding
    assert f"{100 * 1e-7 / 3e-6:.1f}%" in binding and "none: no cheap call" in binding
    calm = speed.timing_context(info_of(timing=timing_info(python_end=1.05e-3)), TIMED,
                                ["sphere"], pd.DataFrame(columns=["unstable"]))
    assert calm["drifted"] == [] and calm["yardstick"][1]["ratio"] == pytest.approx(1.05)


def test_timing_section_is_one_line_without_timing(rendered: str) -> None:
    section = part(rendered, '<h2 id="timing">', "<h2").split("</h2>")[1]
    section = section.split("</section>")[0].strip()  # the page wraps each section
    assert section.count("<p") == 1 and "\n" not in section and "<table" not in section
    assert "Timing was not recorded for this run" in section
    quick = replace(info_of(), options=RunOptions(quick=True))
    assert speed.timing_context(quick, FRAME, ["sphere"], pd.DataFrame()) == {
        "off": "Timing was off for this run (--quick): no case was timed."}


def test_summary_shows_the_iqr_over_cases_beside_the_median(timed_html: str) -> None:
    table = summary_tables.summary(TIMED).set_index(["engine", "kind"])
    fast = TIMED[(TIMED["engine"] == "fast") & (TIMED["kind"] == "sphere")]
    q1, q3 = np.percentile(fast.drop_duplicates("case_id")["query_s"], [25, 75])
    assert table.loc[("fast", "sphere"), "iqr_query_s"] == pytest.approx(q3 - q1)
    assert table.loc[("noisy", "sphere"), ["timed", "unstable"]].tolist() == [5, 3]
    summary_html = part(timed_html, 'id="summary"', "</table>")
    median = table.loc[("fast", "sphere"), "median_query_s"]
    assert "median query &plusmn; IQR over cases" in summary_html
    assert f'<td class="num time">{text.median_iqr(median, q3 - q1)}</td>' in summary_html


def test_results_table_has_one_row_per_case_and_engine_with_its_quantities(rendered: str) -> None:
    data = json.loads(packed_scripts(rendered)["results-data"])
    pairs = FRAME.drop_duplicates(["case_id", "engine"])
    assert len(data["rows"]) == len(pairs)
    assert data["quantities"] == list(dict.fromkeys(FRAME["quantity"]))
    cases = {c["id"]: c for c in data["cases"]}
    assert cases["s5"]["description"] == EVIL  # text: the page escapes it when it shows it
    row = next(r for r in data["rows"] if cases_of(data, r) == "s5" and r["engine"] == "fast")
    frame = FRAME[(FRAME["case_id"] == "s5") & (FRAME["engine"] == "fast")]
    assert set(row["q"]) == set(frame["quantity"])
    assert {q: v[0] for q, v in row["q"].items()} == dict(zip(frame["quantity"], frame["status"],
                                                             strict=True))
    assert 'id="results-table"' in rendered and 'id="case-details"' in rendered


def cases_of(data: dict[str, Any], row: dict[str, Any]) -> str:
    return str(data["cases"][row["case"]]["id"])


def test_the_summary_keeps_each_error_measure_apart() -> None:
    rows = [rec("s1", "fast", "hit", "disagree", 1.0), rec("s2", "fast", "hit", "agree", 0.0),
            rec("s1", "fast", "distance", "disagree", 4e-3),
            rec("s2", "fast", "distance", "agree", 2e-3),
            rec("s1", "fast", "normal", "agree", 0.5)]
    table = summary_tables.summary(pd.DataFrame([r.row() for r in rows])).set_index("engine")
    assert table.loc["fast", "wrong_verdicts"] == 0.5  # one of two verdicts wrong
    assert table.loc["fast", "distance_error"] == 3e-3 and table.loc["fast", "normal_angle"] == 0.5
    assert math.isnan(table.loc["fast", "velocity_error"])  # nothing measured: "-"


def test_the_page_has_contents_and_says_when_a_run_is_incomplete(tmp_path: Path) -> None:
    directory = tmp_path / "run"
    cases = [sphere(0.0, 2.0, id="a"), sphere(0.0, 0.5, id="b")]
    options, engines = RunOptions(quick=True, isolate=False), [fakes.AlwaysRight()]
    launch(ResultsStore(directory), cases, engines, options,
           new_info(directory, "test", options, engines, cases))
    html = report.render(directory)["report"].read_text(encoding="utf-8")
    for anchor in re.findall(r'<nav class="toc">.*?</nav>', html, re.S)[0].split('href="#')[1:]:
        assert f'<section id="{anchor.split(chr(34))[0]}">' in html
    assert "This run is incomplete" not in html
    info = json.loads((directory / "run.json").read_text())
    (directory / "run.json").write_text(json.dumps(info | {"finished": None}))
    lines = (directory / "results.jsonl").read_text().splitlines()
    (directory / "results.jsonl").write_text("\n".join(lines[:-3]) + "\n")  # a pair cut short
    html = report.render(directory)["report"].read_text(encoding="utf-8")
    assert "This run is incomplete" in html and "1 case &times; engine pairs" in html


def test_the_conventions_table_shows_margins_contact_model_and_friction() -> None:
    conventions = asdict(Conventions(margins={"face": 0.02}, friction=0.25,
                                     restitution_model="soft"))
    engine = {"name": "soft-engine", "version": "1", "available": "yes", "capabilities": [],
              "conventions": conventions, "touching_rule": "contact when touching: all",
              "settings": "s"}
    html = style.templates().get_template("_engines.html.j2").render(
        info=SimpleNamespace(engines=[engine]))
    assert '<div class="wide"><table id="conventions">' in html  # never wider than the page
    row = html[html.index("<td>soft-engine</td>"):]
    assert "face 0.02" in row and "soft: no coefficient of restitution" in row
    assert '<td class="num">0.25</td>' in row
