"""Fuzz findings grouped into ready-to-commit case files, and ``findings.csv``.

Every disagree, error, crash or timeout row of a fuzz run is grouped by
engine, kind, quantity, status, category and generator family; each group
beyond the engine's declared tolerance becomes one case file of up to
``per_group`` representatives, written by :mod:`crosscheck.cases.writer`.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, cast

import pandas as pd

from crosscheck.cases.writer import case_block, case_file
from crosscheck.core.model import Status
from crosscheck.core.schema import AnyCase

FINDING_STATUSES = Status.members("breaking")
DRIVER_SLUG = {"relative gap": "gap", "scale": "scale", "offset": "offset", "mass ratio": "ratio"}
CSV_COLUMNS = ("group", "file", "case_id", "engine", "kind", "dim", "quantity", "status",
               "category", "family", "modifiers", "driver", "decade", "driver_value", "value",
               "truth", "error", "tolerance", "reason")
Row = dict[str, Any]


class Provenance(Protocol):
    """Where a generated case comes from (:class:`crosscheck.studies.fuzzgen.Generated` is one)."""

    @property
    def case(self) -> AnyCase: ...
    @property
    def family(self) -> str: ...
    @property
    def parts(self) -> tuple[str, ...]: ...
    @property
    def driver(self) -> str: ...
    @property
    def value(self) -> float: ...
    @property
    def index(self) -> int: ...
    @property
    def decade(self) -> str: ...


@dataclass
class Group:
    """Similar findings: same engine, kind, quantity, status, category and family.

    ``decade`` is left empty: one file spans every magnitude of the driving
    parameter (each finding's decade is in findings.csv).
    """

    engine: str
    kind: str
    quantity: str
    status: str
    category: str
    family: str
    driver: str
    decade: str
    rows: list[Row] = field(default_factory=list)
    """The findings, largest error first, ties by case index."""
    chosen: list[str] = field(default_factory=list)
    """Ids of the cases written in this group's file (at most ``per_group``)."""

    @property
    def slug(self) -> str:
        """File stem, e.g. ``fcl-sphere-normal-disagree-error-near-touching-gap1e-05``."""
        decade = DRIVER_SLUG[self.driver] + self.decade.replace("+", "")
        parts = [self.engine, self.kind.replace("_", "-"), self.quantity, self.status,
                 self.category, self.family, decade]
        return "-".join(p for p in parts if p)


def _text(x: Any) -> str:
    return "" if x is None or (isinstance(x, float) and math.isnan(x)) else str(x)


def _error(row: Row) -> float:
    err = row["error"]
    return -1.0 if err is None or math.isnan(err) else float(err)


def group_findings(frame: pd.DataFrame, meta: Mapping[str, Provenance]) -> list[Group]:
    """Every disagree, error, crash or timeout row of a run, grouped; groups by slug."""
    groups: dict[tuple[str, ...], Group] = {}
    rows = cast(list[Row], frame[frame["status"].isin(FINDING_STATUSES)].to_dict("records"))
    for row in rows:
        gen = meta[row["case_id"]]
        key = (row["engine"], row["kind"], row["quantity"], row["status"],
               _text(row["category"]), gen.family, gen.driver, "")  # decades: findings.csv
        groups.setdefault(key, Group(*key)).rows.append(row)
    for group in groups.values():
        group.rows.sort(key=lambda r: (-_error(r), meta[r["case_id"]].index))
    return sorted(groups.values(), key=lambda g: g.slug)


LISTED_ONLY = frozenset({"tolerance"})
"""Categories listed in findings.csv but given no case file: the engine declared that margin."""


def choose(groups: Sequence[Group], per_group: int) -> dict[str, Group]:
    """Pick up to ``per_group`` cases per group, each case for one group only; case -> group.

    Groups whose disagreements lie within the engine's declared tolerance
    (``LISTED_ONLY``) are listed, not written: they are expected, not findings.

    Smaller groups choose first (they have fewer cases to choose from), then by
    slug; within a group the largest errors come first, ties by case index.
    """
    owner: dict[str, Group] = {}
    for group in sorted(groups, key=lambda g: (len(g.rows), g.slug)):
        if group.category in LISTED_ONLY:
            continue
        for row in group.rows:
            if len(group.chosen) < per_group and row["case_id"] not in owner:
                owner[row["case_id"]] = group
                group.chosen.append(row["case_id"])
    return owner


def finding_text(row: Row, full: bool = True) -> str:
    """A finding in words: engine, quantity, value vs truth, category (or status and reason)."""
    head, disagree = f"{row['engine']} {row['quantity']}", row["status"] == "disagree"
    if not full:
        return f"{head} ({row['category'] if disagree else row['status']})"
    if disagree:
        return (f"{head} {row['value']} vs truth {row['truth']} "
                f"({row['category']}, error {row['error']:.3g})")
    return f"{head} {row['status']}: {_text(row['reason'])[:100]}"


def _header(group: Group, command: str) -> str:
    category = f", category {group.category}" if group.category else ""
    return (f"Fuzz findings, group {group.slug}:\n"
            f"engine {group.engine}, kind {group.kind}, quantity {group.quantity}, "
            f"status {group.status}{category},\n"
            f"family {group.family} (driving parameter: {group.driver}).\n"
            f"Findings in this group: {len(group.rows)}; representative cases here: "
            f"{len(group.chosen)}\n(largest errors first, ties by index; "
            f"a case of several groups is written once only).\n"
            f"Found by: {command}")


def _description(gen: Provenance, group: Group, rows: list[Row]) -> str:
    """The generator's description, then every finding of the case (this group's first)."""
    mine = {id(r) for r in group.rows}
    own = "; ".join(finding_text(r) for r in rows if id(r) in mine)
    more = ", ".join(finding_text(r, full=False) for r in rows if id(r) not in mine)
    return f"{gen.case.description}. Found: {own}" + (f"; also {more}" if more else "")


def write_findings(directory: Path, meta: Mapping[str, Provenance], frame: pd.DataFrame,
                   command: str, per_group: int) -> list[Group]:
    """Write one case file per group that has cases of its own, and ``findings.csv``."""
    groups = group_findings(frame, meta)
    owner = choose(groups, per_group)
    rows = sorted((r for g in groups for r in g.rows),
                  key=lambda r: (meta[r["case_id"]].index, r["engine"], r["quantity"]))
    by_case: dict[str, list[Row]] = {}
    for row in rows:
        by_case.setdefault(row["case_id"], []).append(row)
    for group in groups:
        if group.chosen:
            blocks = [case_block(meta[cid].case,
                                 description=_description(meta[cid], group, by_case[cid]))
                      for cid in group.chosen]
            text = case_file(blocks, _header(group, command))
            (directory / f"{group.slug}.toml").write_text(text, encoding="utf-8")
    group_of = {id(r): g for g in groups for r in g.rows}
    _write_csv(directory / "findings.csv", [(group_of[id(r)], r) for r in rows], meta, owner)
    return groups


def _write_csv(path: Path, rows: list[tuple[Group, Row]], meta: Mapping[str, Provenance],
               owner: Mapping[str, Group]) -> None:
    with path.open("w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(CSV_COLUMNS)
        for group, row in rows:
            gen, where = meta[row["case_id"]], owner.get(row["case_id"])
            extra = {"group": group.slug, "file": f"{where.slug}.toml" if where else "",
                     "family": gen.family, "modifiers": " ".join(gen.parts[1:]),
                     "driver": gen.driver, "decade": gen.decade,
                     "driver_value": repr(gen.value), "category": _text(row["category"]),
                     "reason": _text(row["reason"])}
            writer.writerow([extra.get(c, row.get(c)) for c in CSV_COLUMNS])
