"""The report's tables: per engine x kind, per engine x case group, the disagreements.

Each is a plain DataFrame (written as CSV beside the report) or the dicts a
section template shows.
"""

from __future__ import annotations

from pathlib import PurePosixPath
from typing import Any

import pandas as pd

from crosscheck.core.kinds import error_columns
from crosscheck.core.model import Category, Status
from crosscheck.report.cost import cost_of
from crosscheck.report.frames import records

STATUSES = [str(s) for s in Status]


def _times(frame: pd.DataFrame) -> pd.DataFrame:
    """Per engine x kind: the median of the per-case query times, their IQR over the timed
    cases, and how many cases were timed and how many of those timings are unstable; then
    the same of the counted instructions per query (NaN and 0 where none was counted), and
    the median of those inside the engine's own code (:func:`crosscheck.report.cost.cost_of`)."""
    per_case = frame.drop_duplicates(["engine", "case_id"])
    rows = {}
    for (engine, kind), group in per_case.groupby(["engine", "kind"]):
        cost = cost_of(group)
        rows[engine, kind] = {
            "median_query_s": cost.wall.median, "iqr_query_s": cost.wall.iqr,
            "timed": cost.wall.n,
            "unstable": int((group["unstable"].isin([True]) & group["query_s"].notna()).sum()),
            "median_query_instructions": cost.counted.median,
            "iqr_query_instructions": cost.counted.iqr, "counted": cost.counted.n,
            "median_engine_instructions": cost.in_engine}
    return pd.DataFrame.from_dict(rows, orient="index").rename_axis(["engine", "kind"])


def _errors(frame: pd.DataFrame) -> pd.DataFrame:
    """Per engine x kind: the share of wrong verdicts and the median error of each measure
    over the scored rows (NaN, shown as "-", where nothing was measured).  The columns are the
    quantities' (:func:`crosscheck.core.kinds.error_columns`): one measure each, never mixed
    (hit 0/1, lengths, radians, velocities and mean radii do not share a scale)."""
    scored = frame[frame["status"].isin(Status.members("scored"))]
    keys = ["engine", "kind"]
    out = pd.DataFrame(index=pd.MultiIndex.from_frame(frame[keys].drop_duplicates()))
    for column, quantities in error_columns().items():
        rows = scored[scored["quantity"].isin(quantities)]
        agg = rows.groupby(keys)["error"].mean() if column == "wrong_verdicts" else (
            rows.groupby(keys)["error"].median())
        out[column] = agg
    return out


def summary(frame: pd.DataFrame) -> pd.DataFrame:
    """Per engine x kind: counts of each status, the share of wrong verdicts and the median
    error of each measure separately, the median query time with its IQR over the timed cases,
    timed and unstable cases, and the median instructions per query with their IQR over the
    counted cases, counted cases, and the median inside the engine."""
    if frame.empty:
        return pd.DataFrame(columns=["engine", "kind", *STATUSES])
    counts = pd.crosstab([frame["engine"], frame["kind"]], frame["status"])
    counts = counts.reindex(columns=STATUSES, fill_value=0)
    out = counts.join(_errors(frame)).join(_times(frame)).reset_index()
    order = {name: i for i, name in enumerate(dict.fromkeys(frame["engine"]))}
    return out.sort_values(["engine", "kind"], key=lambda s: s.map(order).fillna(s.rank()))


def disagreements(frame: pd.DataFrame) -> pd.DataFrame:
    """Every row that is not agree/skip/undefined, most severe first: by status
    (:attr:`Status.severity`), then category (:attr:`Category.severity`; none last), then
    the largest error."""
    bad = frame[frame["status"].isin(Status.members("breaking"))].copy()
    severity = {str(s): s.severity for s in Status}
    category = {str(c): c.severity for c in Category} | {"": len(Category)}
    bad["_s"] = bad["status"].map(severity)
    bad["_c"] = bad["category"].fillna("").map(category)
    bad = bad.sort_values(["_s", "_c", "error"], ascending=[True, True, False])
    return bad.drop(columns=["_s", "_c"])


def case_group(source: str) -> str:
    """The case group of a case file: its stem (``cases/float_traps.toml`` -> ``float_traps``)."""
    return PurePosixPath(source).stem if source else "(no file)"


def case_groups(sources: pd.Series) -> pd.Series:
    """:func:`case_group` of every row's source, each distinct source named once.

    >>> case_groups(pd.Series(["cases/a.toml", None, "cases/a.toml"])).tolist()
    ['a', '(no file)', 'a']
    """
    codes, texts = pd.factorize(sources.fillna(""))
    names = [case_group(str(text)) for text in texts]
    return pd.Series([names[code] for code in codes], index=sources.index, dtype="str",
                     name="group")


def group_counts(frame: pd.DataFrame) -> pd.DataFrame:
    """Per engine x case group: counts of each status (case x quantity rows)."""
    if frame.empty:
        return pd.DataFrame(columns=["engine", "group", *STATUSES])
    groups = case_groups(frame["source"])
    counts = pd.crosstab([frame["engine"], groups], frame["status"])
    return counts.reindex(columns=STATUSES, fill_value=0).reset_index()


def share_colour(share: float | None) -> str:
    """Cell colour: red (0) through yellow to green (1); grey when nothing was judged."""
    return "#e4e4e4" if share is None else f"hsl({120 * share:.0f}, 65%, 78%)"


def _cell(counts: dict[Any, Any]) -> dict[str, Any]:
    scored = sum(counts[s] for s in Status.members("scored"))
    failed = {s: counts[s] for s in Status.members("failed") if counts[s]}
    judged = scored + sum(failed.values())
    share = counts["agree"] / judged if judged else None
    everything = sum(counts[s] for s in STATUSES)
    return {
        "agree": counts["agree"], "scored": scored, "failed": failed, "share": share,
        "colour": share_colour(share), "skipped": everything > 0 and counts["skip"] == everything,
        "undefined": counts["undefined"],
        "title": ", ".join(f"{counts[s]} {s}" for s in STATUSES if counts[s]) or "no rows",
    }


def group_matrix(frame: pd.DataFrame) -> dict[str, Any]:
    """The engines x case groups matrix for the report: column heads and coloured cells."""
    group_of = case_groups(frame["source"])
    groups = list(dict.fromkeys(group_of))
    cases = group_of[~frame["case_id"].duplicated()].value_counts()
    counts = {(r["engine"], r["group"]): r for r in records(group_counts(frame))}
    empty = dict.fromkeys(STATUSES, 0)
    rows = [{"engine": engine, "cells": [_cell(counts.get((engine, g), empty)) for g in groups]}
            for engine in dict.fromkeys(frame["engine"])]
    return {"groups": [{"name": g, "cases": int(cases.get(g, 0))} for g in groups], "rows": rows}


def markdown_summary(frame: pd.DataFrame) -> str:
    """The summary as a Markdown table (counts only), for README excerpts."""
    table = summary(frame)[["engine", "kind", *STATUSES]]
    header = "| " + " | ".join(table.columns) + " |"
    rule = "|" + "---|" * len(table.columns)
    rows = ["| " + " | ".join(str(v) for v in row) + " |" for row in table.itertuples(index=False)]
    return "\n".join([header, rule, *rows])
