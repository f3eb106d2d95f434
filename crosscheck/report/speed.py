"""Timing figures for the report: spreads over cases, binding overheads, the machine yardstick.

Every time the report shows comes with its spread.  An engine's time on one
kind is the median of its per-case medians (``query_s`` of the timed cases)
with the interquartile range over those cases; a case's own timing is
*unstable* when its samples' IQR exceeds :data:`UNSTABLE_SPREAD` of their
median.  The run's ``timing`` record (:class:`RunInfo`) adds the cheapest call
into each engine's Python binding and a fixed yardstick timed at the start and
the end of the timing phase, whose drift says whether the machine's speed
changed meanwhile.

Times and counts are written by :mod:`crosscheck.report.text`.

>>> drift({"median_s": 1.0, "q1_s": 0.9, "q3_s": 1.1}, {"median_s": 1.2, "q1_s": 1.1, "q3_s": 1.3})
(1.2, 1.0, 1.4444444444444444)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from crosscheck.report.cost import cost_of
from crosscheck.report.text import with_iqr
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.timings import UNSTABLE_SPREAD, Spread

__all__ = ["DRIFT_WARNING", "UNSTABLE_SPREAD", "Spread", "binding", "binding_note",
           "binding_rows", "case_times", "drift", "timing_context", "yardstick_rows"]

DRIFT_WARNING = 0.10
"""A yardstick whose end/start ratio moves further than this from 1: the machine changed speed."""


def case_times(rows: pd.DataFrame) -> tuple[Spread, int]:
    """The spread of the per-case times of these rows over their timed cases, and how many
    of those cases have an unstable timing (one value per case x engine)."""
    per_case = rows.drop_duplicates(["case_id", "engine"])
    unstable = per_case["unstable"].isin([True]) & per_case["query_s"].notna()
    return cost_of(rows).wall, int(unstable.sum())


def _stored(entry: Mapping[str, Any]) -> Spread:
    """A stored measurement (``median_s``, ``q1_s``, ``q3_s``, ``values``) as a Spread."""
    return Spread(float(entry["median_s"]), float(entry["q1_s"]), float(entry["q3_s"]),
                  len(entry.get("values", ())))


def _binding_entry(info: RunInfo, engine: str) -> Mapping[str, Any] | None:
    entry = ((info.timing or {}).get("binding") or {}).get(engine)
    return entry if isinstance(entry, Mapping) else None


def binding(info: RunInfo, engine: str) -> Spread | None:
    """The cheapest call into ``engine``'s Python binding, when the run measured it."""
    entry = _binding_entry(info, engine)
    return _stored(entry) if entry and "median_s" in entry else None


def binding_note(info: RunInfo, engine: str) -> str:
    """Why ``engine`` has no binding overhead ('' when it has one)."""
    entry = _binding_entry(info, engine)
    if entry is None:
        return "not recorded"
    return "" if "median_s" in entry else f"none: {entry.get('none', 'not measured')}"


def drift(start: Mapping[str, Any], end: Mapping[str, Any]) -> tuple[float, float, float]:
    """End/start ratio of a yardstick workload, and its range from the quartiles (low, high)."""
    s, e = _stored(start), _stored(end)
    if not s.median > 0 or not s.q1 > 0 or not s.q3 > 0:
        return math.nan, math.nan, math.nan
    return e.median / s.median, e.q1 / s.q3, e.q3 / s.q1


def yardstick_rows(timing: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Per yardstick workload: start and end (median and IQR), drift, and whether it warns."""
    stick = timing.get("yardstick") or {}
    start, end = stick.get("start") or {}, stick.get("end") or {}
    rows = []
    for workload in dict.fromkeys([*start, *end]):
        first, last = start.get(workload), end.get(workload)
        ratio, low, high = drift(first, last) if first and last else (math.nan,) * 3
        rows.append({"workload": workload, "ratio": ratio, "low": low, "high": high,
                     "start": with_iqr(_stored(first)) if first else "not measured",
                     "end": with_iqr(_stored(last)) if last else "not measured",
                     "warn": abs(ratio - 1) > DRIFT_WARNING})
    return rows


def _engine_kind_medians(frame: pd.DataFrame) -> dict[tuple[str, str], float]:
    return {(str(e), str(k)): cost_of(rows).wall.median
            for (e, k), rows in frame.groupby(["engine", "kind"], sort=False)}


def binding_rows(info: RunInfo, frame: pd.DataFrame,
                 kinds: Sequence[str]) -> list[dict[str, Any]]:
    """Per engine of the run: its binding call (median with IQR, or why none) and that call's
    share of the engine's median query time on each of ``kinds`` (None: no time there)."""
    medians = _engine_kind_medians(frame)
    rows = []
    for engine in dict.fromkeys([*info.engine_names, *frame["engine"].astype(str)]):
        call = binding(info, engine)
        shares = {kind: call.median / medians[engine, kind]
                  if call and medians.get((engine, kind), 0.0) > 0 else None for kind in kinds}
        rows.append({"engine": engine, "binding": with_iqr(call) if call else "",
                     "note": binding_note(info, engine), "shares": shares})
    return rows


def _off(info: RunInfo) -> str:
    """The one line of a run without a timing record."""
    if info.options.quick:
        return "Timing was off for this run (--quick): no case was timed."
    if not info.options.timing_cases:
        return "Timing was off for this run (timing_cases 0): no case was timed."
    return ("Timing was not recorded for this run (run.json has no timing phase, e.g. a run "
            "written before format 3).")


def timing_context(info: RunInfo, frame: pd.DataFrame, kinds: Sequence[str],
                   timings: pd.DataFrame) -> dict[str, Any]:
    """What the timing section shows; ``off`` is its one line when the run has no timing."""
    if info.timing is None:
        return {"off": _off(info)}
    sticks = yardstick_rows(info.timing)
    return {"off": "", "method": str(info.timing.get("method", "")),
            "sampled": info.timing.get("sampled"), "failed": info.timing.get("failed") or 0,
            "pinned": str(info.timing.get("pinned", "")),
            "stored": len(timings), "unstable": int(timings["unstable"].isin([True]).sum()),
            "threshold": UNSTABLE_SPREAD, "limit": DRIFT_WARNING, "yardstick": sticks,
            "drifted": [r for r in sticks if r["warn"]], "kinds": list(kinds),
            "binding": binding_rows(info, frame, kinds), "cost": cost_record(info.timing)}


def cost_record(timing: Mapping[str, Any]) -> dict[str, Any] | None:
    """The instruction timer's record of the run (``--timer instructions``): its method and
    counts, or ``none``, why nothing was counted; None: the run did not count.

    >>> cost_record({}), cost_record({"cost": {"timer": "instructions", "none": "no valgrind"}})
    (None, {'timer': 'instructions', 'none': 'no valgrind'})
    """
    cost = timing.get("cost")
    return dict(cost) if isinstance(cost, Mapping) else None
