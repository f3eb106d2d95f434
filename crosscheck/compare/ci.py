"""A check's findings for CI: JUnit XML for the test-report tabs, Markdown for a job summary.

:func:`junit_xml` writes one ``<testsuite>`` per engine and one ``<testcase>`` per finding
(``crosscheck.<engine>``, ``<case> :: <quantity>``), in the structure of the common JUnit
schema (Jenkins' and xUnit's ``junit-10.xsd``; ``tests/report/test_ci_output.py`` validates
it); a failing finding is a ``<failure>`` whose text has the whole reason, the baseline's
entry and the run's row, and the command that reproduces the case.  A check's failures are
failures, never errors: ``errors`` is always 0 and the times are 0 (a check runs nothing).

:func:`markdown_summary` is for ``$GITHUB_STEP_SUMMARY``: the outcome as a heading, the
counts per engine and verdict, then the failing findings (at most ``cap``), every cell
escaped so that a ``|`` or a line break in a reason cannot break the table.

>>> from crosscheck.results.baseline import Entry, Finding, Verdict
>>> got = Entry("touch", "e", "hit", "crash", "", float("nan"))
>>> finding = Finding("touch", "e", "hit", Verdict.REGRESSION, "a new crash", None, got)
>>> print(markdown_summary([finding], "reports/r1").splitlines()[0])
## crosscheck check: failed (1 regression)
>>> '<failure message="regression: a new crash" type="regression">' in junit_xml(
...     [finding], "crosscheck", "reports/r1")
True
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Collection, Sequence
from pathlib import Path

from crosscheck.report import repro_links
from crosscheck.results.baseline import Entry, Finding, Verdict

MESSAGE_CHARS = 160
"""The longest reason a failure's message attribute holds (its text has the whole reason)."""
CAP = 50
"""The failing findings a Markdown summary lists (the rest are counted)."""


def repro_command(run_dir: str | Path, finding: Finding) -> str:
    """The command that writes a script reproducing the finding's case on its engine."""
    return repro_links.command(run_dir, finding.case, finding.engine)


def side(entry: Entry | None) -> str:
    """A baseline entry or a run's row in a few words (``none``: that side has no row)."""
    if entry is None:
        return "none"
    category = f" ({entry.category})" if entry.category else ""
    return f"{entry.status}{category}, error {entry.error:.6g}"


def counts(findings: Sequence[Finding]) -> Counter[Verdict]:
    """How many findings of each verdict."""
    return Counter(f.verdict for f in findings)


def outcome(findings: Sequence[Finding]) -> str:
    """``passed`` or ``failed``, with the failing verdicts counted: ``failed (2 regressions,
    1 stale)``."""
    counted = counts(findings)
    failing = [(v, counted[v]) for v in Verdict if v.fails and counted[v]]
    if not failing:
        return "passed"
    words = [f"{n} {v}{'s' if v is Verdict.REGRESSION and n != 1 else ''}" for v, n in failing]
    return f"failed ({', '.join(words)})"


def scope(engines: Collection[str] | None) -> str:
    """The engines a check judged, in words."""
    if engines is None:
        return "engines: all"
    return f"engines: {', '.join(sorted(engines))} only (--engine)"


_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")


def _xml_text(text: str) -> str:
    """``text`` without the characters XML 1.0 cannot hold (an engine's message may have
    them), each written as its escape instead."""
    return _NOT_XML.sub(lambda m: f"\\x{ord(m.group()):02x}", text)


def _short(reason: str) -> str:
    line = " ".join(reason.split())
    return line if len(line) <= MESSAGE_CHARS else line[:MESSAGE_CHARS - 3] + "..."


def _failure_text(finding: Finding, run_dir: str | Path) -> str:
    repro = ("not in this run" if finding.verdict is Verdict.MISSING
             else repro_command(run_dir, finding))
    return (f"{finding.reason}\nexpected (baseline): {side(finding.expected)}\n"
            f"got (run): {side(finding.got)}\nrepro: {repro}\n")


