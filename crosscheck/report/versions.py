"""The report's version section: what changed from an engine's earlier major version to its
next, for every variant that declares the one it supersedes (``Adapter.supersedes``:
``box2d3`` supersedes ``box2d``) when the run holds both.

Each pair is :func:`crosscheck.results.changes.what_changed` on the run's own rows (the
rows ``crosscheck compare RUN --from OLD --to NEW`` lists in ``changes.csv``), shown as the
two versions' counts per kind, the changed rows' failure modes (largest first, with examples
and the repro command of the newer version), and the fast-body families' missed impacts per
version: the cases of each ``fast-*`` block where a row's reason says the impact was missed
(:data:`crosscheck.truth.scene_rules.PASSED_THROUGH`), the count a tunnelling claim is
checked by.

>>> pairs([{"name": "box2d", "supersedes": ""}, {"name": "box2d3", "supersedes": "box2d"},
...        {"name": "x", "supersedes": "gone"}])
[('box2d', 'box2d3')]
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.results.changes import Changes, Side, what_changed
from crosscheck.truth.scene_rules import PASSED_THROUGH

MODES = 12
"""Failure modes shown per pair (the rest are counted; ``crosscheck compare`` lists all)."""
EXAMPLES = 3
"""Example cases shown per failure mode."""
FAST = "fast-"
"""The blocks of the fast-body families (cases/fast.toml)."""


def pairs(engines: Iterable[Mapping[str, Any]]) -> list[tuple[str, str]]:
    """(older, newer) for each engine of the run that supersedes another engine of the run."""
    present = [str(e["name"]) for e in engines]
    found = []
    for e in engines:
        old = str(e.get("supersedes") or "")
        if old and old in present:
            found.append((old, str(e["name"])))
    return found


def _status(frame: pd.DataFrame) -> pd.Series:
    words = frame["status"].astype(str)
    category = frame["category"].fillna("").astype(str)
    return words.where(category == "", words + " (" + category + ")")


def counts(frame: pd.DataFrame, engine: str) -> dict[str, dict[str, int]]:
    """Rows of ``engine`` per kind, by status (and category where one is set)."""
    rows = frame[frame["engine"] == engine]
    out: dict[str, dict[str, int]] = {}
    for kind, status in zip(rows["kind"].astype(str), _status(rows), strict=True):
        per_kind = out.setdefault(kind, {})
        per_kind[status] = per_kind.get(status, 0) + 1
    return out


def family(case_id: str, origin: str) -> str:
    """A fast case's block: its sweep's (``origin``), else its id without the travel and
    phase a block of single cases spells out (the walls' cases are not swept).

    >>> family("fast-wall-x-travel-0.5-phase-0.3", ""), family("fast-head-on.dt=1", "fast-head-on")
    ('fast-wall-x', 'fast-head-on')
    """
    return origin or re.sub(r"-travel-[^-]+-phase-[^-]+$", "", case_id)


def missed_impacts(frame: pd.DataFrame, engines: Iterable[str]) -> list[dict[str, Any]]:
    """Per fast-body block: its cases, and per engine the cases whose impact it missed (a
    row's reason says the bodies passed through each other) and the cases with an ``error``
    row (a wall's pass-through among them: the tunnelling claim reads those)."""
    ids = frame["case_id"].astype(str)
    fast = frame[ids.str.startswith(FAST)]
    if fast.empty:
        return []
    blocks = [family(c, o) for c, o in zip(fast["case_id"].astype(str),
                                           fast["origin"].fillna("").astype(str), strict=True)]
    missed = fast["reason"].fillna("").astype(str).str.contains(PASSED_THROUGH, regex=False)
    wrong = fast["category"].fillna("").astype(str) == "error"
    out = []
    for block, rows in fast.groupby(pd.Series(blocks, index=fast.index), sort=True):
        entry: dict[str, Any] = {"block": str(block), "engines": {}}
        for engine in engines:
            mine = rows[rows["engine"] == engine]
            entry["engines"][engine] = {
                "cases": int(mine["case_id"].nunique()),
                "missed": int(mine.loc[missed.loc[mine.index], "case_id"].nunique()),
                "errors": int(mine.loc[wrong.loc[mine.index], "case_id"].nunique())}
        out.append(entry)
    return out


def _modes(changes: Changes) -> list[dict[str, Any]]:
    shown = []
    for mode, found in list(changes.modes.items())[:MODES]:
        shown.append({"mode": mode, "rows": len(found),
                      "examples": [f.case for f in found[:EXAMPLES]],
                      "repro": changes.after.repro(found[0].case)})
    return shown


def section(frame: pd.DataFrame, engines: Iterable[Mapping[str, Any]],
            directory: Path) -> dict[str, Any] | None:
    """The version section's context (None: no pair of versions in the run)."""
    listed = list(engines)
    versions = {str(e["name"]): str(e.get("version", "")) for e in listed}
    found = pairs(listed)
    if not found:
        return None
    shown = []
    for old, new in found:
        before, after = Side(directory, old, versions[old]), Side(directory, new, versions[new])
        changes = what_changed(before, after, frames=(frame, frame))
        modes = _modes(changes)
        shown.append({
            "before": before.label, "after": after.label, "old": old, "new": new,
            "compared": changes.compared, "changed": changes.changed,
            "verdicts": changes.counts(), "modes": modes,
            "more_modes": max(0, len(changes.modes) - len(modes)),
            "counts": {old: counts(frame, old), new: counts(frame, new)},
            "fast": missed_impacts(frame, (old, new)),
            "command": f"crosscheck compare {directory} --from {old} --to {new}"})
    return {"pairs": shown}
