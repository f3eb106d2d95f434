"""Timing changes between two runs, judged on their stored samples (``timings.jsonl``).

Two runs of identical code on a shared machine differ per case x engine
(load, clock and cache state drift between runs and within a run), so a test on
the raw samples alone finds "significant" changes in a third of pairs or more.
A test of A's samples against B's (:func:`judged`) finds a change only when all
three hold:

- the two samples differ by a two-sided Mann-Whitney U test at p < :data:`ALPHA`;
- the ratio of the medians (B / A) is beyond :data:`MIN_EFFECT` either way;
- the two interquartile ranges do not overlap: a burst of load that shifts a
  few samples of one run moves its median, not its whole distribution.

**Runs timed in rounds** (each sample stored with its round's machine yardstick,
:mod:`crosscheck.run.rounds`): a pair is judged twice, on its samples divided by
their rounds' yardsticks (*normalised*) and on its raw samples.  When both tests
agree the pair is that (``slower``, ``faster`` or ``same``); when they do not, the pair
is ``unknown``, its reason giving the ratio that changed (raw or normalised, and the
other when it changed the other way) and whether it lies within or beyond the largest
drift either run measured
(:func:`machine_drift`: the spread of A's or of B's round yardsticks, or the ratio
of the two runs' yardsticks), e.g. ``x1.31 slower raw, within the machine's drift
x1.45 measured by B's round yardsticks``.

**Runs timed before the rounds** (no per-round yardstick in either run): B's
samples are divided by the ratio of the two runs' start and end yardsticks
(:func:`yardstick_ratio`, unless one drifted during its run, :func:`normalisation`)
and judged once.

A pair with fewer than ``MIN_SAMPLES`` samples in either run, timed in one run
only, or from a run that stored no samples is ``unknown``: never a change, only
counted.

>>> ystick = {"yardstick": {"start": {"numpy": {"median_s": 1.0}, "python": {"median_s": 4.0}},
...                         "end": {"numpy": {"median_s": 3.0}, "python": {"median_s": 4.0}}}}
>>> yardstick(ystick)
{'numpy': 2.0, 'python': 4.0}
>>> yardstick_ratio(yardstick(ystick), {"numpy": 4.0, "python": 8.0})
2.0
>>> a, b = [1.0] * 5 + [1.1] * 5, [2.0] * 5 + [2.2] * 5
>>> judged(a, b, 1.0)["verdict"], judged(a, b, 1.0)["ratio"]
('slower', 2.0)
>>> judged(a, b, 2.0)["verdict"]
'same'

B's machine ran 1.5 times slower in its later rounds, the engine did not change:
raw, B is slower; per round, it is not; the drift B's rounds measured explains it.

>>> drift = Drift(1.5, "by B's round yardsticks")
>>> raw_b = [1.5] * 5 + [1.65] * 5
>>> found = per_round(a, raw_b, a, [1.0] * 5 + [1.1] * 5, drift)
>>> found["verdict"], found["reason"]
('unknown', "x1.50 slower raw, within the machine's drift x1.50 measured by B's round yardsticks")
>>> per_round(a, b, a, b, drift)["verdict"]
'slower'
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd
from scipy.stats import mannwhitneyu

from crosscheck.results.run import Run
from crosscheck.results.timings import (
    FILE,
    MIN_SAMPLES,
    UNSTABLE_SPREAD,
    geomean,
    read_timings,
    spread,
)
from crosscheck.results.timings import normalised as timings_normalised

ALPHA = 0.001
"""Significance level of the two-sided Mann-Whitney U test of A's samples against B's."""
MIN_EFFECT = 1.25
"""Smallest ratio of the normalised medians, either way, that counts as a change (x1.25).

