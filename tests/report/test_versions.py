"""The report's engine-version section (crosscheck.report.versions): pairs found from the
declared ``supersedes``, the changed rows by failure mode, the missed impacts of fast blocks,
and the section on the rendered page."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pandas as pd

import adapters
from crosscheck.core.contract import engine_info
from crosscheck.report import versions
from crosscheck.report.render import render_html
from crosscheck.report.sections import RunView
from crosscheck.results.run import read_run
from crosscheck.truth.scene_rules import PASSED_THROUGH
from tests.report.test_changes import AFTER, BEFORE, make_run

ENGINES = ({"name": "old", "version": "2.3", "supersedes": ""},
           {"name": "new", "version": "3.1", "supersedes": "old"})


def fast_rows() -> pd.DataFrame:
    """Two fast blocks: the old version misses 2 of 3 cases of fast-a, the new one 1."""
    rows = []
    for engine, missed in (("old", {"fast-a.1", "fast-a.2"}), ("new", {"fast-a.3"})):
        for case in ("fast-a.1", "fast-a.2", "fast-a.3", "fast-b.1"):
            for quantity in ("positions", "velocities"):
                rows.append({
                    "case_id": case, "origin": case.partition(".")[0], "engine": engine,
                    "kind": "sphere_scene", "quantity": quantity, "status": "disagree",
                    "category": "timestep" if case in missed else "",
                    "reason": f"{PASSED_THROUGH} at step travel 2" if case in missed else ""})
    return pd.DataFrame(rows)


def test_pairs_need_both_versions_in_the_run() -> None:
    assert versions.pairs(ENGINES) == [("old", "new")]
    assert versions.pairs(ENGINES[1:]) == []


def test_missed_impacts_count_cases_per_block_and_version() -> None:
    found = versions.missed_impacts(fast_rows(), ("old", "new"))
    assert [f["block"] for f in found] == ["fast-a", "fast-b"]
    assert found[0]["engines"] == {"old": {"cases": 3, "missed": 2, "errors": 0},
                                   "new": {"cases": 3, "missed": 1, "errors": 0}}
    assert found[1]["engines"]["old"] == {"cases": 1, "missed": 0, "errors": 0}


def test_wall_cases_without_a_sweep_are_grouped_by_their_block() -> None:
    rows = pd.DataFrame([
        {"case_id": f"fast-wall-x-travel-{t}-phase-0.3", "origin": "", "engine": e,
         "kind": "sphere_scene", "quantity": "velocities", "status": "disagree",
         "category": "error" if (e, t) == ("old", 50) else "", "reason": ""}
        for t in (2, 50) for e in ("old", "new")])
    (found,) = versions.missed_impacts(rows, ("old", "new"))
    assert found["block"] == "fast-wall-x"
    assert found["engines"]["old"] == {"cases": 2, "missed": 0, "errors": 1}
    assert found["engines"]["new"]["errors"] == 0


def test_section_lists_the_changed_rows_by_failure_mode(tmp_path: Path) -> None:
    run = read_run(make_run(tmp_path / "run", {"old": BEFORE, "new": AFTER}))
    engines = [dict(e, supersedes="old" if e["name"] == "new" else "") for e in run.info.engines]
    built = versions.section(run.results, engines, run.directory)
    assert built is not None
    (pair,) = built["pairs"]
    assert (pair["changed"], pair["compared"]) == (6, 7)
    assert pair["modes"][0] == {
        "mode": "hit: agree -> disagree (tolerance)", "rows": 2, "examples": ["a", "b"],
        "repro": f"crosscheck repro {run.directory} a --engine new"}
    assert pair["counts"]["old"]["sphere"]["disagree (convention)"] == 2
    assert versions.section(run.results, run.info.engines, run.directory) is None


def test_the_page_shows_the_section_only_with_both_versions(tmp_path: Path) -> None:
    # rows with a number for a value (the fake's crash row stores 'nan', which no page decodes)
    directory = make_run(tmp_path / "run", {"old": BEFORE[:4], "new": AFTER[:4]})
    stored = read_run(directory)
    real = engine_info(adapters.get("reference"))  # what the engines table reads of each
    info = dataclasses.replace(stored.info, machine={"packages": {}}, engines=tuple(
        {**real, **e} for e in stored.info.engines))
    run = dataclasses.replace(stored, info=info)
    plain = render_html(RunView(run))
    assert "Engine versions" not in plain
    info = dataclasses.replace(run.info, engines=tuple(
        dict(e, supersedes="old" if e["name"] == "new" else "") for e in run.info.engines))
    page = render_html(RunView(dataclasses.replace(run, info=info)))
    assert "Engine versions" in page and "hit: agree -&gt; disagree (tolerance)" in page
