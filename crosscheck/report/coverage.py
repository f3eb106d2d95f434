"""The coverage map: which cells of the configuration space a run (or a fuzz campaign) asked,
and how each engine fared in each.

Every case (bad-input cases left out) is placed in its cell by its geometry
(:func:`crosscheck.cases.space.classify`); the cells are those of
:func:`crosscheck.cases.cover.full_plan` at strength 3 (every pair of levels of every two
dimensions of a kind's space, and every triple of the strong dimensions ``direction x gap x
size_ratio``), for each space (kind, 2-D or 3-D) that holds a case.  Per cell and engine:

- ``worst_status``, ``worst_category``: the worst label (:data:`LABELS`) of the engine's
  rows over the cell's cases: the most severe status
  (:attr:`~crosscheck.core.model.Status.severity`), and among ``disagree`` rows the most
  severe category (:attr:`~crosscheck.core.model.Category.severity`: an unexplained
  ``error`` before ``timestep``, ``convention`` and ``tolerance``); ``worst_case`` the case
  it comes from (among several, the one with the largest error, then the first in case
  order);
- ``max_error_bounds``: the largest error in units of the float64 bound, ``error /
  tolerance`` of the stored rows (:func:`crosscheck.report.speed_points.in_tolerances`: an
  error of 0 counts 0 whatever the tolerance; any other error over a tolerance of 0 or
  none, and an error that is not a number, is infinite), over the scored rows (agree,
  disagree) of the kind's error quantities (a ``hit`` verdict is right or wrong: its status
  says so); empty when no such row was stored.

A fuzz campaign stores only its findings, so :func:`coverage_map` takes ``unlisted``: the
status of a case x engine without a stored row (a campaign's cases without a finding agree);
for a run it is None, and an engine with no row in a cell (a run stopped early) has an
empty ``worst_status`` there.  The page's heat maps are drawn from the same table
(:mod:`crosscheck.report.coverage_page`); ``crosscheck coverage`` writes it as ``coverage.csv``.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from crosscheck.cases.cover import Tuple, full_plan
from crosscheck.cases.space import Cell, Space, space_of
from crosscheck.core.model import Category, Kind, Status
from crosscheck.core.schema import AnyCase
from crosscheck.report.cells import cell_of
from crosscheck.report.speed_points import MEASURES, in_tolerances

CELL_COLUMNS = ("kind", "dim", "dimension_1", "level_1", "dimension_2", "level_2",
                "dimension_3", "level_3", "cases")
"""What names a cell, and how many cases it holds (``dimension_3``, ``level_3``: ``""`` for
a 2-way cell)."""
COLUMNS = (*CELL_COLUMNS, "engine", "worst_status", "worst_category", "worst_case",
           "max_error_bounds")
"""``coverage.csv``: one row per cell x engine."""
FILE = "coverage.csv"
ROW_COLUMNS = ("case_id", "engine", "kind", "quantity", "status", "category", "error",
               "tolerance")
"""What :func:`coverage_map` reads of each stored row (a results row or a fuzz finding)."""

LABELS: tuple[tuple[Status, Category | None], ...] = tuple(
    (status, category) for status in sorted(Status, key=lambda s: s.severity)
    for category in (sorted(Category, key=lambda c: c.severity)
                     if status is Status.DISAGREE else [None]))
"""Every label a cell's worst row can have, most severe first (its index is its rank): the
statuses by severity, ``disagree`` split by category.

>>> [f"{s}/{c}" if c else str(s) for s, c in LABELS][2:8]
['error', 'disagree/error', 'disagree/timestep', 'disagree/convention', 'disagree/tolerance', \
'undefined']
"""
_RANK = {f"{s}/{c}" if c else str(s): rank for rank, (s, c) in enumerate(LABELS)}


def rank_of(status: Status, category: Category | None = None) -> int:
    """The rank (index in :data:`LABELS`) of a status, and of a disagree's category."""
    return _RANK[f"{status}/{category}" if status is Status.DISAGREE and category else
                 str(status)]


