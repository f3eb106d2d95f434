"""The report's coverage section: heat maps of the configuration space, one per kind (and
dimension) and dimension pair, cells coloured by the chosen engine's worst label (its worst
status, and for a ``disagree`` its category).

Everything is decided here, from the coverage table (:mod:`crosscheck.report.coverage`); the
page only draws it.  Each space's grids come most informative first: the strong pairs
(``direction x gap``, then ``direction x size_ratio`` and ``gap x size_ratio``), the 3-way
cells of ``direction x gap x size_ratio`` as one ``direction x gap`` grid per size ratio,
then every other pair.  A grid is packed compactly: per engine, one character per cell for
its label (:data:`EMPTY`: no case; :data:`NO_ROW`: no row of the engine; :data:`NO_CELL`:
no such cell, an offset axis at offset 0; else the label's rank in
:data:`~crosscheck.report.coverage.LABELS`) and one for its largest error's decade
(:func:`error_labels`); the colours and words of every code are in the data too.

The same section is the whole of a standalone page, ``coverage.html``
(:func:`page_html`), which ``crosscheck coverage`` writes for a fuzz campaign (it has no
report) and for a run.
"""

from __future__ import annotations

import functools
import json
import math
import string
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from markupsafe import Markup

from crosscheck.cases.space import space_of
from crosscheck.core.model import Category, Kind, Status
from crosscheck.report.coverage import (
    CELL_COLUMNS,
    LABELS,
    CoverageMap,
    by_space,
    covered,
    label_ranks,
)
from crosscheck.report.speed_points import CEILING, FLOOR
from crosscheck.report.style import packed, templates

PAGE = "coverage.html"
"""The coverage page ``crosscheck coverage`` writes beside ``coverage.csv``."""
EMPTY, NO_ROW, NO_CELL = ".", "-", "x"
"""Label codes of a cell that holds no case, that the engine has no row in, that does not exist."""
CODES = string.digits + string.ascii_letters
"""The characters of the codes: a label's by its rank in
:data:`~crosscheck.report.coverage.LABELS`, an error's in the order of :func:`error_labels`."""
INK = "#222"
"""The colour of a cell's number (on a light cell)."""
EMPTY_COLOUR = "repeating-linear-gradient(45deg, #fff 0 3px, #c8c8c8 3px 5px)"
"""An empty cell is hatched (its background; the legend shows the same)."""


FAILED_COLOURS = {Status.CRASH: ("#7a2a04", "#fff"), Status.TIMEOUT: ("#b8510b", "#fff"),
                  Status.ERROR: ("#f39c34", INK)}
"""The failed statuses from dark (crash) to light (error), each with its text colour."""
DISAGREE_COLOURS = {Category.ERROR: "#e06666", Category.TIMESTEP: "#f3a9b9",
                    Category.CONVENTION: "#f5d77a", Category.TOLERANCE: "#b9d5ee"}
"""A disagree by category: red when unexplained (``error``), soft pink, yellow and blue when
explained by a time step, a declared convention or the engine's declared tolerance."""
CATEGORY_WORDS = {Category.ERROR: "unexplained", Category.TIMESTEP: "a time step's lag",
                  Category.CONVENTION: "a declared convention",
                  Category.TOLERANCE: "within the engine's declared tolerance"}


def colours(status: Status, category: Category | None = None) -> tuple[str, str]:
    """A label's colour in the heat map and the colour of a cell's number on it: green
    agrees, red disagrees unexplained (softer when the category explains it), orange to dark
    brown failed, lavender undefined, grey skipped."""
    if status.failed:
        return FAILED_COLOURS[status]
    if status.breaking:
        return DISAGREE_COLOURS[category or Category.ERROR], INK
    if status is Status.UNDEFINED:
        return "#c9c3e6", INK
    if status.neutral:
        return "#dcdcdc", INK
    return "#8fce8a", INK


def words(status: Status, category: Category | None = None) -> str:
    """A label in words: its status, and a disagree's category with what it means."""
    return f"{status}, {category} ({CATEGORY_WORDS[category]})" if category else str(status)


def legend() -> list[dict[str, str]]:
    """Every label code of a grid: its character, words and colour, most severe first."""
    labels = [{"code": CODES[rank], "label": words(*label), "colour": colours(*label)[0],
               "ink": colours(*label)[1]} for rank, label in enumerate(LABELS)]
    return [*labels,
            {"code": EMPTY, "label": "no case in this cell", "colour": EMPTY_COLOUR,
             "ink": INK},
            {"code": NO_ROW, "label": "no row of this engine (a run stopped early)",
             "colour": "#ffffff", "ink": INK},
            {"code": NO_CELL, "label": "no such cell (an offset axis needs an offset)",
             "colour": "#f7f7f7", "ink": INK}]


