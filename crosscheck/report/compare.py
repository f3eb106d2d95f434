"""Compare two stored runs: verdicts that changed, and timing changes beyond the noise.

Typical use: the same suite before and after an engine upgrade.  A verdict is
a row's status and category; a row present in one run only is ``added`` or
``removed``.  A timing change (per case x engine) counts only when the two
medians differ by more than ``MIN_RATIO`` and their interquartile ranges do
not overlap; timings from two runs are noisier than ratios within one run,
which the page says.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from crosscheck.report.style import templates
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.store import read_run

KEY = ["case_id", "engine", "quantity"]
MIN_RATIO = 1.10
"""Smallest ratio of medians (either way) reported as a timing change."""


def verdict_changes(a: pd.DataFrame, b: pd.DataFrame) -> pd.DataFrame:
    """Rows whose status or category differ, or that exist in one run only."""
    cols = [*KEY, "status", "category", "value", "error"]
    both = a[cols].merge(b[cols], on=KEY, how="outer", suffixes=("_a", "_b"), indicator=True)
    both["change"] = np.select(
        [both["_merge"] == "left_only", both["_merge"] == "right_only"],
        ["removed", "added"], default="changed")
    same = (both["status_a"] == both["status_b"]) & (
        both["category_a"].fillna("") == both["category_b"].fillna(""))
    return both[~same | (both["_merge"] != "both")].drop(columns="_merge").reset_index(drop=True)


def _timings(frame: pd.DataFrame) -> pd.DataFrame:
    per_pair = frame.drop_duplicates(["case_id", "engine"])
    return per_pair[["case_id", "engine", "query_s", "query_iqr_s"]].dropna(subset=["query_s"])


def timing_changes(a: pd.DataFrame, b: pd.DataFrame) -> pd.DataFrame:
    """Case x engine pairs whose query time changed beyond the noise, largest first."""
    both = _timings(a).merge(_timings(b), on=["case_id", "engine"], suffixes=("_a", "_b"))
    both["ratio"] = both["query_s_b"] / both["query_s_a"]
    gap = (both["query_s_b"] - both["query_s_a"]).abs()
    noise = both["query_iqr_s_a"] / 2 + both["query_iqr_s_b"] / 2
    beyond = (gap > noise) & ((both["ratio"] > MIN_RATIO) | (both["ratio"] < 1 / MIN_RATIO))
    out = both[beyond].copy()
    out["_size"] = np.log(out["ratio"]).abs()
    return out.sort_values("_size", ascending=False).drop(columns="_size").reset_index(drop=True)


def engine_ratios(a: pd.DataFrame, b: pd.DataFrame) -> pd.DataFrame:
    """Per engine: geometric mean of B/A query-time ratios over the cases both timed."""
    both = _timings(a).merge(_timings(b), on=["case_id", "engine"], suffixes=("_a", "_b"))
    both = both[(both["query_s_a"] > 0) & (both["query_s_b"] > 0)]
    logs = pd.Series(np.log(both["query_s_b"] / both["query_s_a"]), index=both.index)
    grouped = logs.groupby(both["engine"])
    return pd.DataFrame({"cases": grouped.size(), "geomean_ratio": np.exp(grouped.mean())}
                        ).reset_index()


def _versions(info: RunInfo) -> dict[str, str]:
    return {str(e["name"]): str(e["version"]) for e in info.engines}


MACHINE_KEYS = ("cpu", "cores", "python", "implementation", "platform", "packages")
"""What must match for two runs' timings to be comparable (pyperf's compare checks the same)."""


def machine_differences(a: RunInfo, b: RunInfo) -> list[str]:
    """How the two runs' machines differ, one line per key (empty: the same machine).

    >>> from crosscheck.core.options import RunOptions
    >>> run = RunInfo("r", "c", RunOptions(), {"cpu": "x", "cores": 2}, (), "t")
    >>> machine_differences(run, run)
    []
    >>> machine_differences(run, RunInfo("s", "c", RunOptions(), {"cpu": "y", "cores": 2}, (), "t"))
    ["cpu: 'x' vs 'y'"]
    """
    return [f"{key}: {a.machine.get(key)!r} vs {b.machine.get(key)!r}" for key in MACHINE_KEYS
            if a.machine.get(key) != b.machine.get(key)]


@dataclass(frozen=True)
class Comparison:
    """What :func:`compare` found and wrote."""

    verdict_changes: int
    timing_changes: int
    machine_differences: list[str]
    out: Path


def compare(dir_a: Path, dir_b: Path, out: Path) -> Comparison:
    """Compare two runs, write verdict_changes.csv, timing_changes.csv and compare.html.

    Timing changes are judged only after the machines are compared: when they
    differ, the result and the page say so first.
    """
    run_a, run_b = read_run(dir_a), read_run(dir_b)
    a, b = run_a.results, run_b.results
    machines = machine_differences(run_a.info, run_b.info)
    verdicts, timings, ratios = verdict_changes(a, b), timing_changes(a, b), engine_ratios(a, b)
    out.mkdir(parents=True, exist_ok=True)
    verdicts.to_csv(out / "verdict_changes.csv", index=False)
    timings.to_csv(out / "timing_changes.csv", index=False)
    va, vb = _versions(run_a.info), _versions(run_b.info)
    versions = [{"engine": name, "a": va.get(name, "-"), "b": vb.get(name, "-")}
                for name in dict.fromkeys([*va, *vb])]
    html = templates().get_template("compare.html.j2").render(
        a=str(dir_a), b=str(dir_b), verdicts=verdicts.to_dict("records"),
        timings=timings.to_dict("records"), ratios=ratios.to_dict("records"),
        versions=versions, min_ratio=MIN_RATIO, isnan=math.isnan, machines=machines)
    (out / "compare.html").write_text(html, encoding="utf-8")
    return Comparison(len(verdicts), len(timings), machines, out)
