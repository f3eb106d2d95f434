"""Energy against time in the dynamics section: one readable chart per scene family, read from
the run's ``series.jsonl`` (a report never runs an engine)."""

from __future__ import annotations

import base64
import gzip
import json
import re

from markupsafe import Markup

from crosscheck.report import energy_chart
from crosscheck.report.energy_chart import MAX_CHARTS, Family
from crosscheck.report.style import templates
from crosscheck.results.series import EXACT, SeriesRecord

EVIL = "<script>alert('pwned')</script>"


def line(case_id: str, engine: str, origin: str, end: float, **coords: float) -> SeriesRecord:
    return SeriesRecord(case_id, engine, origin, {"dt": 0.5, **coords}, (0.0, 1.0, 2.0),
                        (0.0, end / 2, end))


def figures(section: dict[str, object]) -> list[dict[str, object]]:
    """The plotly figures of the section's charts, unpacked from their divs."""
    charts = section["charts"]
    assert isinstance(charts, list)
    out = []
    for chart in charts:
        packed = re.search(r'class="plotly-figure"[^>]*>([^<]+)<', chart["html"])
        assert packed is not None
        out.append(json.loads(gzip.decompress(base64.b64decode(packed.group(1)))))
    return out


def test_a_family_draws_one_line_per_engine_and_the_exact_one_with_titled_axes() -> None:
    records = [line("drop.dt=0.5", EXACT, "drop", 0.0), line("drop.dt=0.5", "b", "drop", -0.2),
               line("drop.dt=0.5", "a", "drop", 0.1)]
    section = energy_chart.section(records, {}, ["a", "b"])
    (figure,) = figures(section)
    names = [trace["name"] for trace in figure["data"]]
    assert sorted(names) == ["a", "b", "exact reference"] and names[-1] == "exact reference"
    assert figure["layout"]["xaxis"]["title"]["text"] == "simulated time (s)"
    assert "energy scale" in figure["layout"]["yaxis"]["title"]["text"]
    assert figure["data"][-1]["y"] == [0.0, 0.0, 0.0]
    assert section["charts"][0]["family"] == "drop at dt 0.5 s"
    assert "b -0.2" in section["charts"][0]["summary"]


def test_only_the_origin_point_of_an_offset_or_scale_sweep_is_drawn() -> None:
    records = [line(f"moved.offset={v:g}", "a", "moved", v, offset=v) for v in (0.0, 1e3)]
    records += [line(f"sized.scale={v:g}", "a", "sized", v, scale=v) for v in (0.5, 1.0)]
    found = energy_chart.families(records, {})
    assert [(f.origin, [r.energy[-1] for r in f.series], f.swept) for f in found] == [
        ("moved", [0.0], True), ("sized", [1.0], True)]


def test_past_the_limit_each_block_keeps_its_largest_dt_and_unswept_blocks_come_first() -> None:
    found = [Family(f"b{k}", dt, k >= MAX_CHARTS - 1, ()) for k in range(MAX_CHARTS + 2)
             for dt in (0.01, 0.1)]
    kept = energy_chart.chosen(found)
    assert len(kept) == MAX_CHARTS
    assert {f.dt for f in kept} == {0.1}
    assert [f.origin for f in kept if f.swept] == [f"b{MAX_CHARTS - 1}"]


def test_the_section_shows_the_charts_escaped_and_says_how_many_are_left_out() -> None:
    records = [line(f"s{k}.dt=0.5", EVIL, f"s{k}", 0.1) for k in range(MAX_CHARTS + 1)]
    built = energy_chart.section(records, {}, [])
    assert len(built["charts"]) == MAX_CHARTS and built["omitted"] == 1
    assert all(EVIL not in figure_text for figure_text in map(json.dumps, figures(built)))
    energy = {**built, "charts": [{**c, "html": Markup(c["html"])} for c in built["charts"]]}
    page = templates().get_template("_dynamics.html.j2").render(dynamics={
        "runs": 1, "scenes": [], "engines": [], "charts": [], "energy": energy})
    assert 'id="dynamics-energy"' in page
    assert page.count('class="dynamics-energy"') == MAX_CHARTS
    assert "1 more family left out" in page
    assert EVIL not in page
