"""Fuzz findings grouped into ready-to-commit case files, and ``findings.csv``, in bounded memory.

Every disagree, error, crash or timeout row of a fuzz run is grouped by
engine, kind, quantity, status, category and generator family; each group
beyond the engine's declared tolerance becomes one case file of up to
``per_group`` representatives, written by :mod:`crosscheck.cases.writer`.

A million-case campaign has millions of findings, so nothing here holds them
all: :class:`Groups` counts each group's findings as they stream in and keeps
only its :data:`KEEP` largest errors (the candidates a file can choose from);
:func:`write_stream` reads the findings twice from their source (once to group
and choose, once to write ``findings.csv`` in case order and to collect the
chosen cases' findings), so memory stays flat however many there are.  A
finding row (:func:`finding_row`) is the record's fields plus where its case
came from (family, modifiers, driver, its value and decade, the case index).
"""

from __future__ import annotations

import csv
import heapq
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, cast

import pandas as pd

from crosscheck.cases.writer import case_block, case_file
from crosscheck.core.model import Record, Status
from crosscheck.core.schema import AnyCase

DRIVER_SLUG = {"relative gap": "gap", "scale": "scale", "offset": "offset", "mass ratio": "ratio"}
CSV_COLUMNS = ("group", "file", "case_id", "engine", "kind", "dim", "quantity", "status",
               "category", "family", "modifiers", "driver", "decade", "driver_value", "value",
               "truth", "error", "tolerance", "reason")
FINDING_COLUMNS = (*CSV_COLUMNS[2:], "index")
"""A finding row's fields, in this order when stored as a list (see :func:`as_list`)."""
RECORD_FIELDS = ("case_id", "engine", "kind", "dim", "quantity", "status", "category", "value",
                 "truth", "error", "tolerance", "reason")
"""The fields of a record that a finding keeps."""
KEEP_GROUPS = 100
"""Each group keeps ``per_group * KEEP_GROUPS`` candidates.  A group loses at most
``per_group`` cases to each other group (a case goes to one file only), so the choice
equals the one made from every finding as long as there are at most this many groups
(the seven engine variants on spheres make about 40)."""
Row = dict[str, Any]
Key = tuple[str, str, str, str, str, str, str, str]
"""engine, kind, quantity, status, category, family, driver, decade ("": all decades)."""


class Provenance(Protocol):
    """Where a generated case comes from (a :class:`~crosscheck.studies.fuzz.generator.Generated`
    is one)."""

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


@dataclass(frozen=True)
class Signature:
    """How a finding fails: its record's quantity, status and category (``""``: none).  A
    shrunk case fails *the same way* when its record has the same signature."""

    quantity: str
    status: str
    category: str

    @classmethod
    def of(cls, row: Mapping[str, Any]) -> Signature:
        """The signature of a finding row (or a record's row)."""
        return cls(str(row["quantity"]), str(row["status"]), _text(row["category"]))

    def matches(self, record: Record) -> bool:
        return (record.quantity, str(record.status), _text(record.category)) == (
            self.quantity, self.status, self.category)


def finding_row(record: Mapping[str, Any], gen: Provenance) -> Row:
    """A record's row (``Record.row()`` or a results row) with its case's provenance."""
    row = {name: record[name] for name in RECORD_FIELDS}
    row["category"] = _text(row["category"])
    row["reason"] = _text(row["reason"])
    return row | {"index": gen.index, "family": gen.family, "modifiers": " ".join(gen.parts[1:]),
                  "driver": gen.driver, "driver_value": gen.value, "decade": gen.decade}


def as_list(row: Row) -> list[Any]:
    """A finding row as a list in :data:`FINDING_COLUMNS` order (compact to store)."""
    return [row[c] for c in FINDING_COLUMNS]


