"""What the plugin's items need from a run: the engines the options name, the run's outcome,
and the view of the suite an engine's collector reads (:class:`SuiteView`).

The suite (:mod:`crosscheck.pytest_plugin.suite`) builds these and the items
(:mod:`crosscheck.pytest_plugin.items`) read them; neither imports the other's module for it,
so the plugin has no import circle.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from crosscheck.core.contract import Adapter
from crosscheck.results.baseline import Finding

__all__ = ["Engine", "Ran", "SuiteView"]


@dataclass(frozen=True)
class Engine:
    """One engine the options name: its adapter and whether it is a built-in."""

    name: str
    adapter: Adapter
    builtin: bool


@dataclass(frozen=True)
class Ran:
    """The outcome of the run: its folder and the findings, by engine."""

    directory: Path
    findings: dict[str, list[Finding]]


class SuiteView(Protocol):
    """What an engine's collector reads of the suite: each case's position and quantities,
    its case file, the baseline file, whether a finding has a repro script, and the run
    (made once, on first use)."""

    order: dict[str, tuple[int, tuple[str, ...]]]
    sources: dict[str, str]
    baseline_file: Path | None

    def ran(self) -> Ran:
        """The run, made on first use."""
        ...

    def scripted(self, engine: Engine, case: str) -> bool:
        """Whether ``crosscheck repro`` writes a script of ``case`` on ``engine``."""
        ...
