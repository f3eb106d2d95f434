"""The runner, tested with fake adapters of known behaviour."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Category, Observation, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.run import read_cases, read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.execute import Outcome
from crosscheck.run.launch import launch, new_info
from crosscheck.run.scoring import score_case
from crosscheck.run.timing_phase import timing_sample
from crosscheck.truth import oracle
from tests import fakes
from tests.conftest import response, sphere

CASES: list[AnyCase] = [sphere(0.0, 2.0, id="apart"), sphere(0.0, 1.0, id="touch"),
                        sphere(0.0, 0.0, id="coincident"),
                        response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], id="resp")]


def run_fakes(tmp_path: Path, *engines: Adapter, quick: bool = True,
              timing_cases: int = 30) -> pd.DataFrame:
    """A run of CASES on ``engines`` through launch (verdicts, then the timing phase)."""
    folder = tmp_path / "run"
    options = RunOptions(quick=quick, min_sample_s=0.001, samples=3, timing_cases=timing_cases)
    launch(ResultsStore(folder), CASES, list(engines), options,
           new_info(folder, "test", options, list(engines), CASES))
    return read_results(folder)


def statuses(frame: pd.DataFrame, engine: str) -> dict[tuple[str, str], str]:
    rows = frame[frame["engine"] == engine]
    return {(r.case_id, r.quantity): r.status for r in rows.itertuples()}


def test_always_right_agrees_except_undefined(tmp_path: Path) -> None:
    frame = run_fakes(tmp_path, fakes.AlwaysRight())
    got = statuses(frame, "fake-right")
    assert got.pop(("coincident", "normal")) == "undefined"
    assert set(got.values()) == {"agree"}
    assert len(frame) == 3 * 3 + 2


def test_off_by_one_disagrees_on_distance_only(tmp_path: Path) -> None:
    frame = run_fakes(tmp_path, fakes.OffByOne())
    bad = frame[frame["status"] == "disagree"]
    assert set(bad["quantity"]) == {"distance"}
    assert (bad["error"] == 1.0).all() and (bad["category"] == "error").all()


def test_raising_engine_gives_error_rows_and_run_continues(tmp_path: Path) -> None:
    frame = run_fakes(tmp_path, fakes.Raises(), fakes.AlwaysRight())
    raised = frame[frame["engine"] == "fake-raises"]
    assert set(raised["status"]) == {"error"}
    assert raised["reason"].str.contains("RuntimeError: engine exploded").all()
    assert (frame["engine"] == "fake-right").sum() == 11


def test_missing_capability_and_quantities_are_skips(tmp_path: Path) -> None:
    frame = run_fakes(tmp_path, fakes.HitOnly())
    got = statuses(frame, "fake-hit-only")
    assert got[("resp", "v1")] == "skip"
    assert got[("apart", "distance")] == "skip" and got[("apart", "hit")] == "agree"
    reasons = frame.set_index(["case_id", "quantity"])["reason"]
    assert "does not support sphere_response in 2-D" in reasons[("resp", "v1")]


def test_unavailable_engine_is_skipped_with_reason(tmp_path: Path) -> None:
    frame = run_fakes(tmp_path, fakes.Unavailable())
    assert set(frame["status"]) == {"skip"}
    assert set(frame["reason"]) == {"not installed here"}


def test_touching_convention_is_categorised(tmp_path: Path) -> None:
    frame = run_fakes(tmp_path, fakes.TouchingIsContact())
    row = frame[(frame["case_id"] == "touch") & (frame["quantity"] == "hit")].iloc[0]
    assert (row["status"], row["category"]) == ("disagree", "convention")


def test_timing_columns_filled_unless_quick(tmp_path: Path) -> None:
    quick = run_fakes(tmp_path / "q", fakes.AlwaysRight())
    timed = run_fakes(tmp_path / "t", fakes.AlwaysRight(), quick=False)
    assert quick["query_s"].isna().all() and (quick["loops"] == 0).all()
    # filled, not judged: what a measured time should be is crosscheck bench's business
    assert timed[["query_s", "query_iqr_s", "setup_s"]].notna().all().all()
    assert (timed["loops"] >= 1).all()


def test_cases_are_stored_for_the_report(tmp_path: Path) -> None:
    run_fakes(tmp_path, fakes.AlwaysRight())
    stored = read_cases(tmp_path / "run")
    assert list(stored) == [c.id for c in CASES]
    assert stored["resp"] == next(c for c in CASES if c.id == "resp")  # typed, as it ran


def test_half_written_line_is_ignored(tmp_path: Path) -> None:
    run_fakes(tmp_path, fakes.AlwaysRight())
    path = tmp_path / "run" / "results.jsonl"
    with path.open("a") as handle:
        handle.write('{"case_id": "trunc')
    assert len(read_results(tmp_path / "run")) == 11


def test_a_response_right_only_where_the_engine_met_the_contact_is_timestep() -> None:
    case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0])  # head-on along x
    contact = ((0.0, 0.0), (0.6, 0.8))  # where a late engine first saw the contact
    there = oracle.truth(case.model_copy(update={"b": case.b.model_copy(
        update={"center": contact[1]})}))
    seen = Observation(v1=there.v1, v2=there.v2, resolved_at=contact)
    records = score_case(case, fakes.AlwaysRight(), Outcome(seen), oracle.truth(case))
    for record in records:  # judged against the case as declared: never agree
        assert (record.status, record.category) == (Status.DISAGREE, Category.TIMESTEP)
        assert record.error_at_contact == 0.0 and record.error > 0.5
        assert "first reported the contact" in record.reason
    wrong = Observation(v1=(5.0, 5.0), v2=(5.0, 5.0), resolved_at=contact)
    (v1, _) = score_case(case, fakes.AlwaysRight(), Outcome(wrong), oracle.truth(case))
    assert v1.category == Category.ERROR and v1.error_at_contact > 1.0
    here = Observation(v1=there.v1, v2=there.v2, resolved_at=(case.a.center, case.b.center))
    (v1, _) = score_case(case, fakes.AlwaysRight(), Outcome(here), oracle.truth(case))
    assert v1.category == Category.ERROR and math.isnan(v1.error_at_contact)


def test_the_timing_sample_is_seeded_per_engine_and_kind_without_twins_bad_input_or_failures(
        ) -> None:
    cases = [sphere(0.0, 2.0 + i, id=f"s{i}") for i in range(40)]
    twin = cases[0].model_copy(update={"id": "s0.swapped", "twin_of": "s0"})
    bad = cases[1].model_copy(update={"id": "bad", "tags": ("bad-input",)})
    failed = cases[2].model_copy(update={"id": "failed"})
    suite = [twin, bad, failed, *cases]
    engine = fakes.AlwaysRight()
    frame = pd.DataFrame([{"case_id": c.id, "engine": engine.name, "kind": c.kind,
                           "status": "crash" if c is failed else "agree", "query_s": math.nan}
                          for c in suite])
    options = RunOptions(timing_cases=30)
    chosen = [c.id for c, _ in timing_sample(suite, [engine], frame, options)]
    assert len(chosen) == 30 and not {"s0.swapped", "bad", "failed"} & set(chosen)
    assert chosen == [c.id for c in suite if c.id in chosen]  # in suite order
    again = [c.id for c, _ in timing_sample(suite, [engine], frame, options)]
    other = timing_sample(suite, [engine], frame, RunOptions(timing_cases=30, timing_seed=1))
    assert again == chosen and [c.id for c, _ in other] != chosen


def test_untimed_cases_have_no_timing(tmp_path: Path) -> None:
    frame = run_fakes(tmp_path, fakes.AlwaysRight(), quick=False, timing_cases=1)
    timed = frame.drop_duplicates("case_id").groupby("kind")["loops"].apply(
        lambda s: int((s > 0).sum()))
    assert timed.to_dict() == {"sphere": 1, "sphere_response": 1}


def options_ids(cases: list[AnyCase]) -> set[str]:
    return {case.id for case in cases}