def from_list(values: Sequence[Any]) -> Row:
    """A finding row stored by :func:`as_list`."""
    return dict(zip(FINDING_COLUMNS, values, strict=True))


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
    """The candidates: the group's largest errors (at most ``per_group * KEEP_GROUPS``),
    largest first, ties by case index."""
    count: int = 0
    """How many findings the group has (``rows`` keeps the candidates only)."""
    chosen: list[str] = field(default_factory=list)
    """Ids of the cases written in this group's file (at most ``per_group``)."""
    shrunk: list[str] = field(default_factory=list)
    """Ids of the shrunk cases written in this group's file, each just before its original."""

    @property
    def key(self) -> Key:
        """What its findings share (the grouping key)."""
        return (self.engine, self.kind, self.quantity, self.status, self.category,
                self.family, self.driver, self.decade)

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


def _key(row: Row) -> Key:
    return (row["engine"], row["kind"], row["quantity"], row["status"], row["category"],
            row["family"], row["driver"], "")  # decades: findings.csv


def by_severity(groups: Iterable[Group]) -> list[Group]:
    """The groups as a reader wants them: crash, timeout and error first (worst status
    first), then the groups that wrote a case file, then the rest; within each, the most
    findings first, ties by slug.

    >>> made = [Group("e", "sphere", "distance", status, "", "f", "scale", "", count=n,
    ...               chosen=chosen) for status, n, chosen in [
    ...     ("disagree", 90, []), ("disagree", 3, ["c1"]), ("crash", 1, ["c2"]),
    ...     ("error", 5, [])]]
    >>> [(g.status, g.count) for g in by_severity(made)]
    [('crash', 1), ('error', 5), ('disagree', 3), ('disagree', 90)]
    """
    def rank(group: Group) -> tuple[int, int, int, str]:
        failed = Status(group.status).failed
        return (0 if failed else 1 if group.chosen else 2,
                Status(group.status).severity if failed else 0, -group.count, group.slug)
    return sorted(groups, key=rank)


class Groups:
    """Findings grouped as they stream in: a count and the top candidates per group."""

    def __init__(self, per_group: int) -> None:
        self.keep = per_group * KEEP_GROUPS
        self._groups: dict[Key, Group] = {}
        self._heaps: dict[Key, list[tuple[float, int, int, Row]]] = {}
        self._seen = 0

    def add(self, row: Row) -> None:
        """Count ``row`` in its group; keep it if it is among the group's largest errors."""
        key = _key(row)
        group = self._groups.get(key)
        if group is None:
            group = self._groups[key] = Group(*key)
            self._heaps[key] = []
        group.count += 1
        self._seen += 1
        heap = self._heaps[key]  # a min-heap: its root is the weakest candidate
        item = (_error(row), -int(row["index"]), self._seen, row)
        if len(heap) < self.keep:
            heapq.heappush(heap, item)
        elif item[:2] > heap[0][:2]:
            heapq.heapreplace(heap, item)

    def result(self) -> list[Group]:
        """The groups by slug, each with its candidates largest error first, ties by index."""
        for key, group in self._groups.items():
            best = sorted(self._heaps[key], key=lambda item: (-item[0], -item[1]))
            group.rows = [item[3] for item in best]
        return sorted(self._groups.values(), key=lambda g: g.slug)


def group_findings(frame: pd.DataFrame, meta: Mapping[str, Provenance],
                   per_group: int = 5) -> list[Group]:
    """Every disagree, error, crash or timeout row of a run, grouped; groups by slug."""
    groups = Groups(per_group)
    for row in _frame_rows(frame, meta):
        groups.add(row)
    return groups.result()


def _frame_rows(frame: pd.DataFrame, meta: Mapping[str, Provenance]) -> list[Row]:
    rows = cast(list[Row], frame[frame["status"].isin(Status.members("breaking"))]
                .to_dict("records"))
    return [finding_row(row, meta[row["case_id"]]) for row in rows]


SHRUNK_SUFFIX = "-shrunk"
"""A shrunk case's id is its original's with this suffix."""
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
    for group in sorted(groups, key=lambda g: (g.count, g.slug)):
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
            f"Findings in this group: {group.count}; representative cases here: "
            f"{len(group.chosen)}\n(largest errors first, ties by index; "
            f"a case of several groups is written once only).\n"
            + (f"Shrunk cases here: {len(group.shrunk)} (id ending {SHRUNK_SUFFIX}, each "
               f"just before its original:\nthe simplest case found that fails the same "
               f"way; its description gives both findings).\n" if group.shrunk else "")
            + f"Found by: {command}")


