"""The verdict as a newcomer reads it: it says what its score counts, and its headline
failure modes leave out bad-input cases and zero-size bodies (their rows still count, and
the list of all failure modes keeps them, labelled).

Every frame is built by hand here; each expectation is counted from the rows of the test.
"""

from __future__ import annotations

import re
from html import unescape
from typing import Any

import pandas as pd

from crosscheck.report import aside, profiles, verdict
from crosscheck.report.style import templates
from tests.conftest import aabb, sphere

REFUSED = "ValueError: MuJoCo's compiler refuses this case: Error: size 0 must be positive"
TOO_FAR = "error 1e-06 beyond the agree bound 2e-15 (size 1)"


def row(case_id: str, status: str = "agree", reason: str = "", tags: str = "",
        quantity: str = "hit") -> dict[str, Any]:
    return {"case_id": case_id, "kind": "aabb", "dim": 3, "tags": tags, "engine": "e",
            "quantity": quantity, "status": status, "category": "", "reason": reason,
            "query_s": 1e-6, "unstable": False}


def frame() -> pd.DataFrame:
    """One engine: refused on a zero-size box (3 rows), crashed on a bad-input case (3 rows),
    too far on two plain cases' distances, right on everything else."""
    quantities = ("hit", "distance", "normal")
    rows = [row("point", "error", REFUSED, "degenerate", q) for q in quantities]
    rows += [row("nan", "crash", "worker killed by SIGSEGV", "bad-input", q) for q in quantities]
    for case_id in ("plain-1", "plain-2"):
        rows += [row(case_id), row(case_id, "disagree", TOO_FAR, quantity="distance")]
    rows += [row(f"fine-{i}", quantity=q) for i in range(4) for q in quantities]
    return pd.DataFrame(rows)


def page_text(zero_sized: frozenset[str]) -> str:
    data = frame()
    context = verdict.verdict(data, (), None, zero_sized) | profiles.context(
        data, (), zero_sized) | {"run_dir": "run"}
    html = templates().get_template("_verdict.html.j2").render(**context)
    return " ".join(unescape(re.sub(r"<[^>]+>", "", html)).split())


def test_zero_size_names_the_cases_with_a_radius_or_half_width_of_zero() -> None:
    cases = {"point": sphere(0.0, 2.0, ra=0.0, id="point"),
             "slab": aabb([0.0, 0.0], [1.0, 0.0], [3.0, 0.0], [1.0, 1.0], id="slab"),
             "plain": sphere(0.0, 2.0, id="plain")}
    assert aside.zero_size(cases) == {"point", "slab"}


def test_the_top_failure_modes_leave_out_bad_input_and_zero_size_cases() -> None:
    [only] = verdict.verdicts(frame(), zero_sized={"point"})
    assert [m.reason for m in only.top] == [TOO_FAR]
    assert only.set_aside == 6 and only.breaking == 8  # the rows still count
    assert {m.aside for m in only.modes} == {"zero size", "bad input", ""}


def test_a_profiles_top_failure_modes_leave_out_zero_size_bodies() -> None:
    [ranked] = profiles.profile(frame(), profiles.PROFILES[0], zero_sized={"point"}).ranked
    assert [m.reason for m in ranked.top] == [TOO_FAR]
    assert ranked.set_aside == 3  # bad input is not in a profile at all
    assert ranked.score.judged == 3 + 2 * 2 + 4 * 3  # the zero-size rows stay in the score


def test_the_page_counts_the_rows_set_aside_and_lists_them_labelled() -> None:
    text = page_text(frozenset({"point"}))
    assert "set aside: 3 rows on zero-size bodies" in text
    assert "set aside: 6 rows on bad input or zero-size bodies" in text
    assert text.count(REFUSED) == 0  # in no headline; the full list shows its pattern
    assert "zero size" in text and "bad input" in text


def test_the_verdict_says_which_rows_and_statuses_its_score_counts() -> None:
    text = page_text(frozenset())
    assert "(score: agree share of 19 common rows)" in text
    assert "bad-input cases left out" in text
    assert "agree, the one status counted right" in text
    assert "Every disagree counts as wrong, whatever its category" in text
    assert "skip and undefined rows count neither way" in text
