"""What the repeat check found, as the report and ``advise`` show it: the results table badges
a nondeterministic pair with both answers in its hover, the verdict block counts such pairs
per engine, and ``advise`` says per engine how many of the envelope's cases answered
differently when asked again (in --json too).  The run is made by a fake engine that answers
from a process-wide count (flagged) beside one that is wrong the same way each time (never
flagged)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.report.advise.recommend import Envelope, advise
from crosscheck.report.render import render
from crosscheck.report.results_table import results_data
from crosscheck.results.run import read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.conftest import ROOT
from tests.report.browser import needs_chromium, opened

CASES = load_paths([ROOT / "cases" / "sphere.toml"]).cases[:8]


@pytest.fixture(scope="module")
def checked(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A rendered quick run of the first sphere cases with the repeat check."""
    folder = tmp_path_factory.mktemp("repeat") / "run"
    engines = [fakes.DriftsWithEachQuery(), fakes.OffByOne(), fakes.AlwaysRight()]
    options = RunOptions(quick=True, repeat_check=True)
    launch(ResultsStore(folder), CASES, engines, options,
           new_info(folder, "test", options, engines, CASES))
    render(folder)
    return folder


def flagged_pairs(frame: pd.DataFrame) -> pd.DataFrame:
    return frame[frame["nondeterministic"]].drop_duplicates(["case_id", "engine"])


def test_the_results_data_carries_both_answers_of_a_nondeterministic_pair(
        checked: Path) -> None:
    run = read_run(checked)
    flagged = flagged_pairs(run.results)
    assert len(flagged) > 0 and set(flagged["engine"]) == {"fake-drifts"}
    data = results_data(run.results, run.cases, set())
    rows, cases = data["rows"], data["cases"]
    again = {(cases[r["case"]]["id"], r["engine"]): r for r in rows if "again" in r}
    assert set(again) == set(zip(flagged["case_id"], flagged["engine"], strict=True))
    for row in run.results[run.results["nondeterministic"]].itertuples():
        status, value = again[(row.case_id, row.engine)]["again"][row.quantity]
        assert (status, value) == (row.repeat_status, row.repeat_value)
    for row in rows:  # a twin is folded under its original only if both are flagged or neither
        if row["folded"]:
            original = next(r for r in rows if r["engine"] == row["engine"]
                            and cases[r["case"]]["id"] == cases[row["case"]]["twin_of"])
            assert ("again" in row) == ("again" in original)
    shown = sum("again" in r and not r["folded"] for r in rows)
    assert re.search(rf"; {shown} nondeterministic\)</h2>", (checked / "report.html").read_text())


def test_the_verdict_block_counts_nondeterministic_pairs_per_engine(checked: Path) -> None:
    frame = read_run(checked).results
    flagged = len(flagged_pairs(frame))
    asked = len(frame[frame["repeat_status"] != ""].drop_duplicates(["case_id", "engine"]))
    page = (checked / "report.html").read_text()
    line = re.search(r'<p class="caption" id="verdict-repeat">(.*?)</p>', page, re.S)
    assert line is not None
    text = " ".join(re.sub(r"<[^>]+>", "", line.group(1)).split())
    assert text == (f"Repeat check: {asked} disagreeing pairs asked again in a fresh worker; "
                    f"{flagged} answered differently (nondeterministic): fake-drifts {flagged}.")
    cells = re.findall(r'<tr class="verdict-engine"><td class="engine"><b>([^<]+)</b>(.*?)</td>',
                       page)
    counts = {engine: re.findall(r"(\d+) nondeterministic", rest) for engine, rest in cells}
    assert counts == {"fake-drifts": [str(flagged)], "fake-off": [], "fake-right": []}


def test_advise_says_per_engine_how_many_cases_answered_differently(
        checked: Path, capsys: pytest.CaptureFixture[str]) -> None:
    frame = read_run(checked).results
    advice = advise(read_run(checked), Envelope())
    engines = {e.engine: e for e in advice.ranking + advice.baselines}
    drifts = frame[frame["engine"] == "fake-drifts"]
    assert advice.repeat_checked
    assert engines["fake-drifts"].nondeterministic == drifts[drifts["nondeterministic"]][
        "case_id"].nunique() > 0
    assert engines["fake-drifts"].repeated == engines["fake-off"].repeated == len(CASES)
    assert engines["fake-off"].nondeterministic == 0
    assert engines["fake-right"].repeated == 0 == engines["fake-right"].nondeterministic
    assert main(["advise", str(checked), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    by_name = {e["engine"]: e for e in data["failing"] + data["passing"]}
    assert by_name["fake-drifts"]["nondeterministic"] == engines["fake-drifts"].nondeterministic
    assert main(["advise", str(checked)]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert (f"answered differently when asked again (cases): fake-drifts "
            f"{engines['fake-drifts'].nondeterministic} of {len(CASES)}; every other engine "
            "answered the same") in text


@pytest.mark.browser
def test_the_results_table_badges_the_pair_with_both_answers_in_its_hover(
        checked: Path) -> None:
    needs_chromium()
    frame = read_run(checked).results
    rows = frame[frame["nondeterministic"] & (frame["quantity"] == "distance")]
    row = rows[rows["value"] != rows["repeat_value"]].iloc[0]
    with opened(checked / "report.html") as page:
        page.wait_for_selector("#results-table[data-ready]")
        page.locator("#results-table thead input").first.fill(str(row["case_id"]))
        badges = page.locator("#results-table tbody .badge-nondeterministic")
        titles = [badges.nth(k).get_attribute("title") for k in range(badges.count())]
        names = page.locator("#results-table tbody tr:has(.badge-nondeterministic) "
                             "td:nth-child(2)").all_inner_texts()
    assert names == ["fake-drifts"]
    assert titles == [f"answered differently in a fresh worker\ndistance: {row['value']} "
                      f"({row['status']}), asked again: {row['repeat_value']} "
                      f"({row['repeat_status']})"]