def label_ranks(status: pd.Series, category: pd.Series) -> pd.Series:
    """Each row's rank (NaN: not a status); a disagree without a known category ranks as an
    unexplained one (category ``error``).

    >>> label_ranks(pd.Series(["agree", "disagree", "disagree", "crash", "?"]),
    ...             pd.Series(["", "tolerance", "", "", ""])).tolist()
    [9.0, 6.0, 3.0, 0.0, nan]
    """
    status = status.astype(str)
    disagree = (status == str(Status.DISAGREE)).to_numpy()
    key = status.where(~disagree, status + "/" + category.astype(object).fillna("").astype(str))
    ranks = key.map(_RANK)
    return ranks.where(~(disagree & ranks.isna().to_numpy()),
                       rank_of(Status.DISAGREE, Category.ERROR)).astype(float)


@dataclass(frozen=True, slots=True)
class SpaceCells:
    """The cells of one space, in order: 2-way cells by dimension pair (the space's order of
    dimensions, then of levels), then the 3-way ones."""

    space: Space
    cells: tuple[Tuple, ...]
    index: Mapping[Tuple, int]

    @property
    def key(self) -> tuple[Kind, int]:
        return self.space.kind, self.space.dim


@functools.cache
def space_cells(kind: Kind, dim: int) -> SpaceCells:
    """Every cell of the space of ``kind`` in ``dim`` dimensions (it must have one)."""
    space = space_of(kind, dim)
    assert space is not None, f"{kind} in {dim}-D has no configuration space"
    cells = tuple(sorted(full_plan(space, 3).tuples(), key=lambda t: _rank(space, t)))
    return SpaceCells(space, cells, {t: i for i, t in enumerate(cells)})


def _rank(space: Space, cell: Tuple) -> tuple[int, tuple[int, ...], tuple[int, ...]]:
    names = space.names
    return (len(cell), tuple(names.index(n) for n, _ in cell),
            tuple(space.dimension(n).levels.index(v) for n, v in cell))


def cells_of(cell: Cell, cells: SpaceCells) -> list[int]:
    """The indices (in ``cells``) of the cells a case at ``cell`` lies in."""
    names = [n for n in cells.space.names if n in cell]
    found = []
    for size, pool in ((2, names), (3, [n for n in names if n in cells.space.strong])):
        for combo in itertools.combinations(pool, size):
            i = cells.index.get(tuple((n, cell[n]) for n in combo))
            if i is not None:
                found.append(i)
    return found


@dataclass(frozen=True)
class Placement:
    """Cases placed in their cells: the spaces they reach (in order), and one row per case x
    cell (``cell``: the cell's index over every reached space, in order; ``order``: the
    case's position)."""

    spaces: tuple[SpaceCells, ...]
    members: pd.DataFrame
    cases: Mapping[tuple[Kind, int], int]
    """Placed cases per space."""

    @property
    def cells(self) -> list[tuple[SpaceCells, Tuple]]:
        return [(s, t) for s in self.spaces for t in s.cells]


def place(cases: Iterable[AnyCase]) -> Placement:
    """Place each case (read once, so it may be a stream) in its cells; bad-input cases and
    kinds without a space (scenes) are left out."""
    found: dict[tuple[Kind, int], list[tuple[str, int, list[int]]]] = {}
    for order, case in enumerate(cases):
        if case.bad_input or space_of(case.kind_enum, case.dim) is None:
            continue
        cells = space_cells(case.kind_enum, case.dim)
        found.setdefault(cells.key, []).append((case.id, order, cells_of(cell_of(case), cells)))
    spaces = tuple(space_cells(*key) for key in sorted(found, key=_space_order))
    parts, offset = [], 0
    for cells in spaces:
        placed = found[cells.key]
        counts = [len(where) for _, _, where in placed]
        cell = [offset + i for _, _, where in placed for i in where]
        parts.append(pd.DataFrame({
            "cell": np.asarray(cell, dtype=np.int64),
            "case_id": np.repeat(np.asarray([cid for cid, _, _ in placed], dtype=object), counts),
            "order": np.repeat([order for _, order, _ in placed], counts).astype(np.int64)}))
        offset += len(cells.cells)
    members = (pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(
        {"cell": np.zeros(0, np.int64), "case_id": np.zeros(0, object),
         "order": np.zeros(0, np.int64)}))
    return Placement(spaces, members, {key: len(v) for key, v in found.items()})


