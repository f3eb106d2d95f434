"""The verdict on common ground: standard profiles, ranked engines, coverage, baselines apart,
bad input judged as robustness.

Every frame is built by hand here; each expectation is counted from the rows of the test.
"""

from __future__ import annotations

import math
from typing import Any

import pandas as pd

from crosscheck.report import profiles
from crosscheck.report.style import templates
from crosscheck.report.verdict import verdict

DETECTION_3D = profiles.PROFILES[0]


def row(case_id: str, engine: str, status: str = "agree", quantity: str = "hit",
        kind: str = "sphere", dim: int = 3, tags: str = "basic",
        reason: str = "", query_s: float = 1e-6) -> dict[str, Any]:
    return {"case_id": case_id, "kind": kind, "dim": dim, "tags": tags, "engine": engine,
            "quantity": quantity, "status": status, "category": "", "reason": reason,
            "query_s": query_s, "unstable": False}


def test_an_engine_that_skips_what_it_gets_wrong_does_not_outrank_one_that_answers() -> None:
    frame = pd.DataFrame([
        row("a", "honest"), row("b", "honest", "disagree", reason="error 0.5 beyond 1e-15"),
        row("a", "skipper"), row("b", "skipper", "skip"),
        row("c", "honest"), row("c", "skipper")])
    answer = profiles.profile(frame, DETECTION_3D)
    assert [s.engine for s in answer.ranked] == ["honest", "skipper"]
    honest, skipper = answer.ranked
    # both are scored on the rows both answer (a and c), so both agree on 2 of 2
    assert (honest.score.agree, honest.score.judged) == (2, 2) == (
        skipper.score.agree, skipper.score.judged)
    assert (honest.answered, skipper.answered, honest.total) == (3, 2, 3)
    assert answer.common == 2 and answer.cases == 2


def test_a_2d_only_engine_is_not_ranked_for_3d_and_says_what_it_lacks() -> None:
    frame = pd.DataFrame([
        row("s3", "both"), row("s3", "flat", "skip"),
        row("b3", "both", kind="aabb"), row("b3", "flat", "skip", kind="aabb"),
        row("s2", "both", dim=2), row("s2", "flat", dim=2)])
    answer = profiles.profile(frame, DETECTION_3D)
    assert [s.engine for s in answer.ranked] == ["both"]
    assert [(n.engine, n.lacks) for n in answer.not_ranked] == [
        ("flat", ("aabb 3-D", "sphere 3-D"))]
    two_d = profiles.profile(frame, profiles.PROFILES[1])
    assert [s.engine for s in two_d.ranked] == ["both", "flat"] and not two_d.not_ranked


def test_the_textbook_formulas_are_baselines_never_ranked() -> None:
    frame = pd.DataFrame([row("a", "reference"), row("a", "engine", "disagree"),
                          row("a", "reference-f32", "disagree")])
    answer = profiles.profile(frame, DETECTION_3D)
    assert [s.engine for s in answer.ranked] == ["engine"]
    assert [s.engine for s in answer.baselines] == ["reference", "reference-f32"]
    assert answer.baselines[0].score.share == 1.0 and answer.ranked[0].score.share == 0.0


def test_bad_input_is_left_out_of_accuracy_and_counted_as_robustness() -> None:
    bad = "bad-input swapped"  # the case's declared tag, whatever file it is in
    frame = pd.DataFrame([
        row("ok", "engine", tags="bad-inputs"),  # a tag that only starts alike is not it
        row("nan", "engine", "crash", tags=bad), row("inf", "engine", "error", tags=bad),
        row("neg", "engine", "timeout", tags=bad), row("big", "engine", "skip", tags=bad),
        row("nan", "engine", "error", quantity="distance", tags=bad)])  # one case, worst: crash
    answer = profiles.profile(frame, DETECTION_3D)
    assert answer.total == 1 and answer.ranked[0].score.share == 1.0
    (robust,) = profiles.robustness(frame)
    assert (robust.answered, robust.crash, robust.error, robust.timeout) == (3, 1, 1, 1)


def test_ranked_by_score_then_coverage_then_cost() -> None:
    frame = pd.DataFrame([
        row("a", "slow", query_s=5e-6), row("b", "slow", query_s=5e-6),
        row("a", "fast", query_s=1e-6), row("b", "fast", query_s=1e-6),
        row("a", "wrong", "disagree"), row("b", "wrong")])
    answer = profiles.profile(frame, DETECTION_3D)
    assert [s.engine for s in answer.ranked] == ["fast", "slow", "wrong"]
    assert answer.ranked[0].cost is not None and math.isclose(answer.ranked[0].cost.median, 1e-6)


def test_a_failure_mode_keeps_the_numbers_of_its_example() -> None:
    reason = "error 1.2e-06 beyond the agree bound 3.5e-15 (size 1)"
    frame = pd.DataFrame([row("a", "engine", "disagree", reason=reason, quantity="distance")])
    (mode,) = profiles.profile(frame, DETECTION_3D).ranked[0].modes
    assert mode.reason == reason and "#" in mode.pattern


def test_the_block_shows_each_profile_with_coverage_beside_the_score() -> None:
    frame = pd.DataFrame([
        row("a", "honest"), row("b", "honest", "disagree"),
        row("a", "skipper"), row("b", "skipper", "skip"),
        row("r", "engine", kind="sphere_response", quantity="v1", dim=2),
        row("x", "engine", "crash", tags="bad-input")])
    html = templates().get_template("_verdict.html.j2").render(
        verdict(frame) | profiles.context(frame))
    assert html.count('class="verdict-profile"') == 2
    assert 'data-profile="3-D detection"' in html and 'data-profile="responses"' in html
    assert "<b>50.0%</b><small>1 / 2</small>" in html  # skipper's coverage
    assert "Robustness" in html and "verdict-kinds" in html
