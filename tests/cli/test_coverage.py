"""``crosscheck coverage``: coverage.csv and coverage.html written into a run folder (or
--out), the empty cells printed, a fuzz campaign's folder read the same way (its cases
regenerated from its seed), and bad input refused before any work."""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.cli import main
from crosscheck.core.model import Kind, Status
from crosscheck.core.options import RunOptions
from crosscheck.results.run import read_results, read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from crosscheck.studies.fuzz import generate
from crosscheck.studies.fuzz.bias import bias_from
from crosscheck.studies.fuzz.campaign import fuzz
from tests.conftest import aabb, embedded, sphere
from tests.fakes import AlwaysRight, OffByOne

UNIT = [1.0, 1.0, 1.0]
ENGINES = ("fake-right", "fake-off")


def read(path: Path) -> pd.DataFrame:
    return pd.read_csv(path, keep_default_na=False, dtype={"level_1": str, "level_2": str,
                                                           "level_3": str})


def pair_cell(table: pd.DataFrame, kind: str, first: str, a: str, second: str, b: str
              ) -> pd.DataFrame:
    """The rows (one per engine) of a 2-way cell of the 3-D space of ``kind``."""
    return table[(table["kind"] == kind) & (table["dim"] == 3) & (table["dimension_1"] == first)
                 & (table["level_1"] == a) & (table["dimension_2"] == second)
                 & (table["level_2"] == b) & (table["dimension_3"] == "")]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run of the two fakes: boxes apart along +y at gap 1 and along +x at gap 0.1, two
    spheres apart, and a bad-input case."""
    folder = tmp_path_factory.mktemp("coverage") / "run"
    cases = [aabb([0.0, 0.0, 0.0], UNIT, [0.0, 4.0, 0.0], UNIT, id="box-y1"),
             aabb([0.0, 0.0, 0.0], UNIT, [2.2, 0.0, 0.0], UNIT, id="box-x01"),
             sphere(0.0, 3.0, id="ball"),
             sphere(math.nan, 1.0, id="ball-nan", tags=["bad-input"])]
    options, engines = RunOptions(quick=True, isolate=False), [AlwaysRight(), OffByOne()]
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    return folder


def test_it_writes_coverage_csv_into_the_run_and_prints_the_empty_cells(
        run_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["coverage", str(run_dir), "--limit", "0"]) == 0
    said = " ".join(capsys.readouterr().out.split())
    table = read(run_dir / "coverage.csv")
    rows = pair_cell(table, "aabb", "direction", "+y", "gap", "+1")
    assert list(rows["engine"]) == list(ENGINES) and set(rows["cases"]) == {1}
    assert set(pair_cell(table, "aabb", "direction", "+x", "gap", "+1")["cases"]) == {0}
    results = read_results(run_dir)
    for engine, worst in zip(rows["engine"], rows["worst_status"], strict=True):
        mine = results[(results["engine"] == engine) & (results["case_id"] == "box-y1")]
        assert worst == str(min((Status(s) for s in mine["status"]), key=lambda s: s.severity))
    assert set(table["kind"]) == {"aabb", "sphere"}  # the bad-input case is in no cell
    empty = table[(table["kind"] == "aabb") & (table["dim"] == 3) & (table["cases"] == 0)
                  & (table["dimension_1"] == "direction") & (table["dimension_2"] == "gap")
                  & (table["dimension_3"] == "") & (table["engine"] == "fake-right")]
    line = re.search(r"aabb 3-D: 2 cases.*?empty, direction x gap \((\d+)\): ([^(]*)", said)
    assert line, said
    assert int(line.group(1)) == len(empty)
    assert "+x/+1," in line.group(2) and "+y/+1," not in line.group(2)
    assert f"coverage: {run_dir / 'coverage.csv'}" in said
    assert f"coverage page: {run_dir / 'coverage.html'}" in said
    page = (run_dir / "coverage.html").read_text(encoding="utf-8")
    assert embedded(page, "coverage-data")["engines"] == list(ENGINES)
    assert f"coverage of run {read_run(run_dir).info.run_id}" in page


def test_the_listing_stops_at_the_limit(run_dir: Path, capsys: pytest.CaptureFixture[str]
                                         ) -> None:
    assert main(["coverage", str(run_dir), "--limit", "2"]) == 0
    said = " ".join(capsys.readouterr().out.split())
    shown = re.search(r"empty, direction x gap \((\d+)\): (\S+), (\S+) and (\d+) more", said)
    assert shown and int(shown.group(4)) == int(shown.group(1)) - 2


def test_out_writes_it_elsewhere(run_dir: Path, tmp_path: Path) -> None:
    run = tmp_path / "run"
    shutil.copytree(run_dir, run)
    (run / "coverage.csv").unlink(missing_ok=True)
    (run / "coverage.html").unlink(missing_ok=True)
    elsewhere = tmp_path / "a" / "b"
    assert main(["coverage", str(run), "--out", str(elsewhere)]) == 0
    assert (elsewhere / "coverage.csv").is_file() and not (run / "coverage.csv").exists()
    assert (elsewhere / "coverage.html").is_file() and not (run / "coverage.html").exists()
    assert main(["coverage", str(run)]) == 0
    assert read(run / "coverage.csv").equals(read(elsewhere / "coverage.csv"))


def test_bad_input_is_refused_before_any_work(run_dir: Path, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["coverage", str(tmp_path)]) == 2
    assert "neither a run folder" in capsys.readouterr().err
    a_file = tmp_path / "file.txt"
    a_file.write_text("")
    target = a_file / "out"
    assert main(["coverage", str(run_dir), "--out", str(target)]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert f"cannot write into {target}" in err
    assert main(["coverage", str(run_dir), "--limit", "-1"]) == 2
    assert "--limit" in capsys.readouterr().err


@pytest.fixture(scope="module")
def campaign_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small fuzz campaign of boxes on the two fakes (fake-off is wrong on every distance)."""
    folder = tmp_path_factory.mktemp("coverage-fuzz") / "campaign"
    fuzz(Kind.AABB, 40, 5, folder, [AlwaysRight(), OffByOne()],
         RunOptions(quick=True, jobs=1), per_group=1, command="test")
    return folder