def _space_order(key: tuple[Kind, int]) -> tuple[int, int]:
    """Kinds in their enum's order, 3-D before 2-D (as ``crosscheck validate`` lists them)."""
    return list(Kind).index(key[0]), -key[1]


def case_outcomes(rows: pd.DataFrame) -> pd.DataFrame:
    """Per case x engine: its worst label's rank (``rank``, :data:`LABELS`) and its largest
    error in units of the bound (``units``; NaN without a scored row of an error quantity)."""
    rows = rows.reindex(columns=list(ROW_COLUMNS))
    ranks = label_ranks(rows["status"], rows["category"])
    measured = [f"{kind}/{quantity}" for kind, m in MEASURES.items() for quantity in m.errors]
    errors = (rows["status"].isin(Status.members("scored"))
              & (rows["kind"].astype(str) + "/" + rows["quantity"].astype(str)).isin(measured))
    units = pd.Series(np.nan, index=rows.index)
    if errors.any():
        units[errors] = in_tolerances(rows[errors])
    frame = pd.DataFrame({"case_id": rows["case_id"].astype(str).astype(object),
                          "engine": rows["engine"].astype(str).astype("category"),
                          "rank": ranks, "units": units})
    frame = frame[frame["rank"].notna()]
    return frame.groupby(["case_id", "engine"], as_index=False, sort=False, observed=True).agg(
        rank=("rank", "min"), units=("units", "max"))


@dataclass(frozen=True)
class CoverageMap:
    """The coverage table (``coverage.csv``) and the cases placed per space."""

    table: pd.DataFrame
    cases: Mapping[tuple[Kind, int], int]


def coverage_map(cases: Iterable[AnyCase], rows: pd.DataFrame, engines: Sequence[str],
                 unlisted: Status | None = None) -> CoverageMap:
    """Each cell of every space ``cases`` reach, per engine: its cases, the engine's worst
    label and largest error in bounds over ``rows`` (stored rows: results, or a fuzz
    campaign's findings); a case x engine without a row counts as ``unlisted`` (None: it
    does not count)."""
    placement = place(cases)
    cells = _cells_frame(placement.cells, placement.members)
    grid = pd.MultiIndex.from_product([range(len(cells)), list(engines)],
                                      names=["cell", "engine"]).to_frame(index=False)
    stats = _worst(placement.members, case_outcomes(rows))
    out = grid.join(stats, on=["cell", "engine"]).join(cells, on="cell")
    if unlisted is not None:
        out = _with_unlisted(out, unlisted)
    label = out["rank"].fillna(len(LABELS)).to_numpy(dtype=np.int64)  # past the end: none
    out["worst_status"] = np.array([*(str(s) for s, _ in LABELS), ""], dtype=object)[label]
    out["worst_category"] = np.array([*(str(c or "") for _, c in LABELS), ""],
                                     dtype=object)[label]
    out["worst_case"] = out["case_id"].fillna("").astype(str)
    out["max_error_bounds"] = out["units"].astype(float)
    table = out.loc[:, list(COLUMNS)].astype({"dim": "int64", "cases": "int64"})
    return CoverageMap(table, placement.cases)


