"""The pytest plugin's nodes: a collector per engine, an item per finding and per kit check.

Under ``crosscheck/<engine>`` (an :class:`EngineCollector`, marked ``crosscheck``):

- ``crosscheck/<engine>/conformance::<check>``: one :class:`ConformanceItem` per check of
  the conformance kit (:data:`crosscheck.testing.conformance.CHECKS`), the kit run once for
  all of them; a check with a failure fails with the kit's text, one that the kit never
  reached (it stopped at an earlier failure) is skipped, saying so;
- ``crosscheck/<engine>/<case>::<quantity>``: one :class:`FindingItem` per finding of the
  judgement (:func:`crosscheck.results.baseline.judge`): ``expected`` passes, ``skipped`` is
  a skip with the finding's reason, every other verdict fails with the reason, the expected
  and the got entries and the command that reproduces the case.

A failure's report is its text alone (no Python traceback): what the terminal shows and
what ``--junitxml`` writes in the ``<failure>`` element.
"""

from __future__ import annotations

import math
import shlex
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from crosscheck.pytest_plugin.engines import Engine, SuiteView
from crosscheck.pytest_plugin.kit import KitOutcome, run_kit
from crosscheck.pytest_plugin.marker import MARKER
from crosscheck.results.baseline import Entry, Finding, Verdict
from crosscheck.testing.conformance import CHECKS

if TYPE_CHECKING:
    from _pytest._code.code import TerminalRepr



class CrosscheckFailure(Exception):
    """A finding or a kit check that fails: its message is the whole report."""


def entry_text(entry: Entry | None, missing: str) -> str:
    """An entry in words: its status, category and error (``missing`` if there is none)."""
    if entry is None:
        return missing
    category = f" ({entry.category})" if entry.category else ""
    error = "" if math.isnan(entry.error) else f", error {entry.error:.6g}"
    return f"{entry.status}{category}{error}"


def repro_command(run_dir: Path, finding: Finding, case_file: str, scripted: bool) -> str:
    """How to reproduce a finding: the command that writes a standalone script for it (an
    engine ``crosscheck repro`` writes scripts for), else the run of its case file."""
    if scripted:
        return shlex.join(["crosscheck", "repro", str(run_dir), finding.case,
                           "--engine", finding.engine])
    again = shlex.join(["crosscheck", "run", case_file or "CASES", "--engine", finding.engine])
    return (f"{again} (case {finding.case}; no repro script: crosscheck repro writes one "
            f"where the engine makes the case as calls of its module)")


def finding_text(finding: Finding, run_dir: Path, baseline: str, case_file: str = "",
                 scripted: bool = True) -> str:
    """Why a finding fails: its verdict and reason, expected against got, the repro command.

    ``baseline``: the baseline file ('' when the run is judged without one); ``case_file``
    the case's file; ``scripted``: whether ``crosscheck repro`` writes scripts for the engine.
    """
    expected = (f"expected (baseline {baseline}): {entry_text(finding.expected, 'no entry')}"
                if baseline else "expected (no baseline): agree, skip or undefined")
    return "\n".join([
        f"{str(finding.verdict).upper()}: {finding.reason}",
        f"  case {finding.case}, quantity {finding.quantity}, engine {finding.engine}",
        f"  {expected}",
        f"  got (this run): {entry_text(finding.got, 'no row')}",
        f"  reproduce: {repro_command(run_dir, finding, case_file, scripted)}",
    ])


class ReportedItem(pytest.Item):
    """An item whose failure is reported by its text alone."""

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException],
                     style: Any = None) -> str | TerminalRepr:
        if isinstance(excinfo.value, CrosscheckFailure):
            return str(excinfo.value)
        return super().repr_failure(excinfo, style)

    def reportinfo(self) -> tuple[Path, int, str]:
        """The case file (or the collector's path) and a headline for a failure's report: not
        the end of the node id (pytest would then write a case id's dots as ``::``)."""
        engine = self.parent.name.removeprefix("crosscheck/") if self.parent else ""
        return self.path, 0, f"{self.name} on {engine}"