def test_a_fuzz_campaign_is_read_the_same_way(campaign_dir: Path, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["coverage", str(campaign_dir), "--out", str(tmp_path)]) == 0
    said = " ".join(capsys.readouterr().out.split())
    table = read(tmp_path / "coverage.csv")
    findings = pd.read_csv(campaign_dir / "findings.csv", keep_default_na=False)
    placed = [int(n) for n in re.findall(r"aabb [23]-D: (\d+) cases", said)]
    assert sum(placed) == 40  # every regenerated case, 2-D and 3-D
    held = table[table["cases"] > 0]
    right, off = (findings[findings["engine"] == e] for e in ENGINES)
    assert right.empty and off["case_id"].nunique() == 40  # fake-off is wrong on every case
    assert set(held[held["engine"] == "fake-right"]["worst_status"]) == {"agree"}
    worst = min((Status(s) for s in off["status"]), key=lambda s: s.severity)
    statuses = set(held[held["engine"] == "fake-off"]["worst_status"])
    assert str(worst) in statuses and "agree" not in statuses
    errors = held[held["engine"] == "fake-off"]["max_error_bounds"]
    assert (errors.astype(float) > 1).all()  # an error of 1.0 is many float64 bounds
    disagreeing = held[held["worst_status"] == "disagree"]
    found_categories = set(off[off["status"] == "disagree"]["category"])
    assert set(disagreeing["worst_category"]) <= found_categories and not disagreeing.empty
    assert set(held[held["worst_status"] != "disagree"]["worst_category"]) == {""}
    page = (tmp_path / "coverage.html").read_text(encoding="utf-8")
    assert f"coverage of fuzz campaign {campaign_dir.name}" in page
    assert "one without a finding agrees" in page and "40 aabb cases from seed 5" in page
    data = embedded(page, "coverage-data")
    assert data["engines"] == list(ENGINES) and len(data["spaces"]) == len(placed)
    assert re.search(r'(src|href)="(https?:)?//', page) is None  # self-contained


def test_a_biased_campaign_is_regenerated_with_its_bias(
        run_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A campaign drawn toward the failing cells of a run (``crosscheck fuzz --bias``) makes
    other cases than the same seed without it; the coverage map regenerates them with the
    bias its plan stores, each finding on the case it was found on."""
    bias = bias_from(run_dir)
    assert bias  # fake-off is wrong on every case of the run
    folder = tmp_path / "biased"
    fuzz(Kind.AABB, 40, 5, folder, [AlwaysRight(), OffByOne()],
         RunOptions(quick=True, jobs=1), per_group=1, command="test", bias=bias)
    plain = {g.case.id: g.case for g in generate(Kind.AABB, 40, 5)}
    biased = {g.case.id: g.case for g in generate(Kind.AABB, 40, 5, bias)}
    assert plain != biased
    assert main(["coverage", str(folder)]) == 0
    said = " ".join(capsys.readouterr().out.split())
    assert sum(int(n) for n in re.findall(r"aabb [23]-D: (\d+) cases", said)) == 40


def test_a_campaign_whose_seed_no_longer_makes_its_cases_is_refused(
        campaign_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    changed = tmp_path / "changed"
    shutil.copytree(campaign_dir, changed)
    findings = pd.read_csv(changed / "findings.csv", keep_default_na=False)
    findings.loc[0, "family"] = "something-else"
    findings.to_csv(changed / "findings.csv", index=False)
    assert main(["coverage", str(changed)]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert f"case {findings.loc[0, 'case_id']} is not the one its findings were found on" in err
    assert not (changed / "coverage.csv").exists()
    (changed / "findings.csv").unlink()
    assert main(["coverage", str(changed)]) == 2
    assert "the campaign did not finish" in " ".join(capsys.readouterr().err.split())
