"""crosscheck compare: what differs up front, verdicts on the overlap, timings from samples.

Run folders are built here by hand (run.json, results.jsonl, timings.jsonl) with
samples drawn from a seeded RNG, and for runs timed in rounds a machine whose
speed is given per round: nothing is timed.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from crosscheck.cli import main
from crosscheck.compare.runs import Comparison, compare, verdict_changes
from crosscheck.compare.timing import MIN_EFFECT, OLD_FORMAT
from crosscheck.core.model import COLUMNS, Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.store import ResultsStore
from crosscheck.results.timings import MIN_SAMPLES, TimingRecord

FORMAT1 = Path(__file__).resolve().parent.parent / "data" / "format1-run"
ENGINES = ("e1", "e2")
MEDIANS = (2e-6, 5e-6, 1e-5, 4e-5, 1e-3)
"""The medians of the synthetic samples; :func:`median` picks one per case."""


def median(case_id: str) -> float:
    """The median time of ``case_id``, the same in every run."""
    return MEDIANS[sum(map(ord, case_id)) % len(MEDIANS)]


def yardstick(scale: float = 1.0) -> dict[str, Any]:
    """A run's ``timing`` with a yardstick ``scale`` times the base machine's time."""
    def workload(median: float) -> dict[str, Any]:
        return {"median_s": median * scale, "q1_s": median * scale, "q3_s": median * scale,
                "values": [median * scale] * 5}
    end = {"numpy": workload(1e-3), "python": workload(2e-3)}
    return {"method": "test", "sampled": 0, "pinned": "no", "binding": {},
            "yardstick": {"start": end, "end": end}}


def record(case_id: str, engine: str, status: str = "agree") -> Record:
    return Record(case_id=case_id, source="cases/t.toml", kind="sphere", dim=3, tags="",
                  engine=engine, quantity="hit", value="true", truth="true", error=0.0,
                  tolerance=0.0, status=Status(status), category="", reason="",
                  setup_s=math.nan, query_s=math.nan, query_iqr_s=math.nan, loops=0,
                  unstable=False)


def samples(rng: np.random.Generator, median: float, n: int = 20) -> list[float]:
    """``n`` samples around ``median`` with a 5% log-normal spread (a stable measurement)."""
    return list(median * rng.lognormal(0.0, 0.05, n))


def make_run(directory: Path, cases: Iterable[str], *, seed: int, slower: float = 1.0,
             timing: dict[str, Any] | None = None, n: int = 20,
             statuses: dict[str, str] | None = None, options: RunOptions | None = None,
             versions: dict[str, str] | None = None,
             untimed: Iterable[tuple[str, str]] = (),
             machine: Sequence[float] | None = None) -> Path:
    """A run folder: one ``hit`` row and one timing record per case x engine.

    ``slower`` multiplies every sample; ``n`` is the samples per pair; pairs in
    ``untimed`` have no timing record.  ``machine``: a run timed in rounds, the
    machine's slowness per round (``n`` of them): each sample is multiplied by its
    round's, and stored with its round's yardstick, 1 ms times it (None: a run timed
    before the rounds, no yardstick per sample).
    """
    cases, skip, rng = list(cases), set(untimed), np.random.default_rng(seed)
    store = ResultsStore(directory)
    store.append(record(c, e, (statuses or {}).get(c, "agree")) for c in cases for e in ENGINES)
    store.write_run_info(RunInfo(
        run_id=directory.name, command="test", options=options or RunOptions(),
        machine={"cpu": "test"}, started="", finished="", cases_run=len(cases),
        engines=tuple({"name": e, "engine": "fake", "version": (versions or {}).get(e, "1")}
                      for e in ENGINES), timing=timing))
    store.close()
    slowness = machine or [1.0] * n
    sticks = tuple(1e-3 * m for m in machine) if machine else ()
    lines = [TimingRecord(c, e, "sphere", "call", 100, 0.0, tuple(
        slower * v * m for v, m in zip(samples(rng, median(c), n), slowness, strict=True)),
        sticks).to_json() for c in cases for e in ENGINES if (c, e) not in skip]
    (directory / "timings.jsonl").write_text("".join(line + "\n" for line in lines))
    return directory


CASES = [f"c{i}" for i in range(30)]


def compared(tmp_path: Path, a: dict[str, Any], b: dict[str, Any],
             cases_b: list[str] | None = None) -> tuple[Comparison, pd.DataFrame]:
    """Compare two synthetic runs of ``CASES`` (B: ``cases_b``); the result and timing CSV."""
    run_a = make_run(tmp_path / "a", CASES, seed=1, **a)
    run_b = make_run(tmp_path / "b", cases_b or CASES, seed=2, **b)
    result = compare(run_a, run_b, tmp_path / "cmp")
    return result, pd.read_csv(tmp_path / "cmp" / "timing_changes.csv")


def test_the_same_distribution_in_both_runs_flags_nothing(tmp_path: Path) -> None:
    result, timings = compared(tmp_path, {"timing": yardstick()}, {"timing": yardstick()})
    assert result.timing_counts == {"slower": 0, "faster": 0, "same": 60, "unknown": 0}
    assert result.normalised and result.differences == []
    assert list(timings.columns) == ["case_id", "engine", "n_a", "n_b", "median_a_s",
                                     "median_b_s", "ratio", "raw_ratio", "p_value", "verdict",
                                     "reason"]
    assert timings["ratio"].between(0.9, 1.1).all()


def test_twice_as_slow_is_flagged_slower_on_every_pair(tmp_path: Path) -> None:
    result, timings = compared(tmp_path, {"timing": yardstick()},
                               {"timing": yardstick(), "slower": 2.0})
    assert result.timing_counts["slower"] == 60 == result.timing_changes
    assert set(timings["verdict"]) == {"slower"} and (timings["p_value"] < 1e-6).all()
    assert timings["ratio"].between(1.8, 2.2).all()
    per_engine = pd.read_csv(tmp_path / "cmp" / "timing_engines.csv").set_index("engine")
    assert list(per_engine.index) == list(ENGINES) and (per_engine["slower"] == 30).all()
    assert per_engine["geomean_ratio"].between(1.9, 2.1).all()
    html = (tmp_path / "cmp" / "compare.html").read_text()
    assert "60 slower" in html and "Mann-Whitney" in html and f"&times;{MIN_EFFECT}" in html


def test_a_slower_machine_is_normalised_away_by_the_yardstick(tmp_path: Path) -> None:
    result, timings = compared(tmp_path, {"timing": yardstick()},
                               {"timing": yardstick(2.0), "slower": 2.0})
    assert result.timing_counts["same"] == 60 and result.normalised
    assert "2.000" in result.normalisation
    assert timings["ratio"].between(0.9, 1.1).all()


def test_an_unsteady_yardstick_is_said(tmp_path: Path) -> None:
    moved = yardstick()
    moved["yardstick"] = {"start": moved["yardstick"]["start"],
                          "end": yardstick(1.5)["yardstick"]["end"]}
    result, _ = compared(tmp_path, {"timing": moved}, {"timing": yardstick()})
    assert not result.normalised  # a ruler that moved during its own run measures nothing
    assert any(d.startswith("yardstick not used, it was unsteady (A: numpy x1.50 from start "
                            "to end") for d in result.differences)


def test_without_a_yardstick_nothing_is_normalised_and_the_comparison_says_so(
        tmp_path: Path) -> None:
    result, _ = compared(tmp_path, {"timing": None}, {"timing": yardstick(2.0), "slower": 2.0})
    assert not result.normalised and result.timing_counts["slower"] == 60
    assert any("no yardstick in A" in d for d in result.differences)


STEADY = [1.0] * 20
"""A machine that kept its speed through the 20 rounds of a run."""


def test_raw_slower_within_the_drift_the_rounds_measured_is_unknown(tmp_path: Path) -> None:
    drifting = [1.4] * 18 + [2.2] * 2  # B's machine: slower, and slower still in two rounds
    result, timings = compared(tmp_path, {"timing": yardstick(), "machine": STEADY},
                               {"timing": yardstick(), "machine": drifting})
    assert result.timing_counts == {"slower": 0, "faster": 0, "same": 0, "unknown": 60}
    assert result.normalised and "its round's yardstick" in result.normalisation
    assert "A x1.00, B x1.57; B's over A's: x1.40" in result.normalisation
    assert timings["ratio"].between(0.9, 1.1).all() and timings["raw_ratio"].gt(1.2).all()
    reasons = timings["reason"].str.replace(r"^x1\.\d\d slower raw", "x slower raw", regex=True)
    assert set(reasons) == {"x slower raw, within the machine's drift x1.57 measured by B's round "
                            "yardsticks"}


def test_faster_after_the_yardsticks_but_not_raw_is_unknown(tmp_path: Path) -> None:
    # B's engine 1.5 times slower on a machine 1.5 times faster: raw, nothing moved
    result, timings = compared(tmp_path, {"timing": yardstick(), "machine": STEADY},
                               {"timing": yardstick(), "machine": [1 / 1.5] * 20,
                                "slower": 1.5})
    assert result.timing_counts["unknown"] == 60
    assert timings["reason"].str.match(
        r"x1\.\d\d slower normalised, but not raw \(.*\), (within|beyond) the machine's drift "
        r"x1\.50 measured between the two runs' round yardsticks$").all()
    # "within" only where the normalised ratio is no larger than the drift: the reason's own
    # numbers support it (the drift is exactly x1.5 here)
    within = timings["reason"].str.contains("), within the machine's drift", regex=False)
    assert (within == (timings["ratio"] <= 1.5 * (1 + 1e-9))).all() and within.any()


def test_twice_as_slow_in_rounds_is_slower_on_every_pair_despite_the_drift(
        tmp_path: Path) -> None:
    result, timings = compared(tmp_path, {"timing": yardstick(), "machine": STEADY},
                               {"timing": yardstick(), "machine": [1.0] * 10 + [1.5] * 10,
                                "slower": 2.0})
    assert result.timing_counts["slower"] == 60
    assert timings["ratio"].between(1.8, 2.2).all() and timings["raw_ratio"].gt(2.2).all()
    assert timings["reason"].str.startswith("normalised: p = ").all()
    per_engine = pd.read_csv(tmp_path / "cmp" / "timing_engines.csv")
    assert (per_engine["geomean_raw"] > per_engine["geomean_ratio"] * 1.1).all()


def test_a_run_in_rounds_against_one_before_them_is_judged_the_old_way(tmp_path: Path) -> None:
    result, timings = compared(tmp_path, {"timing": yardstick()},
                               {"timing": yardstick(2.0), "machine": [2.0] * 20})
    assert result.timing_counts["same"] == 60
    assert result.normalised and result.normalisation.startswith(
        "B's samples divided by the yardstick ratio B/A = 2.000")
    assert timings["raw_ratio"].between(1.8, 2.2).all()


def test_too_few_samples_or_one_run_only_is_unknown_never_a_change(tmp_path: Path) -> None:
    few = [f"f{i}" for i in range(3)]
    run_a = make_run(tmp_path / "a", [*CASES, *few], seed=1, timing=yardstick(),
                     untimed=[("c0", "e1")])
    run_b = make_run(tmp_path / "b", [*CASES, *few], seed=2, timing=yardstick(), slower=3.0,
                     n=MIN_SAMPLES - 1, untimed=[("c1", "e2")])
    result = compare(run_a, run_b, tmp_path / "cmp")
    timings = pd.read_csv(tmp_path / "cmp" / "timing_changes.csv").set_index(
        ["case_id", "engine"])
    assert result.timing_counts == {"slower": 0, "faster": 0, "same": 0, "unknown": 66}
    assert timings.loc[("c0", "e1"), "reason"] == "timed in B only"
    assert timings.loc[("c1", "e2"), "reason"] == "timed in A only"
    assert timings.loc[("f0", "e1"), "reason"] == f"fewer than {MIN_SAMPLES} samples"
    assert timings.loc[("f0", "e1"), "n_b"] == MIN_SAMPLES - 1


def test_different_case_sets_are_said_up_front_and_verdicts_compare_the_overlap(
        tmp_path: Path) -> None:
    cases_b = [*CASES[5:], "new1", "new2"]
    result, timings = compared(
        tmp_path, {"timing": yardstick()},
        {"timing": yardstick(), "statuses": {"c7": "disagree", "new1": "disagree"}}, cases_b)
    assert (len(result.removed_cases), len(result.added_cases)) == (5, 2)
    assert result.added_cases == ["new1", "new2"] and result.shared_cases == 25
    assert result.differences[0].startswith("case sets differ: 5 only in A (removed), "
                                            "2 only in B (added)")
    assert result.verdict_changes == 2 and result.shared_rows == 50  # c7 on both engines
    changes = pd.read_csv(tmp_path / "cmp" / "verdict_changes.csv")
    assert set(changes["case_id"]) == {"c7"}
    case_changes = pd.read_csv(tmp_path / "cmp" / "case_changes.csv")
    assert case_changes["change"].value_counts().to_dict() == {"removed": 5, "added": 2}
    assert len(timings) == 50 and not timings["case_id"].isin(["c0", "new1"]).any()
    html = (tmp_path / "cmp" / "compare.html").read_text()
    assert html.index("What differs") < html.index("Verdicts that changed") < html.index(
        "Timing changes")
    assert "cases only in A (removed)" in html


def test_engines_in_one_run_only_are_left_out(tmp_path: Path) -> None:
    run_b = make_run(tmp_path / "b", CASES, seed=2, timing=yardstick())
    run_a = make_run(tmp_path / "a", CASES, seed=1, timing=yardstick())
    info = (run_a / "run.json").read_text().replace('"e2"', '"e3"')
    (run_a / "run.json").write_text(info)
    rows = (run_a / "results.jsonl").read_text().replace('"e2"', '"e3"')
    (run_a / "results.jsonl").write_text(rows)
    (run_a / "timings.jsonl").write_text(
        (run_a / "timings.jsonl").read_text().replace('"e2"', '"e3"'))
    result = compare(run_a, run_b, tmp_path / "cmp")
    assert (result.removed_engines, result.added_engines) == (["e3"], ["e2"])
    assert result.shared_rows == 30 and result.timing_pairs == 30


def test_an_old_format_run_has_every_timing_pair_unknown(tmp_path: Path) -> None:
    old = tmp_path / "old"
    shutil.copytree(FORMAT1, old)
    result = compare(old, old, tmp_path / "cmp")
    timings = pd.read_csv(tmp_path / "cmp" / "timing_changes.csv")
    assert result.timing_pairs == 2 == result.timing_counts["unknown"]  # pymunk's scenes
    assert set(timings["reason"]) == {OLD_FORMAT}
    assert result.samples_missing == [f"A: {OLD_FORMAT}", f"B: {OLD_FORMAT}"]
    assert result.verdict_changes == 0 and result.shared_rows == 40


def test_cli_prints_the_differences_as_warnings_then_the_counts(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    run_a = make_run(tmp_path / "a", CASES, seed=1, timing=yardstick())
    run_b = make_run(tmp_path / "b", CASES[2:], seed=2, timing=yardstick(), slower=2.0,
                     options=RunOptions(samples=30), versions={"e1": "2"},
                     statuses={"c4": "disagree"})
    assert main(["compare", str(run_a), str(run_b), "--out", str(tmp_path / "cmp")]) == 0
    captured = capsys.readouterr()
    warnings = captured.err.replace("\n", " ")
    assert "warning: case sets differ: 2 only in A (removed), 0 only in B (added)" in warnings
    assert f"warning: options differ: samples: {RunOptions().samples} vs 30" in warnings
    assert "warning: engine versions differ: e1: 1 vs 2" in warnings
    line = captured.out.replace("\n", " ")
    assert "2 verdict changes among the 56 shared rows (0 added, 2 removed)" in line
    assert "timing: 56 slower, 0 faster, 0 unknown of 56 pairs (p < 0.001 and beyond x" in line


def frame(rows: list[dict[str, object]]) -> pd.DataFrame:
    base: dict[str, object] = {c: "" for c in COLUMNS}
    base.update(error=0.0, query_iqr_s=0.0, query_s=math.nan)
    return pd.DataFrame([{**base, **row} for row in rows], columns=list(COLUMNS))


def test_verdict_changes_are_status_and_category_changes_of_shared_rows() -> None:
    a = frame([{"case_id": "c1", "engine": "e", "quantity": "hit", "status": "agree"},
               {"case_id": "c2", "engine": "e", "quantity": "hit", "status": "disagree",
                "category": "tolerance"},
               {"case_id": "c3", "engine": "e", "quantity": "hit", "status": "agree"},
               {"case_id": "gone", "engine": "e", "quantity": "hit", "status": "agree"}])
    b = frame([{"case_id": "c1", "engine": "e", "quantity": "hit", "status": "disagree",
                "category": "error"},
               {"case_id": "c2", "engine": "e", "quantity": "hit", "status": "disagree",
                "category": "error"},
               {"case_id": "c3", "engine": "e", "quantity": "hit", "status": "agree"},
               {"case_id": "new", "engine": "e", "quantity": "hit", "status": "agree"}])
    assert list(verdict_changes(a, b)["case_id"]) == ["c1", "c2"]


def test_compare_cli_writes_csv_and_html(tmp_path: Path) -> None:
    case_file = str(Path(__file__).resolve().parents[2] / "cases" / "sphere.toml")
    for name, engine in (("a", "reference"), ("b", "reference-f32")):
        assert main(["run", case_file, "--quick", "--engine", engine,
                     "--out", str(tmp_path / name)]) == 0
    out = tmp_path / "cmp"
    assert main(["compare", str(tmp_path / "a"), str(tmp_path / "b"), "--out", str(out)]) == 0
    assert pd.read_csv(out / "verdict_changes.csv").empty  # engines differ: nothing in common
    assert pd.read_csv(out / "timing_changes.csv").empty  # --quick: nothing timed
    html = (out / "compare.html").read_text()
    assert "engines only in B (not compared): reference-f32" in html