class FindingItem(ReportedItem):
    """One case x engine x quantity as judged."""

    def __init__(self, *, finding: Finding, run_dir: Path, baseline: str, case_file: str,
                 scripted: bool, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.finding, self.run_dir, self.baseline = finding, run_dir, baseline
        self.case_file, self.scripted = case_file, scripted
        self.user_properties.append(("verdict", str(finding.verdict)))
        self.extra_keyword_matches.add(str(finding.verdict))
        if finding.verdict is Verdict.SKIPPED:
            self.add_marker(pytest.mark.skip(reason=finding.reason))

    def runtest(self) -> None:
        if self.finding.verdict.fails:
            raise CrosscheckFailure(finding_text(self.finding, self.run_dir, self.baseline,
                                                 self.case_file, self.scripted))


class ConformanceItem(ReportedItem):
    """One check of the conformance kit on the engine's class."""

    def __init__(self, *, check: str, kit: Callable[[], KitOutcome], **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.check, self.kit = check, kit

    def runtest(self) -> None:
        kit = self.kit()
        mine = [f for f in kit.failures if f.check == self.check]
        if mine:
            lines = "\n".join(f"- {f}" for f in mine)
            raise CrosscheckFailure(f"conformance check {self.check!r}: {len(mine)} "
                                    f"failure(s):\n{lines}")
        if kit.broken:
            raise CrosscheckFailure(f"conformance check {self.check!r} not known: {kit.broken}")
        if kit.stopped and CHECKS.index(self.check) > CHECKS.index(kit.stopped):
            pytest.skip(f"not run: the conformance kit stopped at the failed check "
                        f"{kit.stopped!r}")


class EngineCollector(pytest.Collector):
    """Everything the plugin asks of one engine: the kit's checks, then the findings."""

    def __init__(self, *, suite: SuiteView, engine: Engine, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.suite, self.engine = suite, engine
        self.add_marker(MARKER)
        self._kit: KitOutcome | None = None

    def kit(self) -> KitOutcome:
        """The conformance kit run on the engine's class in a process of its own, once for
        all its items (a built-in's sources may be the harness's own files; a plug-in's must
        be public)."""
        if self._kit is None:
            engine = self.engine
            self._kit = run_kit(type(engine.adapter), engine.name,
                                public_sources=not engine.builtin)
        return self._kit

    def _place(self, finding: Finding) -> tuple[int, int, str]:
        """Where a finding goes: the suite's order of cases and its kind's order of
        quantities (a case or quantity the run lacks, after the others)."""
        index, quantities = self.suite.order.get(finding.case, (len(self.suite.order), ()))
        rank = quantities.index(finding.quantity) if finding.quantity in quantities else len(
            quantities)
        return index, rank, finding.case

    def collect(self) -> list[pytest.Item | pytest.Collector]:
        ran = self.suite.ran()
        baseline = str(self.suite.baseline_file or "")
        found: list[pytest.Item | pytest.Collector] = [
            ConformanceItem.from_parent(self, name=f"conformance::{check}", check=check,
                                        kit=self.kit,
                                        nodeid=f"{self.nodeid}/conformance::{check}")
            for check in CHECKS]
        for finding in sorted(ran.findings[self.engine.name], key=self._place):
            case_file = self.suite.sources.get(finding.case, "")
            file = case_file or baseline
            found.append(FindingItem.from_parent(
                self, name=f"{finding.case}::{finding.quantity}", finding=finding,
                run_dir=ran.directory, baseline=baseline, case_file=case_file,
                scripted=self.suite.scripted(self.engine, finding.case),
                nodeid=f"{self.nodeid}/{finding.case}::{finding.quantity}",
                path=Path(file).resolve() if file else self.path))
        return found