def _worst(members: pd.DataFrame, outcomes: pd.DataFrame) -> pd.DataFrame:
    """Per cell x engine with a row: the worst label's rank (``rank``) and the case it
    comes from (the largest error among those, then the first), the largest error
    (``units``) and how many of the cell's cases have a row (``listed``)."""
    joined = members.merge(outcomes, on="case_id")
    worst = (joined.assign(larger=-joined["units"].fillna(-1.0))
             .sort_values(["cell", "engine", "rank", "larger", "order"], kind="stable")
             .drop_duplicates(["cell", "engine"]).set_index(["cell", "engine"]))
    grouped = joined.groupby(["cell", "engine"], observed=True)
    return worst[["rank", "case_id"]].join(grouped["units"].max()).join(
        grouped.size().rename("listed"))


def _with_unlisted(out: pd.DataFrame, unlisted: Status) -> pd.DataFrame:
    """Cells where some case has no row of the engine take ``unlisted`` when it is more
    severe than what the rows say (then no one case is named)."""
    missing = out["listed"].fillna(0) < out["cases"]
    takes = missing & ~(out["rank"] <= rank_of(unlisted))
    out.loc[takes, "rank"] = rank_of(unlisted)
    out.loc[takes, "case_id"] = ""
    return out


def _cells_frame(cells: Sequence[tuple[SpaceCells, Tuple]], members: pd.DataFrame
                 ) -> pd.DataFrame:
    """One row per cell: its kind, dimension, dimensions and levels, and its case count."""
    def named(cell: Tuple) -> list[str]:
        items = [*cell, *[("", "")] * (3 - len(cell))]
        return [x for item in items for x in item]
    names = list(CELL_COLUMNS[2:-1])
    frame = pd.DataFrame([[s.space.kind.value, s.space.dim, *named(t)] for s, t in cells],
                         columns=["kind", "dim", *names])
    frame["cases"] = members.groupby("cell").size().reindex(range(len(cells)), fill_value=0
                                                            ).to_numpy() if len(cells) else []
    return frame


def empty_cells(table: pd.DataFrame) -> pd.DataFrame:
    """The cells without a case, once each (the engine columns dropped)."""
    empty = table[table["cases"] == 0]
    return empty.loc[:, list(CELL_COLUMNS)].drop_duplicates().reset_index(drop=True)


def write(found: CoverageMap, directory: Path) -> Path:
    """``coverage.csv`` in ``directory`` (empty fields: no value; ``inf``: an infinite error)."""
    path = directory / FILE
    found.table.to_csv(path, index=False)
    return path


def by_space(table: pd.DataFrame) -> Iterator[tuple[str, int, pd.DataFrame]]:
    """The rows of each space (kind, dimension) of a coverage table, in its order."""
    keys = table[["kind", "dim"]].drop_duplicates()
    for kind, dim in zip(keys["kind"], keys["dim"], strict=True):
        yield str(kind), int(dim), table[(table["kind"] == kind) & (table["dim"] == dim)]


def covered(table: pd.DataFrame) -> list[dict[str, Any]]:
    """Per space in the table: its 2-way and 3-way cells, and those holding a case."""
    out = []
    for kind, dim, rows in by_space(table.drop_duplicates(list(CELL_COLUMNS[:-1]))):
        three, held = rows["dimension_3"] != "", rows["cases"] > 0
        out.append({"kind": kind, "dim": dim,
                    "cells_2": int((~three).sum()), "covered_2": int((~three & held).sum()),
                    "cells_3": int(three.sum()), "covered_3": int((three & held).sum())})
    return out


def run_map(cases: Mapping[str, AnyCase], frame: pd.DataFrame, engines: Sequence[str]
            ) -> CoverageMap:
    """The coverage map of a stored run: its cases, its rows, its engines."""
    return coverage_map(cases.values(), frame, engines)


def campaign_map(cases: Iterable[AnyCase], findings: pd.DataFrame, engines: Sequence[str]
                 ) -> CoverageMap:
    """The coverage map of a fuzz campaign: its regenerated cases and its finding rows; a case
    x engine without a finding agrees (a campaign stores findings only)."""
    return coverage_map(cases, findings, engines, unlisted=Status.AGREE)
