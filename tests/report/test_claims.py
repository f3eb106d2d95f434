"""Published claims against a run's rows: the verdict, the worst row, the regime, the units, the
rows without an error kept apart; and the claims' round trip through run.json into the page."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, ClassVar

import pandas as pd
import pytest

from crosscheck.core.claims import APART, OVERLAP, Claim
from crosscheck.core.contract import engine_info
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.report import claims
from crosscheck.report.render import render
from crosscheck.results.run import Run, read_run
from crosscheck.results.runinfo import RunInfo, claims_of
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from crosscheck.truth import oracle
from tests.conftest import aabb, sphere
from tests.fakes import AlwaysRight, OffByOne

ENGINE = "e"
DISTANCE = Claim("distance", ("sphere",), 1e-6, "distance within 1e-6", "https://example.org")


def _case(case_id: str, a: float, b: float, r: float = 0.5) -> AnyCase:
    return sphere(a, b, ra=r, rb=r, id=case_id)


def _run(cases: list[AnyCase], rows: list[dict[str, Any]], engines: tuple[str, ...] = (ENGINE,),
         ) -> Run:
    """A run of ``cases`` whose results are ``rows`` (case_id, quantity, error, status; the
    truth of a distance row is the case's exact distance, as a run stores it)."""
    by_id = {c.id: c for c in cases}
    full = []
    for row in rows:
        case = by_id[row["case_id"]]
        truth = oracle.truth(case).get(row["quantity"])
        full.append({"kind": case.kind, "dim": case.dim, "engine": ENGINE, "origin": "",
                     "value": "null", **row,
                     "truth": "null" if not isinstance(truth, float) else repr(truth)})
    frame = pd.DataFrame(full, columns=["case_id", "kind", "dim", "engine", "quantity", "value",
                                        "truth", "error", "status", "origin"])
    info = RunInfo(run_id="r", command="test", options=RunOptions(quick=True), machine={},
                   engines=tuple({"name": e} for e in engines), started="s")
    run = Run(Path("unused"), info, by_id)
    decoded = pd.DataFrame({"truth_decoded": [oracle.truth(by_id[r["case_id"]]).get(
        r["quantity"]) for r in full]}, index=frame.index, dtype=object)
    return run.with_results(frame, decoded)


def _one(run: Run, claim: Claim, engine: str = ENGINE) -> claims.ClaimCheck:
    [check] = claims.evaluate(run, {engine: (claim,)})
    return check


def test_a_claim_holds_when_every_row_inside_is_within_its_bound() -> None:
    run = _run([_case("a", 0, 2), _case("b", 0, 3)],
               [{"case_id": "a", "quantity": "distance", "error": 1e-7, "status": "agree"},
                {"case_id": "b", "quantity": "distance", "error": 9e-7, "status": "disagree"}])
    check = _one(run, DISTANCE)
    assert (check.verdict, check.inside, check.why) == ("holds", 2, "")
    assert check.worst_inside is not None and check.worst_inside.case_id == "b"


def test_a_claim_fails_on_its_worst_row() -> None:
    run = _run([_case("a", 0, 2), _case("b", 0, 3), _case("c", 0, 4)],
               [{"case_id": "a", "quantity": "distance", "error": 2e-6, "status": "disagree"},
                {"case_id": "b", "quantity": "distance", "error": 5e-6, "status": "disagree"},
                {"case_id": "c", "quantity": "distance", "error": 1e-7, "status": "agree"}])
    check = _one(run, DISTANCE)
    assert check.verdict == "fails"
    assert check.worst_inside is not None
    assert (check.worst_inside.case_id, check.worst_inside.error) == ("b", 5e-6)
    assert check.why.startswith("error 5e-06 > 1e-06")


def test_an_engine_not_in_the_run_leaves_its_claim_untested() -> None:
    run = _run([_case("a", 0, 2)],
               [{"case_id": "a", "quantity": "distance", "error": 0.0, "status": "agree"}])
    check = _one(run, DISTANCE, engine="absent")
    assert (check.verdict, check.why) == ("untested", "engine not in the run")


def test_no_case_in_the_regime_leaves_a_claim_untested_and_counts_the_rows_outside() -> None:
    run = _run([_case("a", 0, 2)],
               [{"case_id": "a", "quantity": "distance", "error": 3.0, "status": "disagree"}])
    small = Claim("distance", ("sphere",), 1e-6, "s", "u", size=(0.001, 0.01))
    check = _one(run, small)
    assert check.verdict == "untested" and "no case in the regime" in check.why
    assert check.inside == 0 and check.outside == 1
    assert check.worst_outside is not None and check.worst_outside.error == 3.0


def test_a_claim_on_another_quantity_or_dimension_is_untested_with_why() -> None:
    run = _run([_case("a", 0, 2)],
               [{"case_id": "a", "quantity": "distance", "error": 0.0, "status": "agree"}])
    check = _one(run, Claim("distance", ("sphere",), 1e-6, "s", "u", dims=(2,)))
    assert check.verdict == "untested" and "no row of e answers distance" in check.why


def test_a_relative_bound_is_the_bound_times_each_rows_size() -> None:
    # 0.05 on a body of radius 100 is within 1e-3 x 100; 0.002 on radius 1 is beyond 1e-3 x 1
    run = _run([_case("big", 0, 300, r=100.0), _case("unit", 0, 3, r=1.0)],
               [{"case_id": "big", "quantity": "distance", "error": 0.05, "status": "disagree"},
                {"case_id": "unit", "quantity": "distance", "error": 0.002,
                 "status": "disagree"}])
    relative = Claim("distance", ("sphere",), 1e-3, "s", "u", relative=True)
    check = _one(run, relative)
    assert check.verdict == "fails"
    assert check.worst_inside is not None and check.worst_inside.case_id == "unit"
    assert check.worst_inside.limit == pytest.approx(1e-3)
    absolute = _one(run, Claim("distance", ("sphere",), 0.1, "s", "u"))
    assert absolute.verdict == "holds"  # the same rows hold an absolute 0.1


def test_a_bound_relative_to_the_length_reads_the_largest_coordinate() -> None:
    far = sphere(1e6, 1e6 + 3, id="far")  # radius 0.5 at an offset of 1e6
    run = _run([far], [{"case_id": "far", "quantity": "distance", "error": 0.01,
                        "status": "disagree"}])
    by_size = Claim("distance", ("sphere",), 2.0**-21, "s", "u", relative=True)
    by_length = Claim("distance", ("sphere",), 2.0**-21, "s", "u", relative=True,
                      relative_to="length")
    assert _one(run, by_size).verdict == "fails"
    assert _one(run, by_length).verdict == "holds"


def test_rows_outside_the_regime_are_not_counted_inside() -> None:
    run = _run([_case("apart", 0, 2), _case("deep", 0, 0.5)],
               [{"case_id": "apart", "quantity": "distance", "error": 1e-7, "status": "agree"},
                {"case_id": "deep", "quantity": "distance", "error": 0.3,
                 "status": "disagree"}])
    apart = Claim("distance", ("sphere",), 1e-6, "s", "u", gap=APART)
    check = _one(run, apart)
    assert (check.verdict, check.inside, check.outside) == ("holds", 1, 1)
    assert check.worst_outside is not None and check.worst_outside.case_id == "deep"
    overlap = _one(run, Claim("distance", ("sphere",), 1e-6, "s", "u", gap=OVERLAP))
    assert overlap.verdict == "fails" and overlap.inside == 1


def test_skip_and_timeout_rows_are_never_read_as_zero_error() -> None:
    run = _run([_case("a", 0, 2), _case("b", 0, 3)],
               [{"case_id": "a", "quantity": "distance", "error": math.nan, "status": "skip"},
                {"case_id": "b", "quantity": "distance", "error": math.nan,
                 "status": "timeout"}])
    check = _one(run, DISTANCE)
    assert check.verdict == "untested" and check.inside == 0
    assert check.unanswered == {"skip": 1, "timeout": 1}
    assert "unanswered" in check.why
    mixed = _run([_case("a", 0, 2), _case("b", 0, 3)],
                 [{"case_id": "a", "quantity": "distance", "error": 1e-7, "status": "agree"},
                  {"case_id": "b", "quantity": "distance", "error": 0.0, "status": "crash"}])
    check = _one(mixed, DISTANCE)
    assert (check.verdict, check.inside, check.unanswered) == ("holds", 1, {"crash": 1})


def test_a_verdict_claim_clear_of_touching_reads_the_gap_from_the_geometry() -> None:
    # hit rows carry no distance: the gap is the case's exact one (a box 0.001 apart, and one
    # 0.5 apart); the near one's wrong verdict is outside a claim clear of touching by 0.005
    near = aabb([0.0, 0.0], [0.5, 0.5], [1.001, 0.0], [0.5, 0.5], id="near")
    far = aabb([0.0, 0.0], [0.5, 0.5], [1.5, 0.0], [0.5, 0.5], id="far")
    run = _run([near, far], [
        {"case_id": "near", "quantity": "hit", "error": 1.0, "status": "disagree"},
        {"case_id": "far", "quantity": "hit", "error": 0.0, "status": "agree"}])
    facts = claims.case_facts(run)
    assert facts.loc["near", "gap"] == pytest.approx(0.001)
    assert facts.loc["far", "size"] == 0.5
    clear = Claim("hit", ("aabb",), 0.0, "s", "u", clear_of_touching=0.005)
    check = _one(run, clear)
    assert (check.verdict, check.inside, check.outside) == ("holds", 1, 1)
    assert _one(run, Claim("hit", ("aabb",), 0.0, "s", "u")).verdict == "fails"


def test_the_csv_table_keeps_numbers_and_the_unit() -> None:
    run = _run([_case("a", 0, 2)],
               [{"case_id": "a", "quantity": "distance", "error": 2e-6, "status": "disagree"}])
    table = claims.frame(claims.evaluate(run, {ENGINE: (DISTANCE,), "absent": (DISTANCE,)}))
    assert list(table["verdict"]) == ["fails", "untested"]
    assert table.loc[0, "worst_inside"] == 2e-6 and table.loc[0, "unit"] == "m"
    assert math.isnan(table.loc[1, "worst_inside"])


def test_old_run_json_without_claims_reads_as_none() -> None:
    info = RunInfo(run_id="r", command="c", options=RunOptions(quick=True), machine={},
                   engines=({"name": "old"},), started="s")
    assert RunInfo.from_json(info.to_json()).claims == {"old": ()}
    assert claims_of({"name": "x", "claims": [DISTANCE.to_json()]}) == (DISTANCE,)


class OffByOneClaiming(OffByOne):
    """Off by 1 in distance, claiming 1e-6 (fails) and a verdict with no error (holds)."""

    name: ClassVar[str] = "fake-off-claiming"
    claims: ClassVar[tuple[Claim, ...]] = (
        DISTANCE, Claim("hit", ("sphere",), 0.0, "verdicts right", "https://example.org/hit",
                        gap=(0.1, math.inf)))


def test_claims_go_through_run_json_to_the_page_and_claims_csv(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    cases = [sphere(0.0, 2.0 + i / 4, id=f"s{i}") for i in range(3)]
    options, engines = RunOptions(quick=True, isolate=False), [AlwaysRight(), OffByOneClaiming()]
    assert engine_info(engines[1])["claims"] == [c.to_json() for c in OffByOneClaiming.claims]
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    run = read_run(folder)
    assert run.info.claims == {"fake-right": (), "fake-off-claiming": OffByOneClaiming.claims}
    verdicts = [c.verdict for c in claims.evaluate(run)]
    assert verdicts == ["fails", "holds"]
    render(folder)
    table = pd.read_csv(folder / "claims.csv")
    assert list(table["verdict"]) == ["fails", "holds"]
    page = (folder / "report.html").read_text(encoding="utf-8")
    assert "Published claims (1 holds, 1 fails)" in page
    assert 'id="section-published-claims"' in page


def test_an_offset_bound_keeps_far_cases_outside_the_regime() -> None:
    # a far pair (centres 1e6 from the origin) errs beyond the bound, a near one within it:
    # with the documented working range of 1e3 m only the near one is inside
    run = _run([_case("near", 0, 2), _case("far", 1e6, 1e6 + 2)],
               [{"case_id": "near", "quantity": "distance", "error": 1e-7, "status": "agree"},
                {"case_id": "far", "quantity": "distance", "error": 1e-3, "status": "disagree"}])
    bounded = Claim("distance", ("sphere",), 1e-6, "within 1e-6 near the origin",
                    "https://example.org", offset=1e3)
    check = _one(run, bounded)
    assert (check.verdict, check.inside, check.outside) == ("holds", 1, 1)
    assert check.worst_outside is not None and check.worst_outside.case_id == "far"
    assert _one(run, DISTANCE).verdict == "fails"
    assert "within 1e+03 m of the origin" in bounded.regime_words()
    assert Claim.from_json(bounded.to_json()) == bounded