def _description(case: AnyCase, group: Group, rows: list[Row]) -> str:
    """The generator's description, then every finding of the case (this group's first)."""
    own = "; ".join(finding_text(r) for r in rows if _key(r) == group.key)
    more = ", ".join(finding_text(r, full=False) for r in rows if _key(r) != group.key)
    return f"{case.description}. Found: {own}" + (f"; also {more}" if more else "")


Batches = Callable[[], Iterable[list[Row]]]
"""Gives the finding rows again each time it is called, in batches in case order."""
Shrinker = Callable[[Sequence[tuple[Group, AnyCase, Row]]], Mapping[str, tuple[AnyCase, str]]]
"""Given findings to shrink (the group, the case, its finding row in that group), gives the
shrunk case and its description by the original case's id, for those it could shrink
(:func:`crosscheck.studies.fuzz.campaign.shrinker`)."""


def write_findings(directory: Path, meta: Mapping[str, Provenance], frame: pd.DataFrame,
                   command: str, per_group: int) -> list[Group]:
    """:func:`write_stream` of the findings of one results table held in memory."""
    rows = _frame_rows(frame, meta)
    return write_stream(directory, lambda: [rows], lambda ids: {i: meta[i].case for i in ids},
                        command, per_group)


def write_stream(directory: Path, batches: Batches,
                 cases: Callable[[set[str]], Mapping[str, AnyCase]], command: str,
                 per_group: int, shrink: Shrinker | None = None,
                 shrink_per_group: int = 0) -> list[Group]:
    """Write one case file per group that has cases of its own, and ``findings.csv``.

    ``batches`` is read twice; ``cases(ids)`` gives the chosen cases.  With ``shrink``, the
    first ``shrink_per_group`` representatives of each group are shrunk, and each shrunk
    case is written just before its original.
    """
    streamed = Groups(per_group)
    for batch in batches():
        for row in batch:
            streamed.add(row)
    groups = streamed.result()
    owner = choose(groups, per_group)
    by_case = _write_csv(directory / "findings.csv", batches(), owner)
    chosen = cases(set(owner))
    shrunk = shrink([(g, chosen[cid], _own(g, by_case[cid])) for g in groups
                     for cid in g.chosen[:shrink_per_group]]) if shrink else {}
    for group in groups:
        if group.chosen:
            blocks = []
            for cid in group.chosen:
                if cid in shrunk:
                    small, words = shrunk[cid]
                    group.shrunk.append(small.id)
                    blocks.append(case_block(small, description=words))
                blocks.append(case_block(chosen[cid], description=_description(
                    chosen[cid], group, by_case[cid])))
            text = case_file(blocks, _header(group, command))
            (directory / f"{group.slug}.toml").write_text(text, encoding="utf-8")
    return groups


def _own(group: Group, rows: list[Row]) -> Row:
    """The finding of ``group`` among a case's findings."""
    return next(row for row in rows if _key(row) == group.key)


def _order(row: Row) -> tuple[int, str, str]:
    return int(row["index"]), row["engine"], row["quantity"]


def _write_csv(path: Path, batches: Iterable[list[Row]],
               owner: Mapping[str, Group]) -> dict[str, list[Row]]:
    """Write every finding in case order; return the findings of the chosen cases."""
    by_case: dict[str, list[Row]] = {}
    slugs: dict[Key, str] = {}
    with path.open("w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(CSV_COLUMNS)
        for batch in batches:
            for row in sorted(batch, key=_order):
                where = owner.get(row["case_id"])
                if where is not None:
                    by_case.setdefault(row["case_id"], []).append(row)
                key = _key(row)
                slug = slugs.get(key) or slugs.setdefault(key, Group(*key).slug)
                writer.writerow([slug, f"{where.slug}.toml" if where else "",
                                 *(row[c] for c in CSV_COLUMNS[2:13]), repr(row["driver_value"]),
                                 *(row[c] for c in CSV_COLUMNS[14:])])
    return by_case
