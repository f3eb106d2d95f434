"""What changed from one engine version to another: the version matrix's report.

``crosscheck compare`` of two runs, or of one run holding both versions
(``crosscheck run --engine pymunk@6.11.1 --engine pymunk``), answers "what changed from X
to Y" for an engine: X's rows are taken as the baseline of Y's and judged by the baseline
rules (:mod:`crosscheck.results.baseline`: a new disagreement, a larger error beyond the
margin, a new crash, a smaller error beyond the stale factor, a row newly answered or no
longer answered, a case on one side only).  Each changed row then falls in a *failure
mode*: its quantity with the verdict and category it had and has
(``distance: agree -> disagree (tolerance)``), or, where those stayed, whether its error
grew or shrank.  The modes are listed by how many rows they hold, each with examples and
the repro command for both versions.

Nothing is run: both sides are stored runs.  A pinned version's script names the
interpreter that has that version (:mod:`crosscheck.studies.repro`); the command given
here prints it.

>>> mode_of("hit", ("agree", ""), ("disagree", "tolerance"), "regression")
'hit: agree -> disagree (tolerance)'
>>> mode_of("distance", ("disagree", "convention"), ("disagree", "convention"), "regression")
'distance: disagree (convention), error grew'
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from crosscheck.results.baseline import (
    DEFAULT_MARGIN,
    DEFAULT_STALE_FACTOR,
    Entry,
    Finding,
    Verdict,
    from_rows,
    judge,
)
from crosscheck.results.run import read_results, read_run_info

SAME = "(engine)"
"""The one engine label both sides' rows are given before they are judged."""

EXAMPLES = 5
"""Examples listed per failure mode in the Markdown report (the CSV has every row)."""


@dataclass(frozen=True)
class Side:
    """One version: an engine (``pymunk@6.11.1``) in a stored run, and its version string."""

    run: Path
    engine: str
    version: str = ""

    @property
    def label(self) -> str:
        return f"{self.engine} ({self.version})" if self.version else self.engine

    def repro(self, case: str) -> str:
        """The command that prints this side's repro script of ``case``."""
        return f"crosscheck repro {self.run} {case} --engine {self.engine}"


@dataclass
class Changes:
    """The changed rows from ``before`` to ``after``, by failure mode (largest first)."""

    before: Side
    after: Side
    compared: int
    """Rows judged (either side)."""
    answered_differently: int = 0
    """Rows of both sides whose stored value differs at all (bit for bit, as text)."""
    modes: dict[str, list[Finding]] = field(default_factory=dict)

    @property
    def changed(self) -> int:
        return sum(len(found) for found in self.modes.values())

    def counts(self) -> dict[str, int]:
        """Changed rows by verdict (regression, stale, missing, new)."""
        out: dict[str, int] = {}
        for found in self.modes.values():
            for finding in found:
                out[str(finding.verdict)] = out.get(str(finding.verdict), 0) + 1
        return out


def side(run: Path, engine: str) -> Side:
    """``engine`` of the stored run in ``run``, with the version its run.json records."""
    info = read_run_info(run)
    versions = {str(e.get("name")): str(e.get("version", "")) for e in info.engines}
    if engine not in versions:
        raise KeyError(f"{run} has no engine {engine!r} (it has {', '.join(versions)})")
    return Side(run, engine, versions[engine])


def _status(entry: Entry | None) -> tuple[str, str]:
    return ("absent", "") if entry is None else (entry.status, entry.category)


def _words(status: tuple[str, str]) -> str:
    return f"{status[0]} ({status[1]})" if status[1] else status[0]


def mode_of(quantity: str, was: tuple[str, str], now: tuple[str, str], verdict: str) -> str:
    """A changed row's failure mode, in words."""
    if was != now:
        return f"{quantity}: {_words(was)} -> {_words(now)}"
    trend = "error grew" if verdict == Verdict.REGRESSION else "error shrank"
    return f"{quantity}: {_words(now)}, {trend}"