Measured on this shared 2-core VM: two back-to-back full ``crosscheck run``
of identical code (688 timed pairs each, 568 compared; the timing phase one
pair at a time, pinned): the ratio of medians had a median of 0.996, a
standard deviation of 3.5% and a maximum of x1.46 (one pair); at p < 0.001
and beyond x1.25, 0 pairs were flagged (x1.1: 1).  The yardstick of the
second run drifted by x1.24 between its start and its end, so it was not
used (see :func:`normalisation`); had it been, every pair would have moved
by x0.87.  Measured earlier with other work loading the machine, ratios
reached x1.75 in bursts: a noisy machine needs a larger effect, and the
yardstick warnings say when."""
VERDICTS = ("slower", "faster", "same", "unknown")
CHANGES = ("slower", "faster")
OLD_FORMAT = "no samples stored (format < 3)"
COLUMNS = ["case_id", "engine", "n_a", "n_b", "median_a_s", "median_b_s", "ratio", "raw_ratio",
           "p_value", "verdict", "reason"]
"""The columns of ``timing_changes.csv``: ``ratio`` is B / A after the yardstick (per round, or
the runs' yardstick ratio), ``raw_ratio`` B / A of the raw medians."""


@dataclass(frozen=True)
class RunTimings:
    """What one run stored of its timing."""

    samples: dict[tuple[str, str], tuple[str, list[float]]]
    """Per (case id, engine): the unit and every kept sample (seconds)."""
    normalised: dict[tuple[str, str], list[float]]
    """Per (case id, engine) timed in rounds: every sample over its round's yardstick."""
    rounds: list[float]
    """The round yardstick of every normalised sample (seconds; empty: not timed in rounds)."""
    timed: set[tuple[str, str]]
    """Every pair the run timed (from its samples, or from its results' ``query_s``)."""
    yardstick: dict[str, float]
    doubt: str | None
    """Why the run's yardstick is an unsteady ruler (None: steady, or none)."""
    missing: str | None
    """Why the run has no samples at all (None: it has ``timings.jsonl``)."""


def run_timings(run: Run) -> RunTimings:
    """The stored samples, timed pairs and yardstick of ``run``."""
    frame = read_timings(run.directory)
    samples, normalised, rounds = {}, {}, []
    for row in frame.to_dict("records"):
        key = (str(row["case_id"]), str(row["engine"]))
        samples[key] = (str(row["unit"]), [float(v) for v in row["values"]])
        if ratios := timings_normalised(row["values"], row["yardstick"]):
            normalised[key] = list(ratios)
            rounds += [float(y) for y in row["yardstick"]]
    results = run.results.dropna(subset=["query_s"])
    timed = set(samples) | set(zip(results["case_id"], results["engine"], strict=True))
    missing = None
    if not (run.directory / FILE).exists():
        missing = OLD_FORMAT if run.format_version < 3 else "no samples stored (no timing phase)"
    return RunTimings(samples, normalised, rounds, timed, yardstick(run.info.timing),
                      yardstick_doubt(run.info.timing), missing)


def _measurements(timing: dict[str, Any] | None) -> dict[str, list[dict[str, Any]]]:
    """Per yardstick workload, its measurements (start, end) with a positive median."""
    out: dict[str, list[dict[str, Any]]] = {}
    for end in ((timing or {}).get("yardstick") or {}).values():
        for workload, stats in (end or {}).items():
            if float(stats.get("median_s", math.nan)) > 0:
                out.setdefault(workload, []).append(stats)
    return out


def yardstick(timing: dict[str, Any] | None) -> dict[str, float]:
    """Per workload, the median of the yardstick's start and end medians ({}: none stored)."""
    return {workload: float(np.median([float(s["median_s"]) for s in stats]))
            for workload, stats in _measurements(timing).items()}


def yardstick_doubt(timing: dict[str, Any] | None) -> str | None:
    """Why a run's yardstick is an unsteady ruler (None: steady): a workload's start and end
    medians differ, or one measurement's IQR exceeds ``UNSTABLE_SPREAD``, of its median.

    >>> steady = {"median_s": 1.0, "q1_s": 0.99, "q3_s": 1.01}
    >>> yardstick_doubt({"yardstick": {"start": {"python": steady}, "end": {"python": steady}}})
    >>> yardstick_doubt({"yardstick": {"start": {"python": steady},
    ...                                "end": {"python": steady | {"median_s": 1.5}}}})
    'python x1.50 from start to end'
    """
    doubts = []
    for workload, stats in _measurements(timing).items():
        medians = [float(s["median_s"]) for s in stats]
        if max(medians) > (1 + UNSTABLE_SPREAD) * min(medians):
            doubts.append(f"{workload} x{max(medians) / min(medians):.2f} from start to end")
        spreads = [(float(s.get("q3_s", math.nan)) - float(s.get("q1_s", math.nan)))
                   / float(s["median_s"]) for s in stats]
        if any(x > UNSTABLE_SPREAD for x in spreads):
            doubts.append(f"{workload} IQR {max(spreads):.0%} of its median")
    return "; ".join(doubts) or None


def yardstick_ratio(a: dict[str, float], b: dict[str, float]) -> float | None:
    """B's yardstick time over A's: geometric mean over the workloads both ran (None: none)."""
    shared = [w for w in a if w in b]
    if not shared:
        return None
    return geomean([b[w] / a[w] for w in shared])


@dataclass(frozen=True)
class Normalisation:
    """How B's timings are set against A's: per round, and for pairs timed before the rounds
    the runs' yardstick ratio ``scale`` (None: not normalised); in words, ``text``."""

    scale: float | None
    per_round: bool
    text: str

    @property
    def normalised(self) -> bool:
        return self.per_round or self.scale is not None


def normalisation(a: RunTimings, b: RunTimings) -> Normalisation:
    """How B's timings are set against A's.

    Both runs timed in rounds: each sample over its round's yardstick (:func:`per_round`).
    Otherwise, B's samples over the ratio of the two runs' yardsticks; a yardstick that
    moved during its own run (:func:`yardstick_doubt`) measures the moment, not the run: it
    is not used, and the text says why.
    """
    scale, text = _scale(a, b)
    drift = machine_drift(a, b)
    if drift is None:
        return Normalisation(scale, False, text)
    spreads = ", ".join(f"{name} x{run_drift(run):.2f}" for name, run in (("A", a), ("B", b)))
    return Normalisation(scale, True, (
        f"each sample divided by its round's yardstick (the round yardsticks' spread: "
        f"{spreads}; B's over A's: x{rounds_ratio(a, b):.2f}); a pair whose raw and normalised "
        f"samples disagree is unknown, within the largest drift measured ({drift})"))


def _scale(a: RunTimings, b: RunTimings) -> tuple[float | None, str]:
    """The factor B's samples are divided by (None: not normalised), and how it was found."""
    doubts = [f"{name}: {run.doubt}" for name, run in (("A", a), ("B", b)) if run.doubt]
    if doubts:
        return None, ("yardstick not used, it was unsteady (" + "; ".join(doubts) +
                      "): timings not normalised")
    ratio = yardstick_ratio(a.yardstick, b.yardstick)
    if ratio is None:
        lacking = " and ".join(name for name, run in (("A", a), ("B", b)) if not run.yardstick)
        where = f"no yardstick in {lacking}" if lacking else "no yardstick workload in common"
        return None, f"{where}: timings not normalised (machine drift counts as change)"
    workloads = ", ".join(sorted(set(a.yardstick) & set(b.yardstick)))
    return ratio, (f"B's samples divided by the yardstick ratio B/A = {ratio:.3f} "
                   f"(geometric mean over {workloads})")


@dataclass(frozen=True)
class Drift:
    """A speed change of the machine that the yardsticks measured (``size`` >= 1), and where."""

    size: float
    where: str

    def __str__(self) -> str:
        return f"the machine's drift x{self.size:.2f} measured {self.where}"


def run_drift(run: RunTimings) -> float:
    """The largest over the smallest round yardstick of a run (NaN: not timed in rounds)."""
    return max(run.rounds) / min(run.rounds) if run.rounds else math.nan


def rounds_ratio(a: RunTimings, b: RunTimings) -> float:
    """The median yardstick of B's samples over A's (NaN: either not timed in rounds)."""
    if not (a.rounds and b.rounds):
        return math.nan
    return float(np.median(b.rounds) / np.median(a.rounds))


def machine_drift(a: RunTimings, b: RunTimings) -> Drift | None:
    """The largest drift of the machine the two runs' round yardsticks measured: within A, within
    B, or between the two (None: either run not timed in rounds)."""
    if not (a.rounds and b.rounds):
        return None
    between = rounds_ratio(a, b)
    return max((Drift(run_drift(a), "by A's round yardsticks"),
                Drift(run_drift(b), "by B's round yardsticks"),
                Drift(max(between, 1 / between), "between the two runs' round yardsticks")),
               key=lambda d: d.size)


def p_value(a: npt.ArrayLike, b: npt.ArrayLike) -> float:
    """Two-sided Mann-Whitney U p-value of ``a`` against ``b``."""
    return float(mannwhitneyu(a, b, alternative="two-sided").pvalue)


def judged(a: Sequence[float], b: Sequence[float], scale: float) -> dict[str, Any]:
    """The test of A's samples against B's divided by ``scale``: ratio, p-value, verdict, reason."""
    xa, xb = np.asarray(a, dtype=float), np.asarray(b, dtype=float) / scale
    median_a, median_b = float(np.median(xa)), float(np.median(xb))
    if not (median_a > 0 and median_b > 0):
        return {"verdict": "unknown", "reason": "a median at or below 0 s (below the timing "
                                                "loop's resolution)"}
    ratio, p = median_b / median_a, p_value(xa, xb)
    size = max(ratio, 1 / ratio)
    qa, qb = spread(xa.tolist()), spread(xb.tolist())
    apart = qb.q1 > qa.q3 if ratio > 1 else qb.q3 < qa.q1
    verdict = ("same" if p >= ALPHA or size <= MIN_EFFECT or not apart
               else "slower" if ratio > 1 else "faster")
    why = (f"p = {p:.2g} >= {ALPHA:g}" if p >= ALPHA
           else f"x{size:.2f} within x{MIN_EFFECT:g}" if size <= MIN_EFFECT
           else "the interquartile ranges overlap" if not apart
           else f"p = {p:.2g}, x{size:.2f}, interquartile ranges apart")
    return {"ratio": ratio, "p_value": p, "verdict": verdict, "reason": why}


def _direction(verdict: dict[str, Any]) -> str:
    """``x1.31 slower`` or ``x1.31 faster``: the size and way of a judged ratio."""
    ratio = float(verdict.get("ratio", math.nan))
    return f"x{max(ratio, 1 / ratio):.2f} {'slower' if ratio > 1 else 'faster'}"


def _within(verdict: dict[str, Any], drift: Drift) -> bool:
    """Whether a judged ratio, either way, is no larger than ``drift`` (to rounding)."""
    ratio = float(verdict["ratio"])
    return max(ratio, 1 / ratio) <= drift.size * (1 + 1e-9)


def per_round(a: Sequence[float], b: Sequence[float], norm_a: Sequence[float],
              norm_b: Sequence[float], drift: Drift) -> dict[str, Any]:
    """The judgement of a pair timed in rounds in both runs: on its normalised samples and on its
    raw ones; a change only when both agree, else ``unknown`` against ``drift``."""
    normal, raw = judged(norm_a, norm_b, 1.0), judged(a, b, 1.0)
    found = normal | {"raw_ratio": raw.get("ratio", math.nan)}
    if normal["verdict"] == "unknown" or raw["verdict"] == "unknown":
        return found | {"verdict": "unknown", "reason": normal["reason"] if normal[
            "verdict"] == "unknown" else raw["reason"]}
    if normal["verdict"] == raw["verdict"]:
        return found | {"reason": f"normalised: {normal['reason']}; raw x{raw['ratio']:.2f}"}
    if raw["verdict"] in CHANGES:
        why = (f"{_direction(raw)} raw, within {drift}" if _within(raw, drift) else
               f"{_direction(raw)} raw, beyond {drift}, but not normalised "
               f"({normal['reason']})")
        if normal["verdict"] in CHANGES:  # the two ways: slower on one, faster on the other
            why += f"; {_direction(normal)} normalised"
    else:
        why = (f"{_direction(normal)} normalised, but not raw ({raw['reason']}), "
               f"{'within' if _within(normal, drift) else 'beyond'} {drift}")
    return found | {"verdict": "unknown", "reason": why}


def _pair(key: tuple[str, str], a: RunTimings, b: RunTimings, scale: float | None,
          drift: Drift | None) -> dict[str, Any]:
    sa, sb = a.samples.get(key), b.samples.get(key)
    row: dict[str, Any] = {
        "case_id": key[0], "engine": key[1], "n_a": len(sa[1]) if sa else 0,
        "n_b": len(sb[1]) if sb else 0, "median_a_s": float(np.median(sa[1])) if sa else math.nan,
        "median_b_s": float(np.median(sb[1])) if sb else math.nan, "ratio": math.nan,
        "raw_ratio": math.nan, "p_value": math.nan, "verdict": "unknown"}
    if a.missing or b.missing:
        return row | {"reason": a.missing if a.missing == OLD_FORMAT or not b.missing
                      else b.missing}
    if sa is None or sb is None:
        return row | {"reason": f"timed in {'B' if sa is None else 'A'} only"}
    if min(len(sa[1]), len(sb[1])) < MIN_SAMPLES:
        return row | {"reason": f"fewer than {MIN_SAMPLES} samples"}
    if sa[0] != sb[0]:
        return row | {"reason": f"units differ ({sa[0]} vs {sb[0]})"}
    if drift is not None and key in a.normalised and key in b.normalised:
        return row | per_round(sa[1], sb[1], a.normalised[key], b.normalised[key], drift)
    raw_ratio = row["median_b_s"] / row["median_a_s"] if row["median_a_s"] > 0 else math.nan
    return row | judged(sa[1], sb[1], 1.0 if scale is None else scale) | {
        "raw_ratio": raw_ratio}


def timing_changes(a: RunTimings, b: RunTimings, cases: set[str], engines: set[str],
                   scale: float | None = None) -> pd.DataFrame:
    """One row per pair timed in either run among the shared ``cases`` x ``engines``.

    Pairs timed in rounds in both runs are judged per round (:func:`per_round`); the others
    with B's samples divided by ``scale`` (the yardstick ratio; None: not normalised).
    Ordered changes first (largest first), then ``same``, then ``unknown``.
    """
    keys = sorted(k for k in a.timed | b.timed if k[0] in cases and k[1] in engines)
    drift = machine_drift(a, b)  # once for every pair: it reads every round of both runs
    frame = pd.DataFrame([_pair(k, a, b, scale, drift) for k in keys], columns=COLUMNS)
    return changes_first(frame, VERDICTS)


def changes_first(frame: pd.DataFrame, verdicts: Sequence[str]) -> pd.DataFrame:
    """``frame`` ordered by its ``verdict`` in the order of ``verdicts``, and within one
    verdict by the size of its ``ratio`` either way, largest first."""
    rank = frame["verdict"].map({v: i for i, v in enumerate(verdicts)})
    size = -np.abs(np.log(frame["ratio"].to_numpy(dtype=float)))
    order = pd.DataFrame({"rank": rank, "size": np.nan_to_num(size)}).sort_values(
        ["rank", "size"], kind="stable").index
    return frame.loc[order].reset_index(drop=True)


def engine_summary(changes: pd.DataFrame, engines: Sequence[str]) -> pd.DataFrame:
    """Per engine (in ``engines`` order): pairs, verdict counts, geomean of the judged pairs'
    ratios after the yardstick and of their raw ratios."""
    rows = []
    for engine in engines:
        group = changes[changes["engine"] == engine]
        if group.empty:
            continue
        judged_pairs = group[group["verdict"] != "unknown"]
        counts = group["verdict"].value_counts()
        rows.append({"engine": engine, "pairs": len(group),
                     **{v: int(counts.get(v, 0)) for v in VERDICTS},
                     "geomean_ratio": geomean(judged_pairs["ratio"].astype(float).tolist()),
                     "geomean_raw": geomean(judged_pairs["raw_ratio"].astype(float).tolist())})
    return pd.DataFrame(rows, columns=["engine", "pairs", *VERDICTS, "geomean_ratio",
                                       "geomean_raw"])

