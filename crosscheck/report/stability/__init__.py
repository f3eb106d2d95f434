"""The stability study: where along each sweep an engine first stops agreeing with the oracle.

A sweep (``cases/sweeps.toml``) varies one difficulty: the gap or overlap
relative to the size, the body scale, the distance from the origin, the mass
ratio or the approach speed.  For every engine x quantity, each sweep is walked
from its easiest value to its hardest; the *threshold* is the first value where
the answer breaks: status ``disagree``, ``error``, ``crash`` or ``timeout``.
``skip`` and ``undefined`` neither break nor agree: they are stepped over.
The scale sweep is walked twice from 1, towards tiny and towards huge bodies.

The matrix (:func:`matrix`) has a cell per engine x ``column``, one walk of one sweep
(``headline`` marks the row it shows).  A 3-D sweep's 2-D twin (``twin_2d`` in the case
file: the same sweep in a plane) has columns of its own beside its 3-D sweep's (its
``family``), so a 3-D column only holds 3-D rows.  The cell is the kind's headline quantity
(the distance; ``v2`` for responses); an engine that reports no distance along a detection
walk (pymunk gives none for separated bodies) is shown by its ``hit`` walk, and the cell
says so.  An engine with no verdict in a column (skip or undefined everywhere, or no rows)
has a grey "no verdict" cell.  The charts are :mod:`crosscheck.report.stability_charts`.

A fast-body scene point (``step_travel`` at one ``dt``, with its impact ``phase``) is a point
of the ``step_travel`` sweep of that ``dt``; its headline quantity is ``velocities`` (a
pass-through exchanges none), and it breaks only where the impact is missed
(:func:`_missed_impacts_only`): the threshold is the travel at which the engine first lets
the bodies pass through each other, at any phase.

A moved or resized scene (an ``offset`` or ``scale`` sweep of a scene with gravity or walls,
:mod:`crosscheck.cases.world_sweep`, at one ``dt``) is a point of that sweep at its ``dt``,
as a fast-body point is: the ``offset`` column of dynamics is the first offset at which the
engine's scene rows stop agreeing (its headline quantity, ``velocities``, as every scene).

The ``time horizon`` axis (:func:`horizons`) is no sweep: for each long scene (a run of
:data:`LONG_SCENE_S` or more, the gas) at each ``dt``, the cell is the engine's ``divergence``,
the simulated seconds until its trajectory left the case's stated tolerance (``diverge_at``
mean radii) of the exact one; "none" when it never did within the run.

The study is :mod:`.points` (sweep rows as points), :mod:`.study` (walks, thresholds,
horizons, files); the page's section is :mod:`.section` (the matrix) and :mod:`.charts`.
"""

from __future__ import annotations

from crosscheck.report.stability.points import (
    AXES,
    DIRECTIONS,
    POINT_COLUMNS,
    TABLE_COLUMNS,
    relative_error,
    sweep_points,
)
from crosscheck.report.stability.section import matrix, quantity_label, short_name
from crosscheck.report.stability.study import (
    LONG_SCENE_S,
    analyse,
    horizons,
    save,
    thresholds,
    walk,
    with_category,
    with_horizons,
    write,
)

__all__ = ["AXES", "DIRECTIONS", "LONG_SCENE_S", "POINT_COLUMNS", "TABLE_COLUMNS",
           "analyse", "horizons", "matrix", "quantity_label", "relative_error", "save",
           "short_name", "sweep_points", "thresholds", "walk", "with_category", "with_horizons",
           "write"]
