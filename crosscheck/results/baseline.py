"""Baselines: what a run is expected to say, row by row, and a check that fails both ways.

A baseline is the status, category and error of every case x engine x quantity of one run,
kept in a reviewable file.  :func:`judge` compares a later run with it and gives one
:class:`Finding` per row of either side: a row that got worse is a ``regression``, one that
got better than the baseline says is ``stale`` (the baseline must be updated, so that it
keeps telling the truth: Drake's characterization tests fail in the same way when an error
shrinks below half its published bound), a row the run lacks is ``missing`` and one the
baseline lacks is ``new``.  Every verdict but ``expected`` and ``skipped`` fails.

The rules, the one place they are kept (``_rule``, ``_disagreement`` and ``_alone`` below
follow this table; ``failed`` is error, crash or timeout, ``neutral`` skip or undefined):

| baseline entry | run row | verdict | the reason says |
|---|---|---|---|
| (no baseline) | agree | expected | agree |
| (no baseline) | skip, undefined | skipped | the row's reason |
| (no baseline) | disagree, failed | regression | no baseline: every disagreement fails |
| none | any | new | the row |
| any | none | missing | the entry |
| a status | the same (not disagree) | expected | as in the baseline |
| agree | disagree | regression | a new disagreement |
| agree | failed | regression | a new error, crash or timeout |
| agree, disagree | skip, undefined | regression | no longer answered |
| disagree | agree | stale | better than the baseline: update it |
| disagree | disagree, another category | regression | both categories (now unexplained) |
| disagree | disagree, error > bound x (1 + margin) | regression | error, bound, margin |
| disagree | disagree, error < bound / factor | stale | error, bound, factor |
| disagree | disagree, otherwise | expected | error, bound |
| disagree | failed | regression | the failure |
| failed | agree | stale | better than the baseline: update it |
| failed | disagree | stale | answers now |
| failed | a worse failed status (severity) | regression | both statuses |
| failed | a milder failed status | stale | both statuses |
| failed | skip, undefined | stale | no longer fails, not answered either |
| skip, undefined | agree, disagree | stale | newly answered |
| skip, undefined | failed | regression | newly failing |
| skip, undefined | the other neutral status | stale | both statuses |

The *bound* is the baseline entry's error.  A row the repeat check found nondeterministic
(the ``nondeterministic`` column) says so in its reason.  Every reason carries the numbers
that justify it: the error, the bound, the margin or the factor, the tolerance.

>>> import pandas as pd
>>> run = pd.DataFrame({"case_id": ["touch", "touch"], "engine": ["e", "e"],
...     "quantity": ["hit", "distance"], "status": ["agree", "disagree"],
...     "category": ["", "tolerance"], "error": [0.0, 1e-9], "tolerance": [0.0, 4e-16]})
>>> baseline = from_rows(run, source="reports/first")
>>> [(f.quantity, str(f.verdict)) for f in judge(run, baseline)]
[('distance', 'expected'), ('hit', 'expected')]
>>> worse = judge(run.assign(error=[0.0, 2e-9]), baseline)[0]
>>> worse.verdict.fails, worse.reason
(True, 'error 2e-09 > bound 1e-09 x (1 + margin 0.5) = 1.5e-09 (tolerance 4e-16)')
>>> str(judge(run.assign(error=[0.0, 1e-10]), baseline)[0].verdict)
'stale'
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass
from enum import StrEnum
from typing import TYPE_CHECKING, Any

from crosscheck.core.model import Status
from crosscheck.results.baseline_file import (
    DEFAULT_MARGIN,
    DEFAULT_STALE_FACTOR,
    Baseline,
    BaselineError,
    Entry,
    Key,
    read_baseline,
    settings_problem,
    write_baseline,
)

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["DEFAULT_MARGIN", "DEFAULT_STALE_FACTOR", "Baseline", "BaselineError", "Entry",
           "Finding", "Verdict", "engines_beyond", "from_rows", "judge", "read_baseline",
           "updated", "write_baseline"]


class Verdict(StrEnum):
    """What one row is against the baseline (the module's table says when)."""

    EXPECTED = "expected"
    SKIPPED = "skipped"
    """A neutral row (skip, undefined) judged without a baseline."""
    REGRESSION = "regression"
    STALE = "stale"
    MISSING = "missing"
    """In the baseline, not in the run."""
    NEW = "new"
    """In the run, not in the baseline."""

    @property
    def fails(self) -> bool:
        """Whether this verdict fails a check (all but expected and skipped)."""
        return self not in (Verdict.EXPECTED, Verdict.SKIPPED)


@dataclass(frozen=True)
class Finding:
    """The verdict on one case x engine x quantity, why, and both sides (None: absent)."""

    case: str
    engine: str
    quantity: str
    verdict: Verdict
    reason: str
    expected: Entry | None
    got: Entry | None


@dataclass(frozen=True)
class _Row:
    """A run's row: its entry, and what its reason needs beside."""

    entry: Entry
    tolerance: float
    reason: str
    nondeterministic: bool


def _rows(frame: pd.DataFrame) -> dict[Key, _Row]:
    """The rows of a results frame by key (``tolerance``, ``reason`` and ``nondeterministic``
    are optional columns)."""
    n = len(frame)
    columns = [frame[name] if name in frame else [default] * n for name, default in
               (("category", ""), ("error", math.nan), ("tolerance", math.nan), ("reason", ""),
                ("nondeterministic", False))]
    rows: dict[Key, _Row] = {}
    for case, engine, quantity, status, category, error, tolerance, reason, flag in zip(
            frame["case_id"], frame["engine"], frame["quantity"], frame["status"], *columns,
            strict=True):
        entry = Entry(str(case), str(engine), str(quantity), str(Status(status)),
                      category if isinstance(category, str) else "", float(error))
        if entry.key in rows:
            raise ValueError(f"two rows of case {case!r} on {engine!r}, quantity {quantity!r}")
        rows[entry.key] = _Row(entry, float(tolerance), reason if isinstance(reason, str)
                               else "", bool(flag))
    return rows


def from_rows(frame: pd.DataFrame, margin: float = DEFAULT_MARGIN,
              stale_factor: float = DEFAULT_STALE_FACTOR, source: str = "") -> Baseline:
    """The baseline of a results frame (every row of it: agree, neutral and failed ones too)."""
    problem = settings_problem(margin, stale_factor)
    if problem:
        raise ValueError(problem)
    return Baseline({key: row.entry for key, row in _rows(frame).items()}, margin,
                    stale_factor, source)


def updated(baseline: Baseline | None, frame: pd.DataFrame,
            engines: Collection[str] | None = None, margin: float | None = None,
            stale_factor: float | None = None, source: str = "") -> Baseline:
    """``baseline`` rewritten from ``frame``: the entries of ``engines`` (all: every engine)
    replaced by the frame's rows, those of other engines kept; its margin and factor kept
    unless given."""
    margin = (DEFAULT_MARGIN if baseline is None else baseline.margin) if margin is None \
        else margin
    factor = (DEFAULT_STALE_FACTOR if baseline is None else baseline.stale_factor) \
        if stale_factor is None else stale_factor
    scoped = frame if engines is None else frame[frame["engine"].isin(list(engines))]
    fresh = from_rows(scoped, margin, factor, source)
    kept = {} if baseline is None or engines is None else {
        key: entry for key, entry in baseline.entries.items() if key[1] not in engines}
    return Baseline(kept | fresh.entries, margin, factor, source)


def engines_beyond(frame: pd.DataFrame, baseline: Baseline) -> dict[str, int]:
    """The run's engines of which ``baseline`` holds no row, with their row counts: judged
    against it without an ``engines`` scope, every one of their rows would be new (an empty
    baseline: none, it holds no engine to scope to).

    >>> import pandas as pd
    >>> from crosscheck.results.baseline_file import Entry
    >>> base = Baseline({("c", "a", "hit"): Entry("c", "a", "hit", "agree", "", 0.0)}, 0.5,
    ...                 2.0, "run")
    >>> engines_beyond(pd.DataFrame({"engine": ["a", "b", "b"]}), base)
    {'b': 2}
    """
    if not baseline.engines:
        return {}
    counts = frame["engine"].astype(str).value_counts(sort=False)
    return {str(e): int(n) for e, n in counts.items() if e not in baseline.engines}


def judge(frame: pd.DataFrame, baseline: Baseline | None,
          engines: Collection[str] | None = None, margin: float | None = None,
          stale_factor: float | None = None) -> list[Finding]:
    """One finding per case x engine x quantity of the run or the baseline (only those of
    ``engines`` when given: an explicit scope), sorted by engine, case and quantity.

    ``margin`` and ``stale_factor`` override the baseline's; without a baseline every
    breaking row is a regression (the module's table)."""
    rows = {key: row for key, row in _rows(frame).items()
            if engines is None or key[1] in engines}
    if baseline is None:
        return [_finding(key, None, row, *_alone(row)) for key, row in sorted(rows.items(),
                                                                              key=_order)]
    margin = baseline.margin if margin is None else margin
    factor = baseline.stale_factor if stale_factor is None else stale_factor
    problem = settings_problem(margin, factor)
    if problem:
        raise ValueError(problem)
    entries = {key: entry for key, entry in baseline.entries.items()
               if engines is None or key[1] in engines}
    findings = []
    for key in sorted(rows.keys() | entries.keys(), key=lambda k: (k[1], k[0], k[2])):
        entry, row = entries.get(key), rows.get(key)
        if row is None:
            assert entry is not None
            verdict, reason = Verdict.MISSING, f"in the baseline ({_was(entry)}), not in the run"
        elif entry is None:
            verdict, reason = Verdict.NEW, f"in the run ({_now(row)}), not in the baseline"
        else:
            verdict, reason = _rule(entry, row, margin, factor)
        findings.append(_finding(key, entry, row, verdict, reason))
    return findings


def _order(item: tuple[Key, Any]) -> tuple[str, str, str]:
    case, engine, quantity = item[0]
    return (engine, case, quantity)


def _finding(key: Key, entry: Entry | None, row: _Row | None, verdict: Verdict,
             reason: str) -> Finding:
    if row is not None and row.nondeterministic:
        reason += " [nondeterministic: the repeat check got another answer]"
    return Finding(*key, verdict, reason, entry, None if row is None else row.entry)


# The rules: the module docstring's table, in code.

def _alone(row: _Row) -> tuple[Verdict, str]:
    """A row judged without a baseline."""
    now = Status(row.entry.status)
    if now.breaking:
        return Verdict.REGRESSION, f"no baseline: every disagreement fails; {_now(row)}"
    return (Verdict.SKIPPED if now.neutral else Verdict.EXPECTED), _now(row)


def _rule(entry: Entry, row: _Row, margin: float, factor: float) -> tuple[Verdict, str]:
    """A row judged against its baseline entry."""
    was, now = Status(entry.status), Status(row.entry.status)
    if was is Status.DISAGREE and now is Status.DISAGREE:
        return _disagreement(entry, row, margin, factor)
    if was is now:
        return Verdict.EXPECTED, f"{_now(row)}, as in the baseline"
    baseline = f"the baseline has {_was(entry)}"
    if now.neutral:
        if was.scored:
            return Verdict.REGRESSION, f"no longer answered: {_now(row)}; {baseline}"
        if was.failed:
            return Verdict.STALE, (f"no longer fails, but is not answered either: {_now(row)}; "
                                   f"{baseline}: update it")
        return Verdict.STALE, f"{_now(row)}; {baseline}: update it"
    if was.neutral:
        if now.failed:
            return Verdict.REGRESSION, f"newly failing: {_now(row)}; {baseline}"
        return Verdict.STALE, f"newly answered: {_now(row)}; {baseline}: update it"
    if now.failed:
        if was.failed and now.severity > was.severity:
            return Verdict.STALE, f"a milder failure: {_now(row)}; {baseline}: update it"
        what = "a worse failure" if was.failed else f"a new {now}"
        return Verdict.REGRESSION, f"{what}: {_now(row)}; {baseline}"
    if now is Status.AGREE:  # the baseline disagrees or failed
        return Verdict.STALE, (f"better than the baseline: {_now(row)}; {baseline}: "
                               "update it")
    if was is Status.AGREE:
        return Verdict.REGRESSION, f"a new disagreement: {_now(row)}; {baseline}"
    return Verdict.STALE, f"answers now: {_now(row)}; {baseline}: update it"


def _disagreement(entry: Entry, row: _Row, margin: float, factor: float) -> tuple[Verdict, str]:
    """A row that disagrees, against an entry that disagreed."""
    got = row.entry
    tolerance = f" (tolerance {_g(row.tolerance)})"
    if got.category != entry.category:
        what = ("now unexplained: category error" if got.category == "error"
                else f"category changed to {got.category or '(none)'}")
        return Verdict.REGRESSION, (f"{what}, the baseline has {entry.category or '(none)'} "
                                    f"(error {_g(got.error)}, bound {_g(entry.error)})")
    bound, error = entry.error, got.error
    if math.isnan(bound) or math.isnan(error):
        return Verdict.EXPECTED, (f"disagree ({got.category}) as in the baseline, no error to "
                                  f"compare (error {_g(error)}, bound {_g(bound)})")
    limit, floor = bound * (1 + margin), bound / factor
    if error > limit:
        shown, limit_shown = _pair(error, limit)
        return Verdict.REGRESSION, (f"error {shown} > bound {_g(bound)} x (1 + margin "
                                    f"{margin:g}) = {limit_shown}{tolerance}")
    if error < floor:
        shown, floor_shown = _pair(error, floor)
        return Verdict.STALE, (f"error {shown} < bound {_g(bound)} / stale factor {factor:g} = "
                               f"{floor_shown}: better than the baseline, update it{tolerance}")
    return Verdict.EXPECTED, (f"disagree ({got.category}) within the baseline: error "
                              f"{_g(error)}, bound {_g(bound)} (margin {margin:g}, stale factor "
                              f"{factor:g}){tolerance}")


def _now(row: _Row) -> str:
    """A run's row in words, with its numbers."""
    got, status = row.entry, Status(row.entry.status)
    if status.scored:
        label = "agree" if status is Status.AGREE else f"disagree ({got.category})"
        return f"{label}, error {_g(got.error)} against tolerance {_g(row.tolerance)}"
    return f"{status} ({row.reason})" if row.reason else str(status)


def _was(entry: Entry) -> str:
    """A baseline entry in words."""
    if entry.status == Status.DISAGREE:
        return f"disagree ({entry.category}), error {_g(entry.error)}"
    return entry.status


def _g(x: float) -> str:
    return f"{x:.4g}"


def _pair(a: float, b: float) -> tuple[str, str]:
    """``a`` and ``b`` written with the fewest digits that keep them apart (if they differ)."""
    for digits in (4, 6, 9, 12):
        shown = f"{a:.{digits}g}", f"{b:.{digits}g}"
        if shown[0] != shown[1] or a == b:
            return shown
    return repr(a), repr(b)