def error_labels() -> list[str]:
    """The words of each error code: none stored, 0, below the chart's floor, each decade up
    to its ceiling (in units of the float64 bound), then off scale."""
    low, high = round(math.log10(FLOOR)), round(math.log10(CEILING))
    return ["", "error 0", f"error below 1e{low} bounds",
            *(f"error 1e{k} to 1e{k + 1} bounds" for k in range(low, high)),
            f"error above 1e{high} bounds, or not finite"]


def error_codes(units: np.ndarray) -> np.ndarray:
    """The code of each largest error of ``units`` bounds (NaN: none stored).

    >>> "".join(error_codes(np.array([math.nan, 0.0, 1e-5, 1e-3, 2.5, 1e15, 2e15, math.inf])))
    '01236kll'
    """
    low, high = round(math.log10(FLOOR)), round(math.log10(CEILING))
    with np.errstate(divide="ignore", invalid="ignore"):
        decade = 3 + np.clip(np.floor(np.log10(units)), low, high - 1) - low
    index = np.select([np.isnan(units), units == 0, units < FLOOR, ~(units <= CEILING)],
                      [0, 1, 2, 3 + high - low], decade)
    codes: np.ndarray = np.array(list(CODES))[index.astype(int)]
    return codes


def grid_plan(kind: Kind, dim: int) -> list[tuple[str, str, str, str]]:
    """The grids of a space, most informative first: (rows, columns, fixed dimension, its
    level); the fixed dimension is ``""`` for a 2-way grid, and the 3-way cells (a space
    with the three strong dimensions) are one grid per level of the third."""
    space = space_of(kind, dim)
    assert space is not None
    names = space.names
    pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1:]]
    strong = [p for p in pairs if p[0] in space.strong and p[1] in space.strong]
    grids = [(a, b, "", "") for a, b in strong[:1]]
    if len(strong) == 3:
        a, b = strong[0]
        third = next(n for n in space.strong if n not in (a, b))
        grids += [(a, b, third, level) for level in space.dimension(third).levels]
    grids += [(a, b, "", "") for a, b in strong[1:]]
    return grids + [(a, b, "", "") for a, b in pairs if (a, b) not in strong]


def _label(rows: str, columns: str, fixed: str, level: str) -> str:
    words = f"{rows} x {columns}".replace("_", " ")
    return f"{words} at {fixed.replace('_', ' ')} {level}" if fixed else words


@dataclass(frozen=True)
class SpaceCodes:
    """One space's cells (one row each, :data:`CELL_COLUMNS`) and per engine the status and
    error code of each."""

    cells: pd.DataFrame
    status: list[np.ndarray]
    error: list[np.ndarray]

    @functools.cached_property
    def grids(self) -> dict[tuple[str, str, str, str], dict[tuple[str, str], int]]:
        """Per grid (its dimensions, its fixed dimension and level): each cell's row by its
        two levels."""
        columns = [self.cells[name] for name in ("dimension_1", "dimension_2", "dimension_3",
                                                 "level_3", "level_1", "level_2")]
        out: dict[tuple[str, str, str, str], dict[tuple[str, str], int]] = {}
        for i, (d1, d2, d3, l3, l1, l2) in enumerate(zip(*columns, strict=True)):
            out.setdefault((d1, d2, d3, l3), {})[l1, l2] = i
        return out


def space_codes(table: pd.DataFrame, engines: Sequence[str]) -> SpaceCodes:
    """The codes of every cell of one space's rows of the coverage table, per engine."""
    wide = table.pivot(index=list(CELL_COLUMNS), columns="engine",
                       values=["worst_status", "worst_category", "max_error_bounds"])
    cells = wide.index.to_frame(index=False)
    held = cells["cases"].to_numpy() > 0
    label = np.array([*CODES[:len(LABELS)], NO_ROW])  # past the end: no row of the engine
    ranks = [label_ranks(wide["worst_status", e].fillna(""), wide["worst_category", e])
             .fillna(len(LABELS)).to_numpy(dtype=np.int64) for e in engines]
    status = [np.where(held, label[rank], EMPTY) for rank in ranks]
    error = [error_codes(wide["max_error_bounds", e].to_numpy(dtype=float)) for e in engines]
    return SpaceCodes(cells, status, error)


