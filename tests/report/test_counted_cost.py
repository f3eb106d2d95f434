"""The report and ``advise`` rank by counted instructions where every engine of a group was
counted, by the wall clock otherwise, and show both measures where both exist.

The runs are :func:`tests.report.counted.counted_run`: fakes whose costs the test writes
(``fake-right`` cheaper in instructions but slower on the wall clock than ``fake-twin``, as
right as it), either every engine counted or ``fake-twin`` not counted.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from crosscheck.cli import main
from crosscheck.report import profiles, speed_error
from crosscheck.report.advise.recommend import INSTRUCTIONS, WALL, Envelope, advise
from crosscheck.report.sections import RunView
from crosscheck.report.text import instructions, instructions_iqr, median_iqr, seconds
from crosscheck.results.run import read_run
from tests.report import counted as run
from tests.report.counted import counted_run

PARTLY = run.PARTLY


@pytest.fixture(scope="module")
def counted_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return counted_run(tmp_path_factory.mktemp("counted") / "run")


@pytest.fixture(scope="module")
def partly_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return counted_run(tmp_path_factory.mktemp("partly") / "run", PARTLY)


@pytest.fixture(scope="module")
def uncounted_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return counted_run(tmp_path_factory.mktemp("uncounted") / "run", {})


def quartiles(engine: str, per_query: dict[str, float]) -> tuple[float, float]:
    """The median and IQR over the cases of what the test wrote for ``engine``."""
    levels = [per_query[engine] * (1 + i / 100) for i in range(len(run.CASES))]
    q1, median, q3 = np.percentile(levels, [25, 50, 75])
    return float(median), float(q3 - q1)


def counted_text(engine: str) -> str:
    return instructions_iqr(*quartiles(engine, run.INSTRUCTIONS))


def wall_text(engine: str) -> str:
    """Its median ± IQR over cases of the per-case medians (each case: three samples)."""
    return median_iqr(*quartiles(engine, run.WALL_S))


def page(directory: Path) -> str:
    return (directory / "report.html").read_text(encoding="utf-8")


def part(html: str, start: str, end: str) -> str:
    return html.split(start, 1)[1].split(end, 1)[0]


def ranked(directory: Path) -> list[str]:
    detection = profiles.profiles(read_run(directory).results)[0]
    assert detection.profile.name == "3-D detection"
    return [s.engine for s in detection.ranked]


def test_the_verdict_breaks_ties_by_instructions_only_when_every_ranked_engine_was_counted(
        counted_dir: Path, partly_dir: Path) -> None:
    # fake-right and fake-twin are both exact: cost decides, and the two measures disagree
    assert ranked(counted_dir) == ["fake-right", "fake-twin", "fake-off"]
    assert ranked(partly_dir) == ["fake-twin", "fake-right", "fake-off"]


def test_the_verdict_block_shows_instructions_with_the_wall_clock_beside_them(
        counted_dir: Path, partly_dir: Path) -> None:
    block = part(page(counted_dir), 'data-profile="3-D detection"><summary>', "</table>")
    assert "ties after score and coverage are broken by the\nmedian instructions per query" \
        in block
    assert "<th>instructions per query &plusmn; IQR<small>wall clock" in block
    assert (f'<td class="cost counted">{counted_text("fake-right")}, 4 cases'
            f'<small>{wall_text("fake-right")}, 4 cases</small></td>') in block
    before = part(page(partly_dir), 'data-profile="3-D detection"><summary>', "</table>")
    assert "tie-break" not in before and "instr" not in before  # as before counts existed
    assert "<th>median query &plusmn; IQR</th>" in before
    assert f'<td class="cost">{wall_text("fake-twin")}, 4 cases</td>' in before


def chart(directory: Path) -> speed_error.SpeedChart:
    made = RunView(read_run(directory)).speed_charts
    assert [c.kind for c in made] == ["sphere"]
    return made[0]


def drawn(directory: Path) -> tuple[str, dict[str, float], dict[str, str]]:
    """The chart's speed axis title, and each engine's x and hover on the first panel."""
    made = chart(directory)
    fig = speed_error.figure(made, [e.name for e in run.ENGINES])
    points = [t for t in fig.data if t.type == "scatter" and t.showlegend]
    return (fig.layout.xaxis.title.text, {t.legendgroup: t.x[0] for t in points},
            {t.legendgroup: t.hovertext[0] for t in points})


def test_the_speed_axis_is_instructions_when_every_engine_was_counted_and_says_so(
        counted_dir: Path, partly_dir: Path) -> None:
    title, xs, hovers = drawn(counted_dir)
    assert title == "median instructions per query (counted under callgrind)"
    assert xs == {e: quartiles(e, run.INSTRUCTIONS)[0] for e in run.INSTRUCTIONS}
    median_s = quartiles("fake-right", run.WALL_S)[0]
    assert f"instructions per query (callgrind): {instructions(50_750.0)}" in hovers["fake-right"]
    assert f"median query per call: {seconds(median_s)}" in hovers["fake-right"]  # both
    assert f"inside the engine's own code: {instructions(0.4 * 50_750.0)}" in hovers["fake-right"]
    title, xs, hovers = drawn(partly_dir)
    assert title == "median wall-clock time per query (s)"
    assert xs == {e: pytest.approx(quartiles(e, run.WALL_S)[0]) for e in run.WALL_S}
    assert "instructions" not in hovers["fake-twin"] and "instructions" in hovers["fake-right"]


def test_the_speed_headline_names_the_cheapest_in_the_charts_measure(
        counted_dir: Path, partly_dir: Path) -> None:
    line = part(page(counted_dir), 'id="speed-sphere-section" open><summary>', "</summary>")
    assert (f"cheapest first by instructions per query: <b>fake-right</b> "
            f"{counted_text('fake-right')} ({wall_text('fake-right')})") in line
    line = part(page(partly_dir), 'id="speed-sphere-section" open><summary>', "</summary>")
    assert f"fastest first: <b>fake-twin</b> {wall_text('fake-twin')}" in line


def test_the_engine_kind_table_shows_instructions_beside_the_wall_clock(
        counted_dir: Path, uncounted_dir: Path) -> None:
    table = part(page(counted_dir), 'id="summary"', "</table>")
    assert "<th>instructions per query &plusmn; IQR over counted cases</th>" in table
    row = part(table, "<tr><td>fake-right</td>", "</tr>")
    assert f'title="counted on 4 cases; {instructions(0.4 * 50_750.0)} inside the engine">' \
           f'{counted_text("fake-right")}</td>\n<td class="num time">{wall_text("fake-right")}' \
           in row
    assert "instr" not in part(page(uncounted_dir), 'id="summary"', "</table>")


def passing(directory: Path) -> tuple[list[str], str]:
    advice = advise(read_run(directory), Envelope())
    return [e.engine for e in advice.passing], advice.cost_by


def test_advise_orders_the_passing_engines_by_instructions_only_when_all_were_counted(
        counted_dir: Path, partly_dir: Path, uncounted_dir: Path) -> None:
    assert passing(counted_dir) == (["fake-right", "fake-twin"], INSTRUCTIONS)
    assert passing(partly_dir) == (["fake-twin", "fake-right"], WALL)
    assert passing(uncounted_dir) == (["fake-twin", "fake-right"], WALL)


def test_advise_json_gives_both_measures(counted_dir: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(counted_dir), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["cost_by"] == "instructions"
    right = data["passing"][0]
    assert right["engine"] == "fake-right"
    median, iqr = quartiles("fake-right", run.INSTRUCTIONS)
    assert (right["median_query_instructions"], right["query_instructions_iqr"]) == (
        pytest.approx(median), pytest.approx(iqr))
    assert right["median_query_s"] == pytest.approx(quartiles("fake-right", run.WALL_S)[0])


def test_advise_cli_shows_instructions_before_the_wall_clock_where_counted(
        counted_dir: Path, uncounted_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["advise", str(counted_dir)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert max(len(line) for line in lines) <= 80
    header = next(line for line in lines if line.startswith("#"))
    assert header.split()[-6:] == ["instr/query", "±", "IQR", "wall", "±", "IQR"]
    right = next(line for line in lines if " fake-right " in line)
    assert right.endswith(f"{counted_text('fake-right')}  {wall_text('fake-right')}")
    assert any("passing: fake-right, fake-twin (cheapest first by instructions per query)"
               in line for line in lines)
    assert main(["advise", str(uncounted_dir)]) == 0
    text = capsys.readouterr().out
    assert "instr" not in text and "passing: fake-twin, fake-right (cheapest first)\n" in text
