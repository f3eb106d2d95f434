"""Baselines: every rule of the judge's table, the file's round trip and its refusals."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from crosscheck.results.baseline import (
    DEFAULT_MARGIN,
    DEFAULT_STALE_FACTOR,
    Baseline,
    BaselineError,
    Entry,
    Finding,
    Verdict,
    from_rows,
    judge,
    read_baseline,
    updated,
    write_baseline,
)


def frame(*rows: dict[str, Any]) -> pd.DataFrame:
    """A results frame of the columns judge reads."""
    return pd.DataFrame(list(rows), columns=["case_id", "engine", "quantity", "status",
                                             "category", "error", "tolerance", "reason",
                                             "nondeterministic"])


def row(status: str, category: str = "", error: float = math.nan, *, case: str = "c",
        engine: str = "e", quantity: str = "distance", tolerance: float = 1e-15,
        reason: str = "", nondeterministic: bool = False) -> dict[str, Any]:
    if status in ("agree", "disagree") and math.isnan(error):
        error = 0.0 if status == "agree" else 1e-9
    return {"case_id": case, "engine": engine, "quantity": quantity, "status": status,
            "category": category, "error": error, "tolerance": tolerance, "reason": reason,
            "nondeterministic": nondeterministic}


def one(was: dict[str, Any] | None, now: dict[str, Any] | None, **options: Any) -> Finding:
    """The one finding on a row that was ``was`` in the baseline and is ``now`` in the run."""
    baseline = from_rows(frame(*[was] if was else []))
    findings = judge(frame(*[now] if now else []), baseline, **options)
    assert len(findings) == 1
    return findings[0]


FAILED = ("error", "crash", "timeout")
NEUTRAL = ("skip", "undefined")

# (baseline row, run row, verdict, words of the reason): the module's table, row by row.
RULES: list[tuple[str, dict[str, Any] | None, dict[str, Any] | None, Verdict, tuple[str, ...]]] = [
    ("new", None, row("agree"), Verdict.NEW, ("in the run", "not in the baseline")),
    ("missing", row("agree"), None, Verdict.MISSING, ("in the baseline", "not in the run")),
    *[(f"same-{s}", row(s), row(s), Verdict.EXPECTED, ("as in the baseline",))
      for s in ("agree", *FAILED, *NEUTRAL)],
    ("agree-then-disagree", row("agree"), row("disagree", "error", 3e-9, tolerance=2e-16),
     Verdict.REGRESSION, ("a new disagreement", "3e-09", "2e-16", "the baseline has agree")),
    *[(f"agree-then-{s}", row("agree"), row(s, reason="it broke"), Verdict.REGRESSION,
       (f"a new {s}", "it broke")) for s in FAILED],
    *[(f"{w}-then-{s}", row(w), row(s, reason="not asked"), Verdict.REGRESSION,
       ("no longer answered", s, "not asked")) for w in ("agree", "disagree") for s in NEUTRAL],
    ("disagree-then-agree", row("disagree", "tolerance", 1e-9), row("agree"), Verdict.STALE,
     ("better than the baseline", "update it", "1e-09")),
    ("category-changed", row("disagree", "tolerance", 1e-9), row("disagree", "convention", 1e-9),
     Verdict.REGRESSION, ("category changed to convention", "the baseline has tolerance")),
    ("now-unexplained", row("disagree", "tolerance", 1e-9), row("disagree", "error", 1e-9),
     Verdict.REGRESSION, ("now unexplained", "category error", "the baseline has tolerance")),
    ("error-grew", row("disagree", "tolerance", 1e-9), row("disagree", "tolerance", 2e-9),
     Verdict.REGRESSION, ("error 2e-09 > bound 1e-09", "margin 0.5", "= 1.5e-09",
                          "tolerance 1e-15")),
    ("error-shrank", row("disagree", "tolerance", 1e-9), row("disagree", "tolerance", 4e-10),
     Verdict.STALE, ("error 4e-10 < bound 1e-09", "stale factor 2", "= 5e-10", "update it")),
    ("error-within", row("disagree", "tolerance", 1e-9), row("disagree", "tolerance", 1.2e-9),
     Verdict.EXPECTED, ("within the baseline", "1.2e-09", "bound 1e-09")),
    ("error-at-the-limit", row("disagree", "tolerance", 1.0), row("disagree", "tolerance", 1.5),
     Verdict.EXPECTED, ("within the baseline",)),
    ("error-at-the-floor", row("disagree", "tolerance", 1.0), row("disagree", "tolerance", 0.5),
     Verdict.EXPECTED, ("within the baseline",)),
    *[(f"disagree-then-{s}", row("disagree", "tolerance"), row(s, reason="boom"),
       Verdict.REGRESSION, (f"a new {s}", "boom", "the baseline has disagree")) for s in FAILED],
    *[(f"{s}-then-agree", row(s), row("agree"), Verdict.STALE, ("better than the baseline",))
      for s in FAILED],
    *[(f"{s}-then-disagree", row(s), row("disagree", "tolerance", 1e-3), Verdict.STALE,
       ("answers now", "0.001")) for s in FAILED],
    ("error-then-crash", row("error"), row("crash"), Verdict.REGRESSION,
     ("a worse failure", "crash", "the baseline has error")),
    ("error-then-timeout", row("error"), row("timeout"), Verdict.REGRESSION,
     ("a worse failure",)),
    ("crash-then-error", row("crash"), row("error"), Verdict.STALE,
     ("a milder failure", "the baseline has crash", "update it")),
    ("timeout-then-error", row("timeout"), row("error"), Verdict.STALE, ("a milder failure",)),
    ("timeout-then-crash", row("timeout"), row("crash"), Verdict.REGRESSION,
     ("a worse failure",)),
    ("crash-then-timeout", row("crash"), row("timeout"), Verdict.STALE, ("a milder failure",)),
    *[(f"{f}-then-{s}", row(f), row(s), Verdict.STALE, ("no longer fails", s))
      for f in FAILED for s in NEUTRAL],
    *[(f"{s}-then-{a}", row(s), row(a, "tolerance"), Verdict.STALE, ("newly answered", a))
      for s in NEUTRAL for a in ("agree", "disagree")],
    *[(f"{s}-then-{f}", row(s), row(f), Verdict.REGRESSION, ("newly failing", f))
      for s in NEUTRAL for f in FAILED],
    ("skip-then-undefined", row("skip"), row("undefined"), Verdict.STALE,
     ("undefined", "the baseline has skip")),
    ("undefined-then-skip", row("undefined"), row("skip"), Verdict.STALE,
     ("skip", "the baseline has undefined")),
]


@pytest.mark.parametrize(("was", "now", "verdict", "words"), [r[1:] for r in RULES],
                         ids=[r[0] for r in RULES])
def test_each_rule_of_the_table(was: dict[str, Any] | None, now: dict[str, Any] | None,
                                verdict: Verdict, words: tuple[str, ...]) -> None:
    finding = one(was, now)
    assert finding.verdict is verdict, finding.reason
    for word in words:
        assert word in finding.reason, (word, finding.reason)


def test_the_table_covers_every_pair_of_statuses() -> None:
    """Each baseline status against each run status (and absent) is a case of RULES."""
    statuses = ("agree", "disagree", *FAILED, *NEUTRAL)
    covered = {((w or {}).get("status"), (n or {}).get("status")) for _, w, n, _, _ in RULES}
    assert {(w, n) for w in statuses for n in statuses} <= covered
    assert (None, "agree") in covered and ("agree", None) in covered


@pytest.mark.parametrize(("status", "verdict"), [
    ("agree", Verdict.EXPECTED), ("skip", Verdict.SKIPPED), ("undefined", Verdict.SKIPPED),
    ("disagree", Verdict.REGRESSION), ("error", Verdict.REGRESSION),
    ("crash", Verdict.REGRESSION), ("timeout", Verdict.REGRESSION)])
def test_without_a_baseline_every_disagreement_fails(status: str, verdict: Verdict) -> None:
    [finding] = judge(frame(row(status, "tolerance", reason="why")), None)
    assert finding.verdict is verdict and finding.expected is None
    assert ("no baseline: every disagreement fails" in finding.reason) == verdict.fails


def test_which_verdicts_fail() -> None:
    assert {v for v in Verdict if not v.fails} == {Verdict.EXPECTED, Verdict.SKIPPED}


def test_margin_and_factor_given_override_the_baselines() -> None:
    was, now = row("disagree", "tolerance", 1.0), row("disagree", "tolerance", 1.8)
    assert one(was, now).verdict is Verdict.REGRESSION
    assert one(was, now, margin=1.0).verdict is Verdict.EXPECTED
    shrank = row("disagree", "tolerance", 0.4)
    assert one(was, shrank).verdict is Verdict.STALE
    finding = one(was, shrank, stale_factor=3.0)
    assert finding.verdict is Verdict.EXPECTED and "stale factor 3" in finding.reason
    with pytest.raises(ValueError, match="margin"):
        one(was, now, margin=-0.1)


def test_close_numbers_are_written_apart_so_a_reason_never_contradicts_itself() -> None:
    bound = 1.0
    error = bound * 1.5 * (1 + 1e-12)
    finding = one(row("disagree", "tolerance", bound), row("disagree", "tolerance", error))
    assert finding.verdict is Verdict.REGRESSION
    shown, limit = finding.reason.split("error ")[1].split(" > ")[0], \
        finding.reason.split("= ")[1].split(" ")[0]
    assert float(shown) > float(limit), finding.reason


def test_engines_scope_the_judgement_and_other_engines_are_not_missing() -> None:
    baseline = from_rows(frame(row("agree", engine="a"), row("agree", engine="b")))
    findings = judge(frame(row("agree", engine="a")), baseline)
    assert [(f.engine, f.verdict) for f in findings] == [("a", Verdict.EXPECTED),
                                                         ("b", Verdict.MISSING)]
    scoped = judge(frame(row("agree", engine="a")), baseline, engines=["a"])
    assert [(f.engine, f.verdict) for f in scoped] == [("a", Verdict.EXPECTED)]


def test_findings_are_sorted_by_engine_case_and_quantity_and_carry_both_sides() -> None:
    rows = [row("agree", engine=e, case=c, quantity=q)
            for e in ("z", "a") for c in ("c2", "c1") for q in ("normal", "hit")]
    findings = judge(frame(*rows), from_rows(frame(*rows)))
    keys = [(f.engine, f.case, f.quantity) for f in findings]
    assert keys == sorted(keys) and len(keys) == 8
    assert all(f.expected == f.got and f.got is not None for f in findings)


def test_a_nondeterministic_row_says_so() -> None:
    finding = one(row("disagree", "tolerance", 1.0),
                  row("disagree", "tolerance", 1.0, nondeterministic=True))
    assert finding.verdict is Verdict.EXPECTED and "nondeterministic" in finding.reason
    assert "nondeterministic" not in one(row("agree"), row("agree")).reason


def test_two_rows_of_one_key_are_refused() -> None:
    with pytest.raises(ValueError, match="two rows of case 'c'"):
        from_rows(frame(row("agree"), row("disagree")))


def test_updated_replaces_the_scoped_engines_and_keeps_the_rest() -> None:
    old = from_rows(frame(row("agree", engine="a"), row("agree", engine="b")), margin=0.2)
    run = frame(row("disagree", "tolerance", 1.0, engine="a"), row("crash", engine="b"))
    scoped = updated(old, run, engines=["a"], source="r2")
    assert {k[1]: e.status for k, e in scoped.entries.items()} == {"a": "disagree",
                                                                   "b": "agree"}
    assert (scoped.margin, scoped.stale_factor, scoped.source) == (0.2, DEFAULT_STALE_FACTOR,
                                                                   "r2")
    everything = updated(old, run, stale_factor=4.0)
    assert {k[1]: e.status for k, e in everything.entries.items()} == {"a": "disagree",
                                                                       "b": "crash"}
    assert (everything.margin, everything.stale_factor) == (0.2, 4.0)
    assert updated(None, run).margin == DEFAULT_MARGIN


TRICKY = [0.1 + 0.2, 5e-324, 1.7976931348623157e308, math.inf, 0.0, 1 / 3, math.nan]


def test_the_file_round_trips_every_error_exactly(tmp_path: Path) -> None:
    entries = [Entry(f"case-{i}", "e", "distance", "disagree", "tolerance", x)
               for i, x in enumerate(TRICKY)]
    path = tmp_path / "baseline.jsonl"
    write_baseline(Baseline({e.key: e for e in entries}, 0.25, 3.0, "reports/r1"), path)
    back = read_baseline(path)
    assert (back.margin, back.stale_factor, back.source) == (0.25, 3.0, "reports/r1")
    for entry in entries:
        got = back.entries[entry.key].error
        assert got == entry.error or (math.isnan(got) and math.isnan(entry.error))


def test_the_file_is_a_header_then_sorted_entries_in_a_fixed_field_order(
        tmp_path: Path) -> None:
    rows = [row("agree", engine=e, case=c) for e in ("z", "a") for c in ("c2", "c1")]
    path = tmp_path / "b.jsonl"
    write_baseline(from_rows(frame(*rows), source="reports/x"), path)
    lines = path.read_text().splitlines()
    assert json.loads(lines[0]) == {"format": 1, "kind": "crosscheck-baseline",
                                    "source": "reports/x", "margin": DEFAULT_MARGIN,
                                    "stale_factor": DEFAULT_STALE_FACTOR}
    entries = [json.loads(line) for line in lines[1:]]
    assert [list(e) for e in entries] == [["engine", "case", "quantity", "status", "category",
                                           "error"]] * 4
    assert [(e["engine"], e["case"]) for e in entries] == [("a", "c1"), ("a", "c2"),
                                                           ("z", "c1"), ("z", "c2")]


HEADER = ('{"format": 1, "kind": "crosscheck-baseline", "source": "r", "margin": 0.5, '
          '"stale_factor": 2.0}')
ENTRY = ('{"engine": "e", "case": "c", "quantity": "hit", "status": "agree", "category": "", '
         '"error": 0.0}')


def entry_with(old: str, new: str) -> str:
    return ENTRY.replace(old, new)


@pytest.mark.parametrize(("text", "line", "reason"), [
    ("", 1, "empty"),
    ("not json\n", 1, "not a JSON line"),
    ('{"format": 1}\n', 1, "not a baseline header"),
    (HEADER.replace('"format": 1', '"format": 7') + "\n", 1, "unknown format 7"),
    (HEADER.replace('"margin": 0.5', '"margin": -1') + "\n", 1, "margin must be"),
    (HEADER.replace('"stale_factor": 2.0', '"stale_factor": 0.5') + "\n", 1, "stale factor"),
    (HEADER.replace(', "source": "r"', "") + "\n", 1, "missing field source"),
    (HEADER + "\n" + ENTRY + "\n{oops\n", 3, "not a JSON line"),
    (HEADER + "\n[1, 2]\n", 2, "not a JSON object"),
    (HEADER + "\n" + entry_with(', "category": ""', "") + "\n", 2, "missing field category"),
    (HEADER + "\n" + entry_with("}", ', "extra": 1}') + "\n", 2, "unknown field extra"),
    (HEADER + "\n" + entry_with("agree", "fine") + "\n", 2, "unknown status 'fine'"),
    (HEADER + "\n" + entry_with("0.0", "Infinity") + "\n", 2, "Infinity is not JSON"),
    (HEADER + "\n" + entry_with("0.0", '"big"') + "\n", 2, "error must be a number"),
    (HEADER + "\n" + entry_with('"e"', '""') + "\n", 2, "must not be empty"),
    (HEADER + "\n" + ENTRY + "\n\n" + ENTRY + "\n", 4,
     "duplicate entry for case 'c' on 'e', quantity 'hit' (first on line 2)"),
])
def test_a_malformed_file_is_refused_naming_file_line_and_reason(
        tmp_path: Path, text: str, line: int, reason: str) -> None:
    path = tmp_path / "baseline.jsonl"
    path.write_text(text)
    with pytest.raises(BaselineError) as refused:
        read_baseline(path)
    assert str(refused.value).startswith(f"{path}, line {line}: "), refused.value
    assert reason in str(refused.value)


def test_a_missing_file_is_refused_naming_it(tmp_path: Path) -> None:
    with pytest.raises(BaselineError, match="cannot read it"):
        read_baseline(tmp_path / "nowhere.jsonl")


def test_a_good_file_reads(tmp_path: Path) -> None:
    path = tmp_path / "baseline.jsonl"
    path.write_text(f"{HEADER}\n{ENTRY}\n{ENTRY.replace('hit', 'normal')}\n")
    baseline = read_baseline(path)
    assert sorted(baseline.entries) == [("c", "e", "hit"), ("c", "e", "normal")]
    assert baseline.engines == {"e"}