def junit_xml(findings: Sequence[Finding], suite_name: str, run_dir: str | Path) -> str:
    """The findings as a JUnit XML document: one testsuite per engine, one testcase each."""
    by_engine: dict[str, list[Finding]] = {}
    for finding in findings:
        by_engine.setdefault(finding.engine, []).append(finding)
    total = counts(findings)
    failures = sum(n for v, n in total.items() if v.fails)
    root = ET.Element("testsuites", name=suite_name, tests=str(len(findings)),
                      failures=str(failures), errors="0", time="0")
    for engine, found in by_engine.items():
        counted = counts(found)
        suite = ET.SubElement(root, "testsuite", name=f"{suite_name}.{engine}",
                              tests=str(len(found)),
                              failures=str(sum(n for v, n in counted.items() if v.fails)),
                              errors="0", skipped=str(counted[Verdict.SKIPPED]), time="0")
        for finding in found:
            case = ET.SubElement(suite, "testcase", classname=f"crosscheck.{engine}",
                                 name=_xml_text(f"{finding.case} :: {finding.quantity}"),
                                 time="0")
            if finding.verdict.fails:
                failure = ET.SubElement(
                    case, "failure", message=_xml_text(f"{finding.verdict}: "
                                                       f"{_short(finding.reason)}"),
                    type=str(finding.verdict))
                failure.text = _xml_text(_failure_text(finding, run_dir))
            elif finding.verdict is Verdict.SKIPPED:
                ET.SubElement(case, "skipped", message=_xml_text(_short(finding.reason)))
    ET.indent(root)
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            + ET.tostring(root, encoding="unicode") + "\n")


def write_junit(findings: Sequence[Finding], suite_name: str, run_dir: str | Path,
                path: Path) -> None:
    """Write :func:`junit_xml` to ``path`` (its folder made if need be)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(junit_xml(findings, suite_name, run_dir), encoding="utf-8")


_MARKDOWN = re.compile(r"([\\`*_\[\]<>|&~#])")


def cell(text: str) -> str:
    """``text`` as one Markdown table cell: punctuation that Markdown or HTML would read
    escaped (``|`` above all), line breaks as ``<br>``.

    >>> cell("a | b\\n<c>")
    'a \\\\| b<br>\\\\<c\\\\>'
    """
    return "<br>".join(_MARKDOWN.sub(r"\\\1", line) for line in text.splitlines() or [""])


def code(text: str) -> str:
    """``text`` as inline code in a table cell (a ``|`` escaped, as GitHub's tables need even
    in code; lines joined by spaces)."""
    text = " ".join(text.split()).replace("|", "\\|")
    fence = "``" if "`" in text else "`"
    return f"{fence} {text} {fence}" if fence == "``" else f"`{text}`"


def markdown_summary(findings: Sequence[Finding], run_dir: str | Path, *,
                     baseline: str | Path | None = None, margin: float | None = None,
                     stale_factor: float | None = None,
                     engines: Collection[str] | None = None, cap: int = CAP) -> str:
    """The check as Markdown for a CI job summary: outcome, counts, the failing findings."""
    against = (f"against the baseline {code(str(baseline))} (margin {margin:g}, stale factor "
               f"{stale_factor:g})" if baseline is not None and margin is not None
               and stale_factor is not None else "with no baseline: every disagreement fails")
    lines = [f"## crosscheck check: {outcome(findings)}", "",
             f"Run {code(str(run_dir))} {against}; {scope(engines)}.", ""]
    lines += _counts_table(findings)
    failing = [f for f in findings if f.verdict.fails]
    if failing:
        lines += ["", f"### Failing ({len(failing)})", "",
                  "| case | engine | quantity | verdict | reason | repro |",
                  "|---|---|---|---|---|---|"]
        for f in failing[:cap]:
            repro = "" if f.verdict is Verdict.MISSING else code(repro_command(run_dir, f))
            lines.append(f"| {code(f.case)} | {cell(f.engine)} | {cell(f.quantity)} | "
                         f"{f.verdict} | {cell(f.reason)} | {repro} |")
        if len(failing) > cap:
            lines += ["", f"and {len(failing) - cap} more (every finding is in the JUnit XML, "
                          "or run crosscheck check locally)."]
    return "\n".join(lines) + "\n"


def _counts_table(findings: Sequence[Finding]) -> list[str]:
    engines = list(dict.fromkeys(f.engine for f in findings))
    counted = Counter((f.engine, f.verdict) for f in findings)
    lines = ["| engine | " + " | ".join(str(v) for v in Verdict) + " |",
             "|---|" + "---:|" * len(Verdict)]
    for engine in engines:
        lines.append(f"| {cell(engine)} | "
                     + " | ".join(str(counted[(engine, v)]) for v in Verdict) + " |")
    if not engines:
        lines.append("| (no rows) | " + " | ".join("0" for _ in Verdict) + " |")
    return lines
