"""Energy against time of a run's scenes (``series.jsonl``): what the dynamics charts draw.

A report never runs an engine, so the run stores what the energy charts need.  For every
scene case x engine whose observation carries a recorded trajectory (a scene with gravity
or walls, :func:`crosscheck.truth.scene_measures.record_every`), and for the exact
reference's trajectory of the case (engine :data:`EXACT`), the runner appends one
:class:`SeriesRecord` as the case's rows are written: the case, its block (``origin``) and
sweep coordinates, the recorded times and the relative energy drift at each,

    (E(t) - E(0)) / energy_scale(case)

with ``E`` the trajectory's total energy (kinetic plus ``-m g . (x - x0)``) and
:func:`~crosscheck.truth.scene_measures.energy_scale`, downsampled to at most
:data:`MAX_POINTS` points (the first and the last always kept, :func:`downsample`).
Times are stored to 9 significant digits and energies to 6 (:data:`DIGITS`: a chart's
precision, a third of the file); a non-finite energy (an engine that blew up) is stored as
``null`` and read as NaN.

A resumed run appends after the old lines; a pair run again (or the exact line of a case
run again for another engine) appends a new line, and :func:`read_series` keeps the last
line of each (case id, engine).

>>> downsample(list(range(10)), 4)
[0, 3, 6, 9]
>>> r = SeriesRecord("c", "exact", "b", {"dt": 0.5}, (0.0, 0.5), (0.0, math.nan))
>>> back = SeriesRecord.from_json(r.to_json())
>>> back.times, math.isnan(back.energy[1]), back.coords
((0.0, 0.5), True, {'dt': 0.5})
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from crosscheck.core.model import Trajectory
from crosscheck.core.schema import SceneCase
from crosscheck.results import jsonlines
from crosscheck.truth.scene_measures import energy_scale

FILE = "series.jsonl"
EXACT = "exact"
"""The engine name of the exact reference's series."""
MAX_POINTS = 200
"""Points kept per series at most (the first and the last always)."""
DIGITS = {"times": 9, "energy": 6}
"""Significant digits stored of each list."""

T = TypeVar("T")


def downsample(values: Sequence[T], most: int = MAX_POINTS) -> list[T]:
    """At most ``most`` of ``values``, evenly spread over their indices, the first and the
    last always kept (all of them when there are no more than ``most``)."""
    n = len(values)
    if n <= most:
        return list(values)
    picks = dict.fromkeys(round(k * (n - 1) / (most - 1)) for k in range(most))
    return [values[i] for i in picks]


@dataclass(frozen=True, slots=True)
class SeriesRecord:
    """One case x engine's relative energy drift against time."""

    case_id: str
    engine: str
    origin: str
    """The case's block (its id before the sweep and time-step suffixes)."""
    coords: dict[str, float] = field(default_factory=dict)
    times: tuple[float, ...] = ()
    """Seconds from the scene's start."""
    energy: tuple[float, ...] = ()
    """``(E(t) - E(0)) / energy_scale(case)`` at each time (NaN: not finite)."""

    def to_json(self) -> str:
        """The record's line in ``series.jsonl`` (without the newline; NaN as null)."""
        return json.dumps({
            "case_id": self.case_id, "engine": self.engine, "origin": self.origin,
            "coords": self.coords, "times": [_rounded(t, DIGITS["times"]) for t in self.times],
            "energy": [_rounded(e, DIGITS["energy"]) for e in self.energy]})

    @classmethod
    def from_json(cls, data: str | Mapping[str, Any]) -> SeriesRecord:
        row = json.loads(data) if isinstance(data, str) else data
        return cls(str(row["case_id"]), str(row["engine"]), str(row.get("origin") or ""),
                   {str(k): float(v) for k, v in (row.get("coords") or {}).items()},
                   tuple(float(t) for t in row["times"]),
                   tuple(math.nan if e is None else float(e) for e in row["energy"]))


def _rounded(value: float, digits: int) -> float | None:
    """``value`` to ``digits`` significant digits (None: not finite).

    >>> _rounded(1 / 3, 6), _rounded(math.inf, 6)
    (0.333333, None)
    """
    return float(f"{value:.{digits}g}") if math.isfinite(value) else None


def series_of(case: SceneCase, engine: str, trajectory: Trajectory | None) -> SeriesRecord | None:
    """The record of ``case`` on ``engine`` from its trajectory (None without one, or with no
    recorded state)."""
    if trajectory is None or not trajectory.times or not trajectory.energy:
        return None
    scale = energy_scale(case)
    scale = scale if scale > 0 and math.isfinite(scale) else 1.0
    start = trajectory.energy[0]
    points = downsample(list(zip(trajectory.times, trajectory.energy, strict=False)))
    return SeriesRecord(case.id, engine, case.origin or case.id, dict(case.coords),
                        tuple(float(t) for t, _ in points),
                        tuple((float(e) - start) / scale for _, e in points))


def read_series(directory: Path) -> list[SeriesRecord]:
    """The series of a run, the last line of each (case id, engine), in the order first
    written; none when the run has no ``series.jsonl`` (a half-written last line is left out)."""
    path = directory / FILE
    found: dict[tuple[str, str], SeriesRecord] = {}
    for line in jsonlines.parse_lines(path):  # a half-written last line is left out
        try:
            record = SeriesRecord.from_json(line)
        except (KeyError, TypeError, ValueError, AttributeError):
            continue  # a line cut where it still reads as JSON
        found[(record.case_id, record.engine)] = record
    return list(found.values())
