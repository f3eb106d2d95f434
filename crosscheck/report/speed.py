"""Timing figures for the report: spreads over cases, binding overheads, the machine yardstick.

Every time the report shows comes with its spread.  An engine's time on one
kind is the median of its per-case medians (``query_s`` of the timed cases)
with the interquartile range over those cases; a case's own timing is
*unstable* when its samples' IQR exceeds :data:`UNSTABLE_SPREAD` of their
median.  The run's ``timing`` record (:class:`RunInfo`) adds the cheapest call
into each engine's Python binding and a fixed yardstick timed at the start and
the end of the timing phase, whose drift says whether the machine's speed
changed meanwhile.

Every median with its spread is written one way, on the page, in the advise form
and on the command line (:func:`median_iqr`): the median to three significant
digits in ns, µs, ms or s, then ``±`` the IQR in the same unit.  A count of
instructions per query (``crosscheck run --timer instructions``) is written the same
way with a decimal prefix (:func:`instructions_iqr`): ``93.3 ± 4.1 k instr``.

>>> seconds(2e-05)
'20 µs'
>>> with_iqr(Spread(2e-6, 1.5e-6, 2.5e-6, 5))
'2 ± 1 µs'
>>> drift({"median_s": 1.0, "q1_s": 0.9, "q3_s": 1.1}, {"median_s": 1.2, "q1_s": 1.1, "q3_s": 1.3})
(1.2, 1.0, 1.4444444444444444)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import pandas as pd

from crosscheck.results.runinfo import RunInfo
from crosscheck.results.timings import UNSTABLE_SPREAD, Spread, spread

__all__ = ["DRIFT_WARNING", "UNSTABLE_SPREAD", "Spread", "binding", "binding_note",
           "binding_rows", "case_times", "drift", "instructions", "instructions_iqr",
           "median_iqr", "seconds", "timing_context", "with_iqr", "yardstick_rows"]

DRIFT_WARNING = 0.10
"""A yardstick whose end/start ratio moves further than this from 1: the machine changed speed."""


UNITS = ((1.0, "s"), (1e-3, "ms"), (1e-6, "µs"), (1e-9, "ns"))
"""The units a time is written in, largest first (below 1 ns: ns with decimals)."""


def _unit(value: float) -> tuple[float, str]:
    """The largest unit in which ``value`` is at least 1 (after rounding to 3 digits)."""
    return next(((scale, unit) for scale, unit in UNITS if value >= scale * 0.9995), UNITS[-1])


def _digits(value: float, significant: int) -> str:
    """``value`` to ``significant`` digits without an exponent (whole from 10**digits on;
    below 0.01: '<0.01'), exactly as the page's script writes it.

    >>> _digits(12.84, 3), _digits(1.25, 2), _digits(99.7, 2), _digits(0.004, 2), _digits(0.0, 2)
    ('12.8', '1.2', '100', '<0.01', '0')
    """
    if value == 0:
        return "0"
    if value < 0.01:
        return "<0.01"
    if value >= 10 ** significant - 0.5:
        return f"{value:.0f}"
    return f"{value:.{significant}g}"


def seconds(value: float) -> str:
    """A duration with an SI prefix, to three significant digits: 2e-05 -> '20 µs'.

    >>> seconds(1.2845e-05), seconds(9.9996e-04), seconds(3e-10), seconds(float("nan"))
    ('12.8 µs', '1 ms', '0.3 ns', 'n/a')
    """
    if math.isnan(value):
        return "n/a"
    scale, unit = _unit(value)
    return f"{_digits(value / scale, 3)} {unit}"


def median_iqr(median: float | None, iqr: float | None) -> str:
    """A median time and its interquartile range, in the one format of the page and the CLI:
    the median to three significant digits, ``±`` the IQR to two, in the median's unit.

    >>> median_iqr(1.2845e-05, 1.2e-06), median_iqr(8.5e-07, 3e-08), median_iqr(2e-3, None)
    ('12.8 ± 1.2 µs', '850 ± 30 ns', '2 ms')
    >>> median_iqr(None, None), median_iqr(float("nan"), 1.0)
    ('n/a', 'n/a')
    """
    return _spread_text(median, iqr, _unit)


def _spread_text(median: float | None, iqr: float | None,
                 unit_of: Callable[[float], tuple[float, str]]) -> str:
    """The median to three significant digits, ``± `` the IQR to two, in the median's unit."""
    if median is None or math.isnan(median):
        return "n/a"
    scale, unit = unit_of(median)
    if iqr is None or math.isnan(iqr):
        return f"{_digits(median / scale, 3)} {unit}"
    return f"{_digits(median / scale, 3)} ± {_digits(iqr / scale, 2)} {unit}"


COUNT_UNITS = ((1e9, "G instr"), (1e6, "M instr"), (1e3, "k instr"), (1.0, "instr"))
"""The units a count of instructions is written in, largest first."""


def _count_unit(value: float) -> tuple[float, str]:
    return next(((scale, unit) for scale, unit in COUNT_UNITS if value >= scale * 0.9995),
                COUNT_UNITS[-1])


def instructions(value: float) -> str:
    """A count of instructions with a decimal prefix, to three significant digits.

    >>> instructions(93349.0), instructions(850.0), instructions(1.2e6), instructions(math.nan)
    ('93.3 k instr', '850 instr', '1.2 M instr', 'n/a')
    """
    if math.isnan(value):
        return "n/a"
    scale, unit = _count_unit(value)
    return f"{_digits(value / scale, 3)} {unit}"


def instructions_iqr(median: float | None, iqr: float | None) -> str:
    """A median count of instructions and its interquartile range, as :func:`median_iqr`
    writes a time: the median to three significant digits, ``±`` the IQR to two, in the
    median's unit.

    >>> instructions_iqr(93349.0, 4100.0), instructions_iqr(850.0, 30.0)
    ('93.3 ± 4.1 k instr', '850 ± 30 instr')
    >>> instructions_iqr(1.2e6, None), instructions_iqr(None, None)
    ('1.2 M instr', 'n/a')
    """
    return _spread_text(median, iqr, _count_unit)


def with_iqr(s: Spread) -> str:
    """A spread as :func:`median_iqr` writes it: '2 ± 1 µs'."""
    return median_iqr(s.median, s.iqr)


def case_times(rows: pd.DataFrame) -> tuple[Spread, int]:
    """The spread of the per-case times of these rows over their timed cases, and how many
    of those cases have an unstable timing (one value per case x engine)."""
    per_case = rows.drop_duplicates(["case_id", "engine"])
    timed = per_case[per_case["query_s"].notna()]
    return spread(timed["query_s"].tolist()), int(timed["unstable"].isin([True]).sum())


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
    per_case = frame.drop_duplicates(["engine", "case_id"])
    medians = per_case.groupby(["engine", "kind"], sort=False)["query_s"].median()
    return {(str(e), str(k)): float(v) for e, k, v in
            zip(medians.index.get_level_values(0), medians.index.get_level_values(1),
                medians.to_numpy(), strict=True)}


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
