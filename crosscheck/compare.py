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
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from jinja2 import Environment, PackageLoader, select_autoescape

from crosscheck.store import read_results, read_run_info

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


def _versions(info: dict[str, Any]) -> dict[str, str]:
    return {e["name"]: str(e["version"]) for e in info.get("engines", [])}


def compare(dir_a: Path, dir_b: Path, out: Path) -> dict[str, Any]:
    """Compare two runs, write verdict_changes.csv, timing_changes.csv and compare.html."""
    a, b = read_results(dir_a), read_results(dir_b)
    info_a, info_b = read_run_info(dir_a), read_run_info(dir_b)
    verdicts, timings, ratios = verdict_changes(a, b), timing_changes(a, b), engine_ratios(a, b)
    out.mkdir(parents=True, exist_ok=True)
    verdicts.to_csv(out / "verdict_changes.csv", index=False)
    timings.to_csv(out / "timing_changes.csv", index=False)
    versions = [{"engine": name, "a": _versions(info_a).get(name, "-"),
                 "b": _versions(info_b).get(name, "-")}
                for name in dict.fromkeys([*_versions(info_a), *_versions(info_b)])]
    env = Environment(loader=PackageLoader("crosscheck", "templates"),
                      autoescape=select_autoescape(default=True, default_for_string=True))
    html = env.get_template("compare.html.j2").render(
        a=str(dir_a), b=str(dir_b), verdicts=verdicts.to_dict("records"),
        timings=timings.to_dict("records"), ratios=ratios.to_dict("records"),
        versions=versions, min_ratio=MIN_RATIO, isnan=math.isnan)
    (out / "compare.html").write_text(html, encoding="utf-8")
    return {"verdict_changes": len(verdicts), "timing_changes": len(timings), "out": out}
