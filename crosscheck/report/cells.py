"""Each case's cell of the configuration space, worked out once per case object.

:func:`crosscheck.cases.space.classify` measures a case's numbers on every dimension of its
space; a report asks it for every case of the run in the coverage section and again for the
cases of each standard advise profile (:func:`crosscheck.report.advise.recommend.cells_of`).
:func:`cell_of` answers each case object once and then from memory (a case is frozen, so its
cell cannot change); the memory holds the last :data:`KEPT` cases at most.
"""

from __future__ import annotations

from crosscheck.cases.space import Cell, classify
from crosscheck.core.schema import AnyCase

KEPT = 100_000
"""Cases remembered at most (more than a full suite); past that the memory starts again."""

_CELLS: dict[int, tuple[AnyCase, Cell]] = {}
"""By the case object's id: the case (its id is its identity only while it lives: the entry
keeps it alive and is checked against it) and its cell."""


def cell_of(case: AnyCase) -> Cell:
    """The cell of ``case`` (:func:`~crosscheck.cases.space.classify`; not to be changed)."""
    known = _CELLS.get(id(case))
    if known is not None and known[0] is case:
        return known[1]
    if len(_CELLS) >= KEPT:
        _CELLS.clear()
    cell = classify(case)
    _CELLS[id(case)] = (case, cell)
    return cell
