"""Cost changes between two runs, judged on counted instructions (``counts.jsonl``).

A count is not a sample of a noisy clock: the same code on the same inputs runs
the same instructions, so no statistics are needed.  A pair counted in both runs
changes when its instructions per query move by more than :data:`THRESHOLD` either
way (``more`` or ``less`` work); otherwise it is ``same``.  A pair counted in one
run only, or a pair whose unit differs (a call, a scene run), is ``unknown``.  A
count is never compared with a wall time: a run that counted nothing leaves every
pair ``unknown`` with the reason, and the wall-clock comparison
(:mod:`crosscheck.compare.timing`) stands alone.

>>> judged(100_000.0, 105_000.0)
('more', '+5.00% instructions per query (100,000 -> 105,000), beyond the 1% threshold')
>>> judged(100_000.0, 100_400.0)[0]
'same'
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import pandas as pd

from crosscheck.compare.timing import changes_first
from crosscheck.results.counts import FILE, read_counts
from crosscheck.results.run import Run
from crosscheck.results.timings import geomean

THRESHOLD = 0.01
"""A pair whose instructions per query move by more than this share either way has changed."""
VERDICTS = ("more", "less", "same", "unknown")
COLUMNS = ["case_id", "engine", "unit", "instructions_a", "instructions_b", "ratio",
           "engine_a", "engine_b", "verdict", "reason"]


@dataclass(frozen=True)
class RunCounts:
    """What one run stored of its instruction counts."""

    counts: dict[tuple[str, str], tuple[str, float, float]]
    """Per (case id, engine): the unit, instructions per query, and of them the engine's."""
    missing: str | None
    """Why the run has no counts (None: it has ``counts.jsonl``)."""


def run_counts(run: Run) -> RunCounts:
    """The stored counts of ``run``."""
    frame = read_counts(run.directory)
    counts = {(str(c), str(e)): (str(u), float(q), float(g)) for c, e, u, q, g in zip(
        frame["case_id"], frame["engine"], frame["unit"], frame["query_instructions"],
        frame["engine_instructions"], strict=True)}
    missing = None
    if not (run.directory / FILE).exists():
        missing = "no instructions counted (a run without --timer instructions)"
    return RunCounts(counts, missing)


def judged(a: float, b: float, threshold: float = THRESHOLD) -> tuple[str, str]:
    """The verdict on instructions per query ``a`` then ``b``, and its reason with the numbers."""
    if not (a > 0 and b > 0):
        return "unknown", f"a count at or below 0 ({a:,.0f} -> {b:,.0f})"
    change = b / a - 1
    verdict = "same" if abs(change) <= threshold else "more" if change > 0 else "less"
    where = "beyond" if verdict != "same" else "within"
    return verdict, (f"{change:+.2%} instructions per query ({a:,.0f} -> {b:,.0f}), {where} "
                     f"the {threshold * 100:g}% threshold")


def _pair(key: tuple[str, str], a: RunCounts, b: RunCounts, threshold: float) -> dict[str, Any]:
    ca, cb = a.counts.get(key), b.counts.get(key)
    row: dict[str, Any] = {
        "case_id": key[0], "engine": key[1], "unit": (ca or cb or ("",))[0],
        "instructions_a": ca[1] if ca else math.nan, "instructions_b": cb[1] if cb else math.nan,
        "engine_a": ca[2] if ca else math.nan, "engine_b": cb[2] if cb else math.nan,
        "ratio": math.nan, "verdict": "unknown"}
    if a.missing or b.missing:
        return row | {"reason": "; ".join(f"{n}: {r.missing}" for n, r in (("A", a), ("B", b))
                                          if r.missing)}
    if ca is None or cb is None:
        return row | {"reason": f"counted in {'B' if ca is None else 'A'} only"}
    if ca[0] != cb[0]:
        return row | {"reason": f"units differ ({ca[0]} vs {cb[0]})"}
    verdict, reason = judged(ca[1], cb[1], threshold)
    return row | {"ratio": cb[1] / ca[1] if ca[1] > 0 else math.nan, "verdict": verdict,
                  "reason": reason}


def cost_changes(a: RunCounts, b: RunCounts, cases: set[str], engines: set[str],
                 threshold: float = THRESHOLD) -> pd.DataFrame:
    """One row per pair counted in either run among the shared ``cases`` x ``engines``:
    changes first (largest first), then ``same``, then ``unknown``."""
    keys = sorted(k for k in set(a.counts) | set(b.counts) if k[0] in cases and k[1] in engines)
    frame = pd.DataFrame([_pair(k, a, b, threshold) for k in keys], columns=COLUMNS)
    return changes_first(frame, VERDICTS)


def cost_summary(changes: pd.DataFrame, engines: list[str]) -> pd.DataFrame:
    """Per engine (in ``engines`` order): pairs, verdict counts, geometric mean of the ratios."""
    rows = []
    for engine in engines:
        group = changes[changes["engine"] == engine]
        if group.empty:
            continue
        ratios = group["ratio"].dropna().astype(float)
        counts = group["verdict"].value_counts()
        rows.append({"engine": engine, "pairs": len(group),
                     **{v: int(counts.get(v, 0)) for v in VERDICTS},
                     "geomean_ratio": geomean(ratios.tolist())})
    return pd.DataFrame(rows, columns=["engine", "pairs", *VERDICTS, "geomean_ratio"])
