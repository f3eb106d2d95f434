"""The runner, tested with fake adapters of known behaviour."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Category, Observation, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.store import ResultsStore, read_cases, read_results
from crosscheck.run.execute import Outcome
from crosscheck.run.runner import run, score_case, timed_sample
from crosscheck.truth import oracle
from tests import fakes
from tests.conftest import response, sphere

CASES: list[AnyCase] = [sphere(0.0, 2.0, id="apart"), sphere(0.0, 1.0, id="touch"),
                        sphere(0.0, 0.0, id="coincident"),
                        response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], id="resp")]


def run_fakes(tmp_path: Path, *engines: Adapter, quick: bool = True) -> pd.DataFrame:
    store = ResultsStore(tmp_path / "run")
    run(CASES, list(engines), store, RunOptions(quick=quick, min_sample_s=0.001, samples=3))
    store.close()
    return read_results(tmp_path / "run")


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
    assert (timed["query_s"] > 0).all() and (timed["loops"] >= 1).all()
    assert (timed["setup_s"] >= 0).all()


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


def test_timing_sample_is_per_file_kind_and_dim_without_twins_or_bad_input() -> None:
    cases = [sphere(0.0, 2.0 + i, id=f"s{i}") for i in range(5)]
    cases = [c.model_copy(update={"source": "cases/a.toml"}) for c in cases]
    twin = cases[0].model_copy(update={"id": "s0.swapped", "tags": ("swapped",)})
    bad = cases[1].model_copy(update={"id": "bad", "tags": ("bad-input",)})
    other = cases[2].model_copy(update={"id": "o", "source": "cases/b.toml"})
    options = RunOptions(time_per_group=2)
    assert timed_sample([twin, bad, *cases, other], options) == {"s0", "s1", "o"}
    assert timed_sample(cases, RunOptions(quick=True, time_per_group=2)) == frozenset()
    every = RunOptions(time_per_group=0)
    assert timed_sample([twin, *cases], every) == {twin.id, *options_ids(cases)}


def test_untimed_cases_have_no_timing(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path / "run")
    cases = [sphere(0.0, 2.0 + i, id=f"s{i}") for i in range(4)]
    run(cases, [fakes.AlwaysRight()], store,
        RunOptions(min_sample_s=0.001, samples=3, time_per_group=1))
    store.close()
    frame = read_results(tmp_path / "run").drop_duplicates("case_id")
    assert list(frame["loops"] > 0) == [True, False, False, False]


def options_ids(cases: list[AnyCase]) -> set[str]:
    return {case.id for case in cases}