def _grid(codes: SpaceCodes, kind: Kind, dim: int, plan: tuple[str, str, str, str]
          ) -> dict[str, Any]:
    """One grid's data: its levels, cases per cell (-1: no such cell) and per engine its
    status and error codes, one character a cell, rows first."""
    rows, columns = plan[:2]
    space = space_of(kind, dim)
    assert space is not None
    found = codes.grids.get(plan, {})
    row_levels, column_levels = space.dimension(rows).levels, space.dimension(columns).levels
    where = [found.get((a, b)) for a in row_levels for b in column_levels]
    counts = codes.cells["cases"].to_numpy()

    def text(per_cell: np.ndarray, missing: str) -> str:
        return "".join(missing if i is None else str(per_cell[i]) for i in where)
    return {"label": _label(*plan), "rows": rows.replace("_", " "),
            "columns": columns.replace("_", " "), "row_levels": list(row_levels),
            "column_levels": list(column_levels),
            "cases": [-1 if i is None else int(counts[i]) for i in where],
            "status": [text(per_cell, NO_CELL) for per_cell in codes.status],
            "error": [text(per_cell, CODES[0]) for per_cell in codes.error]}


UNEXPLAINED = tuple(CODES[rank] for rank, (status, category) in enumerate(LABELS)
                    if status.failed or category is Category.ERROR)
"""The codes of a wrong answer nothing declared explains: failed, or disagree of category
``error``."""
EXPLAINED = tuple(CODES[rank] for rank, (_, category) in enumerate(LABELS)
                  if category not in (None, Category.ERROR))
"""The codes of a disagree a declared time step, convention or tolerance explains."""


def _breaking(codes: SpaceCodes, engines: Sequence[str]) -> str:
    """Per engine, the 2-way cells whose worst answer is wrong unexplained, and those whose
    worst is a disagree the engine's declarations explain."""
    two = (codes.cells["dimension_3"] == "").to_numpy()

    def counted(which: tuple[str, ...]) -> str:
        return ", ".join(f"{e} {int((two & np.isin(status, which)).sum())}"
                         for e, status in zip(engines, codes.status, strict=True))
    return (f"2-way cells whose worst answer is wrong and unexplained (crash, timeout, error, "
            f"or disagree of category error): {counted(UNEXPLAINED)}; whose worst is a disagree "
            f"explained (timestep, convention, tolerance): {counted(EXPLAINED)}")


def section(found: CoverageMap, engines: Sequence[str], command: str, source: str = "run",
            opened: bool = False) -> dict[str, Any] | None:
    """The coverage section's context (None: no case of the run has a cell); ``source`` says
    what the cases are (``"run"``, ``"campaign"``), ``opened`` whether its fold is open."""
    table = found.table
    if table.empty or not engines:
        return None
    spaces, data = [], []
    counts = {(s["kind"], s["dim"]): s for s in covered(table)}
    for kind, dim, rows in by_space(table):
        key = (Kind(kind), dim)
        codes = space_codes(rows, engines)
        grids = [_grid(codes, *key, plan) for plan in grid_plan(*key)]
        spaces.append(counts[kind, dim] | {
            "cases": found.cases.get(key, 0), "grids": [g["label"] for g in grids],
            "breaking": _breaking(codes, engines)})
        data.append({"grids": grids})
    payload = {"engines": list(engines), "spaces": data, "legend": legend(),
               "errors": error_labels(), "error_codes": CODES[:len(error_labels())]}
    totals = {key: sum(int(space[key]) for space in spaces)
              for key in ("covered_2", "cells_2", "covered_3", "cells_3")}
    return {"coverage": {"spaces": spaces, "engines": list(engines), "legend": legend(),
                         "command": command, "totals": totals, "source": source,
                         "open": opened,
                         "packed": packed(json.dumps(payload, separators=(",", ":")))}}


def page_html(found: CoverageMap, engines: Sequence[str], command: str, title: str,
              about: str, source: str) -> str:
    """``coverage.html``: the coverage section alone (open) in a self-contained page with the
    report's look and scripts; ``about`` is the line under its title (what was mapped)."""
    context = section(found, engines, command, source, opened=True)
    body = (templates().get_template("_coverage.html.j2").render(**context)
            if context is not None else "")
    return templates().get_template("coverage.html.j2").render(
        title=title, about=about, section=Markup(body))


def write_page(found: CoverageMap, engines: Sequence[str], directory: Path, *, command: str,
               title: str, about: str, source: str) -> Path:
    """Write :func:`page_html` as ``coverage.html`` into ``directory``."""
    path = directory / PAGE
    path.write_text(page_html(found, engines, command, title, about, source), encoding="utf-8")
    return path
