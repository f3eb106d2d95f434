"""A check's CI outputs: JUnit XML valid against the common JUnit schema, Markdown that keeps
its tables whole whatever a reason holds."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from typing import Any

import pandas as pd
import pytest
import xmlschema

from crosscheck.compare.ci import junit_xml, markdown_summary, repro_command
from crosscheck.results.baseline import Finding, Verdict, from_rows, judge
from tests.conftest import ROOT

SCHEMA = xmlschema.XMLSchema(ROOT / "tests" / "data" / "junit.xsd")
NASTY = "a | pipe\nand <b>line</b> & \x01 control"
"""A reason as an engine's message might make it: a pipe, a line break, markup, a control
character."""


def frame(rows: list[dict[str, Any]]) -> pd.DataFrame:
    return pd.DataFrame(rows)


def row(case: str, engine: str, status: str, error: float = 0.0, reason: str = "",
        quantity: str = "distance", category: str = "") -> dict[str, Any]:
    return {"case_id": case, "engine": engine, "quantity": quantity, "status": status,
            "category": category, "error": error, "tolerance": 1e-15, "reason": reason}


BEFORE = [row("apart", "fcl", "agree"), row("touch|x", "fcl", "disagree", 1e-9,
                                            category="tolerance"),
          row("gone", "fcl", "agree"), row("apart", "pymunk", "skip", reason="not asked"),
          row("apart", "pymunk", "agree", quantity="hit")]


def passing() -> list[Finding]:
    return judge(frame(BEFORE), from_rows(frame(BEFORE)))


def failing() -> list[Finding]:
    after = [row("apart", "fcl", "crash", reason=NASTY),
             row("touch|x", "fcl", "disagree", 1e-10, category="tolerance"),
             row("apart", "pymunk", "skip", reason="not asked"),
             row("apart", "pymunk", "agree", quantity="hit"), row("fresh", "pymunk", "agree")]
    return judge(frame(after), from_rows(frame(BEFORE)))


def test_the_failing_fixture_has_every_failing_verdict() -> None:
    assert {f.verdict for f in failing()} == {Verdict.REGRESSION, Verdict.STALE,
                                             Verdict.MISSING, Verdict.NEW, Verdict.EXPECTED}


@pytest.mark.parametrize("findings", [passing, failing, lambda: judge(frame(BEFORE), None),
                                      lambda: []], ids=["passing", "failing", "no-baseline",
                                                        "empty"])
def test_junit_is_valid_against_the_schema(findings: Any) -> None:
    SCHEMA.validate(junit_xml(findings(), "crosscheck", "reports/r1"))


def test_the_schema_can_fail() -> None:
    document = junit_xml(failing(), "crosscheck", "reports/r1")
    assert not SCHEMA.is_valid(document.replace('name="apart :: distance"', ""))
    assert not SCHEMA.is_valid(document.replace('tests="', 'tests="-', 1))


def test_junit_has_a_suite_per_engine_and_a_case_per_finding() -> None:
    findings = failing()
    root = ET.fromstring(junit_xml(findings, "crosscheck", "reports/r1"))
    suites = root.findall("testsuite")
    assert [s.get("name") for s in suites] == ["crosscheck.fcl", "crosscheck.pymunk"]
    assert root.get("tests") == str(len(findings)) and root.get("errors") == "0"
    assert root.get("failures") == str(sum(f.verdict.fails for f in findings))
    for suite in suites:
        engine = suite.get("name", "").removeprefix("crosscheck.")
        mine = [f for f in findings if f.engine == engine]
        cases = suite.findall("testcase")
        assert suite.get("tests") == str(len(mine)) == str(len(cases))
        assert suite.get("failures") == str(len(suite.findall("testcase/failure")))
        assert {c.get("classname") for c in cases} == {f"crosscheck.{engine}"}
        assert [c.get("name") for c in cases] == [f"{f.case} :: {f.quantity}" for f in mine]


def test_a_failure_says_verdict_reason_both_sides_and_the_repro() -> None:
    findings = failing()
    root = ET.fromstring(junit_xml(findings, "crosscheck", "reports/r1"))
    crash = next(f for f in findings if f.case == "apart" and f.engine == "fcl")
    failure = root.find("testsuite/testcase[@name='apart :: distance']/failure")
    assert failure is not None and crash.verdict is Verdict.REGRESSION
    assert failure.get("type") == "regression"
    assert (failure.get("message") or "").startswith("regression: a new crash")
    text = failure.text or ""
    assert "expected (baseline): agree, error 0" in text and "got (run): crash" in text
    assert f"repro: {repro_command('reports/r1', crash)}" in text
    assert "\\x01" in text and "\x01" not in text  # XML 1.0 cannot hold it: escaped
    missing = root.find("testsuite/testcase[@name='gone :: distance']/failure")
    assert missing is not None and "repro: not in this run" in (missing.text or "")


def test_skipped_findings_are_skipped_test_cases() -> None:
    root = ET.fromstring(junit_xml(judge(frame(BEFORE), None), "crosscheck", "r"))
    skipped = root.findall(".//testcase/skipped")
    assert [s.get("message") for s in skipped] == ["skip (not asked)"]
    assert root.find("testsuite[@name='crosscheck.pymunk']").get("skipped") == "1"  # type: ignore[union-attr]


def test_the_repro_command_is_quoted_for_a_shell() -> None:
    finding = next(f for f in failing() if f.case == "touch|x")
    assert repro_command("my runs/r1", finding) == (
        "crosscheck repro 'my runs/r1' 'touch|x' --engine fcl")


def cells(line: str) -> list[str]:
    """The cells of a Markdown table line (split at unescaped pipes)."""
    return [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]


def tables(text: str) -> list[list[str]]:
    """The lines of each table of a Markdown document."""
    found: list[list[str]] = []
    previous = ""
    for line in text.splitlines():
        if line.startswith("|"):
            if not previous.startswith("|"):
                found.append([])
            found[-1].append(line)
        previous = line
    return found


def test_markdown_says_the_outcome_counts_and_failures_in_whole_tables() -> None:
    findings = failing()
    text = markdown_summary(findings, "reports/r1", baseline="base.jsonl", margin=0.5,
                            stale_factor=2.0)
    assert text.splitlines()[0] == ("## crosscheck check: failed (1 regression, 1 stale, "
                                    "1 missing, 1 new)")
    assert "`base.jsonl` (margin 0.5, stale factor 2)" in text
    counts, failures = tables(text)
    assert cells(counts[0]) == ["engine", *[str(v) for v in Verdict]]
    assert cells(counts[2])[0] == "fcl" and cells(counts[3])[0] == "pymunk"
    assert [int(c) for c in cells(counts[2])[1:]] == [
        sum(f.engine == "fcl" and f.verdict is v for f in findings) for v in Verdict]
    width = len(cells(failures[0]))
    assert width == 6 and all(len(cells(line)) == width for line in failures)
    assert len(failures) == 2 + sum(f.verdict.fails for f in findings)
    crash = next(line for line in failures if "a new crash" in line)
    assert "a \\| pipe<br>and \\<b\\>line\\</b\\> \\& " in crash
    assert "`touch\\|x`" in text  # the case id, a pipe escaped even in code


def test_markdown_of_a_passing_check_lists_no_failures() -> None:
    text = markdown_summary(passing(), "reports/r1", baseline="b.jsonl", margin=0.5,
                            stale_factor=2.0, engines=["fcl", "pymunk"])
    assert text.startswith("## crosscheck check: passed\n")
    assert "engines: fcl, pymunk only" in text and "Failing" not in text
    assert len(tables(text)) == 1


def test_markdown_without_a_baseline_says_so() -> None:
    text = markdown_summary(judge(frame(BEFORE), None), "r")
    assert "with no baseline: every disagreement fails" in text
    assert text.splitlines()[0] == "## crosscheck check: failed (1 regression)"


def test_markdown_caps_the_failing_list() -> None:
    rows = [row(f"case-{i}", "fcl", "crash") for i in range(7)]
    text = markdown_summary(judge(frame(rows), None), "r", cap=5)
    failures = tables(text)[1]
    assert len(failures) == 2 + 5
    assert "and 2 more" in text