def what_changed(before: Side, after: Side, margin: float = DEFAULT_MARGIN,
                 stale_factor: float = DEFAULT_STALE_FACTOR,
                 frames: tuple[pd.DataFrame, pd.DataFrame] | None = None) -> Changes:
    """The rows of ``after`` judged against ``before``'s as a baseline, grouped by failure
    mode.  ``frames``: both runs' results, if already read."""
    first, second = frames if frames is not None else (read_results(before.run),
                                                       read_results(after.run))
    old = first[first["engine"] == before.engine].assign(engine=SAME)
    new = second[second["engine"] == after.engine].assign(engine=SAME)
    findings = judge(new, from_rows(old, margin, stale_factor, str(before.run)))
    key = ["case_id", "quantity"]
    both = old[[*key, "value"]].merge(new[[*key, "value"]], on=key, suffixes=("_a", "_b"))
    differ = int((both["value_a"].astype(str) != both["value_b"].astype(str)).sum())
    changes = Changes(before, after, len(findings), differ)
    for finding in findings:
        if not finding.verdict.fails:
            continue
        mode = mode_of(finding.quantity, _status(finding.expected), _status(finding.got),
                       finding.verdict)
        changes.modes.setdefault(mode, []).append(finding)
    changes.modes = dict(sorted(changes.modes.items(), key=lambda kv: (-len(kv[1]), kv[0])))
    return changes


def _error(entry: Entry | None) -> float:
    return math.nan if entry is None else entry.error


COLUMNS = ["mode", "case_id", "quantity", "verdict", "before", "after", "error_before",
           "error_after", "reason", "repro_before", "repro_after"]
"""The columns of ``changes.csv`` (before the two engine labels)."""


def table(changes: Changes) -> pd.DataFrame:
    """Every changed row: its mode, verdict, both sides' status, category and error, the
    reason and both repro commands."""
    rows = []
    for mode, found in changes.modes.items():
        for f in found:
            rows.append({
                "mode": mode, "case_id": f.case, "quantity": f.quantity,
                "verdict": str(f.verdict), "before": _words(_status(f.expected)),
                "after": _words(_status(f.got)), "error_before": _error(f.expected),
                "error_after": _error(f.got), "reason": f.reason,
                "repro_before": changes.before.repro(f.case),
                "repro_after": changes.after.repro(f.case)})
    return pd.DataFrame(rows, columns=COLUMNS)


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown(all_changes: Sequence[Changes]) -> str:
    """The "what changed" report in Markdown: per engine pair, the counts, then every
    failure mode with its count, up to :data:`EXAMPLES` examples and their repro commands."""
    lines = ["# What changed", ""]
    for changes in all_changes:
        counts = ", ".join(f"{n} {verdict}" for verdict, n in sorted(changes.counts().items()))
        lines += [f"## {changes.before.label} -> {changes.after.label}", "",
                  f"{changes.changed} of {changes.compared} rows changed"
                  + (f" ({counts}) in {len(changes.modes)} failure modes." if counts else ".")
                  + f" {changes.answered_differently} rows on both sides answer differently "
                    "at all (the stored value, bit for bit).",
                  f"Before: `{changes.before.run}`; after: `{changes.after.run}`.", ""]
        for mode, found in changes.modes.items():
            lines += [f"### {_cell(mode)}: {len(found)} rows", "",
                      "| case | verdict | reason | repro before | repro after |",
                      "|---|---|---|---|---|"]
            for f in found[:EXAMPLES]:
                lines.append(f"| {_cell(f.case)} | {f.verdict} | {_cell(f.reason)} | "
                             f"`{changes.before.repro(f.case)}` | "
                             f"`{changes.after.repro(f.case)}` |")
            if len(found) > EXAMPLES:
                lines.append(f"| and {len(found) - EXAMPLES} more (changes.csv) | | | | |")
            lines.append("")
    return "\n".join(lines) + "\n"


def write(all_changes: Sequence[Changes], out: Path) -> dict[str, Path]:
    """``changes.md`` and ``changes.csv`` (every changed row of every pair) in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    paths = {"markdown": out / "changes.md", "csv": out / "changes.csv"}
    paths["markdown"].write_text(markdown(all_changes), encoding="utf-8")
    frames = [table(c).assign(before_engine=c.before.label, after_engine=c.after.label)
              for c in all_changes]
    empty = pd.DataFrame(columns=[*COLUMNS, "before_engine", "after_engine"])
    (pd.concat(frames, ignore_index=True) if frames else empty).to_csv(paths["csv"],
                                                                        index=False)
    return paths
