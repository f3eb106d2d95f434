"""What the speed-against-error charts plot: per kind, one point per engine and quantity.

A point's x is the engine's cost per query over the cases of that kind
(:mod:`crosscheck.report.cost`): its median instructions per query over the cases
it counted, when every engine of the chart was counted (``crosscheck run --timer
instructions``), else its median wall-clock time per query over the cases it timed
(``query_s``, one value per case x engine: the median of its samples); with the quartiles
of those per-case figures.  Its errors are read per quantity (one
panel each: ``distance`` and ``normal`` for detection, ``v1`` and ``v2`` for
responses) on a **scale-free axis**: each case's error divided by that case's
agree tolerance, the float64 bound of :mod:`crosscheck.truth.bounds` (a few units
in the last place of the magnitudes the textbook formula combines, so it grows
with the case's size), or the case's own tolerance where it sets one.  An error
of 1 is as close as float64 arithmetic allows for that case, whatever the size
of its bodies: a 1e-6 error on bodies of size 1e-6 and a 1e-6 error on bodies of
size 1e6 are 1e12 apart on this axis.  An error with no tolerance to divide by
(0) counts as 0 when it is 0 and off scale otherwise.

The axis is clipped to :data:`FLOOR` .. :data:`CEILING`: errors below the floor
(exact answers among them) are drawn on it, errors above the ceiling (infinite,
NaN, or an answer of -1.8e308) at the ceiling and counted per engine and panel.
``hit`` verdicts are right or wrong, so they are counted apart (wrong verdicts).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from crosscheck.core.kinds import SPECS, SpeedPanels
from crosscheck.core.model import Status
from crosscheck.core.schema import AnyCase
from crosscheck.report import cost as costs
from crosscheck.report.cost import UNMEASURED, Cost
from crosscheck.report.speed import Spread, binding, binding_note, case_times
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.timings import quantiles

FLOOR = 1e-3
"""Errors below this many tolerances (exact ones too) are drawn on the floor line."""
CEILING = 1e15
"""Errors above this many tolerances are off scale (about the size of the case itself:
the float64 bound of a distance is ``8 u`` of it, 10**15 of those is 0.9 of it)."""
UNIT = "case's float64 bound"
"""What one unit of the error axis is, in words (the axis title and the page say it)."""


Measure = SpeedPanels
"""What the chart of one kind plots: one panel per error quantity, and the verdicts."""
MEASURES: dict[str, Measure] = {str(s.kind): s.speed for s in SPECS if s.speed is not None}
"""The kinds with a chart (those whose spec has ``speed``), in report order."""


@dataclass(frozen=True, slots=True)
class Errors:
    """One engine's errors of one quantity, in units of each case's agree tolerance."""

    scored: int
    zeros: int
    """Cases with an error of exactly 0."""
    below: int
    """Cases drawn on the floor (below FLOOR, exact ones included)."""
    off: int
    """Cases off scale (above CEILING, infinite or NaN)."""
    median: float
    p95: float
    max: float
    worst: str
    """Id and description of the case with the largest error."""


NO_ERRORS = Errors(0, 0, 0, 0, math.nan, math.nan, math.nan, "")


@dataclass(frozen=True, slots=True)
class Point:
    """One engine on the chart of one kind (its errors per quantity); NaN: nothing measured."""

    engine: str
    about: str
    """The engine, its version and its settings (from run.json)."""
    cases: int
    time: Spread
    """Per-case query times over the timed cases: median (x), quartiles (whisker), count."""
    unstable: int
    """Timed cases whose own samples spread more than UNSTABLE_SPREAD of their median."""
    binding: Spread | None
    """The cheapest call into the engine's Python binding (None: not measured)."""
    binding_note: str
    """Why there is no binding overhead ('' when there is one)."""
    errors: dict[str, Errors]
    wrong: int
    verdicts: int
    failed: int
    counted: Spread = UNMEASURED
    """Per-case instructions per query over the counted cases (``n == 0``: none counted)."""
    in_engine: float = math.nan
    """Median instructions per query inside the engine's shared objects (NaN: unknown)."""

    @property
    def cost(self) -> Cost:
        """Its cost both ways: the wall-clock times and the counted instructions."""
        return Cost(self.time, self.counted, self.in_engine)

    @property
    def scored(self) -> int:
        """Cases scored on any error quantity."""
        return max((e.scored for e in self.errors.values()), default=0)

    @property
    def timed(self) -> int:
        return self.time.n

    @property
    def query_s(self) -> float:
        return self.time.median

    @property
    def mostly_unstable(self) -> bool:
        """More than half of the timed cases unstable: no precise point for this engine."""
        return self.unstable > self.timed / 2

    @property
    def binding_share(self) -> float | None:
        """The binding call's share of the median query time (None: unknown)."""
        if self.binding is None or not self.query_s > 0:
            return None
        return self.binding.median / self.query_s


@dataclass(frozen=True, slots=True)
class SpeedChart:
    """The points of one kind, drawn on the clipped scale-free error axis."""

    kind: str
    measure: Measure
    points: list[Point]

    @property
    def by_counts(self) -> bool:
        """Every scored engine with a cost was counted: x is instructions per query."""
        return costs.by_counts(p.cost.measure for p in self.points if p.scored)

    @property
    def any_counted(self) -> bool:
        """Some scored engine was counted (its counts are shown, whatever x is)."""
        return any(p.cost.is_counted for p in self.points if p.scored)

    @property
    def x_title(self) -> str:
        """What x is, in words: the speed axis's title."""
        return costs.COUNTED_TITLE if self.by_counts else costs.WALL_TITLE

    def x(self, p: Point) -> Spread:
        """The per-case spread ``p`` is drawn at along x (counted, or wall clock)."""
        return p.cost.ranked_by(self.by_counts)

    def cost_text(self, p: Point) -> str:
        """``p``'s cost in this chart's measure (counted: the wall clock in brackets)."""
        return p.cost.text(self.by_counts)

    def hollow(self, p: Point) -> bool:
        """Drawn hollow: its wall-clock times are mostly unstable and x is the wall clock (a
        count is exact)."""
        return p.mostly_unstable and not self.by_counts

    @property
    def plotted(self) -> list[Point]:
        return [p for p in self.points if p.scored and self.x(p).n]

    @property
    def not_timed(self) -> list[Point]:
        """Scored engines without this chart's measure (not timed, or not counted)."""
        return [p for p in self.points if p.scored and not self.x(p).n]

    @property
    def not_scored(self) -> list[Point]:
        return [p for p in self.points if not p.scored]

    @property
    def timings(self) -> tuple[int, int]:
        """Unstable and all timed cases of the plotted engines."""
        return sum(p.unstable for p in self.plotted), sum(p.timed for p in self.plotted)

    @property
    def within_bound(self) -> list[Point]:
        """The plotted engines whose median error is within the float64 bound (1 on the error
        axis) on every panel they are scored on, cheapest first along x: the headline of the
        kind."""
        scored = [(p, [e for e in p.errors.values() if e.scored]) for p in self.plotted]
        good = [p for p, errors in scored if errors and all(e.median <= 1 for e in errors)]
        return sorted(good, key=lambda p: self.x(p).median)

    def off_scale(self, quantity: str) -> int:
        """Answers of the plotted engines off scale on the panel of ``quantity``."""
        return sum(p.errors[quantity].off for p in self.plotted)

    @staticmethod
    def y(value: float) -> float:
        """Where an error (in tolerances) is drawn: clipped to FLOOR .. CEILING."""
        return CEILING if not value <= CEILING else max(value, FLOOR)

    @staticmethod
    def clipped(value: float) -> bool:
        """Whether ``value`` is drawn on the ceiling instead of where it is."""
        return not value <= CEILING


def in_tolerances(rows: pd.DataFrame) -> pd.Series:
    """Each row's error divided by its tolerance: 0 stays 0, anything over a tolerance of 0
    (or NaN) is infinite, NaN errors are infinite (off scale)."""
    error = rows["error"].astype(float)
    tolerance = rows["tolerance"].astype(float)
    with np.errstate(divide="ignore", invalid="ignore"):
        units = error / tolerance.where(tolerance > 0)
    units = units.where(error != 0, 0.0)
    return units.fillna(math.inf).abs()


def error_stats(errors: pd.Series) -> tuple[float, float, float]:
    """Median, 95th percentile (nearest rank) and max of non-negative errors (inf allowed)."""
    values = errors.dropna().to_numpy(dtype=float)
    if not len(values):
        return math.nan, math.nan, math.nan
    (p95,) = quantiles(values.tolist(), [0.95], nearest=True)
    return float(np.median(values)), p95, float(values.max())


def _worst(errors: pd.Series, cases: Mapping[str, AnyCase]) -> str:
    if errors.empty:
        return ""
    case_id = str(errors.idxmax())
    case = cases.get(case_id)
    return f"{case_id}: {case.description if case else ''}"


def errors_of(scored: pd.DataFrame, quantity: str, cases: Mapping[str, AnyCase]) -> Errors:
    """The errors of one quantity (one value per case: the largest) in tolerances."""
    rows = scored[scored["quantity"] == quantity]
    if rows.empty:
        return NO_ERRORS
    units = in_tolerances(rows).groupby(rows["case_id"]).max()
    median, p95, top = error_stats(units)
    return Errors(scored=len(units), zeros=int((units == 0).sum()),
                  below=int((units < FLOOR).sum()), off=int((~(units <= CEILING)).sum()),
                  median=median, p95=p95, max=top, worst=_worst(units, cases))


def _about(engine: str, info: RunInfo) -> str:
    for entry in info.engines:
        if entry.get("name") == engine:
            return f"{entry.get('engine')} {entry.get('version')}: {entry.get('settings')}"
    return ""


def point(rows: pd.DataFrame, measure: Measure, info: RunInfo,
          cases: Mapping[str, AnyCase]) -> Point:
    """The point of one engine, from its rows of one kind."""
    engine = str(rows["engine"].iloc[0])
    scored = rows[rows["status"].isin(Status.members("scored"))]
    verdicts = scored[scored["quantity"].isin(measure.verdicts)]
    time, unstable = case_times(rows)
    cost = costs.cost_of(rows)
    return Point(
        engine=engine, about=_about(engine, info), cases=rows["case_id"].nunique(),
        time=time, unstable=unstable, binding=binding(info, engine),
        binding_note=binding_note(info, engine),
        errors={q: errors_of(scored, q, cases) for q in measure.errors},
        verdicts=verdicts["case_id"].nunique(),
        wrong=verdicts.loc[verdicts["status"] == Status.DISAGREE, "case_id"].nunique(),
        failed=rows.loc[rows["status"].isin(Status.members("failed")), "case_id"].nunique(),
        counted=cost.counted, in_engine=cost.in_engine)


def speed_chart(frame: pd.DataFrame, kind: str, info: RunInfo,
                cases: Mapping[str, AnyCase]) -> SpeedChart:
    """The speed-against-error data of one kind: one point per engine with rows of it."""
    measure = MEASURES[kind]
    rows = frame[frame["kind"] == kind]
    return SpeedChart(kind, measure, [point(group, measure, info, cases)
                                      for _, group in rows.groupby("engine", sort=False)])


def speed_charts(frame: pd.DataFrame, info: RunInfo,
                 cases: Mapping[str, AnyCase]) -> list[SpeedChart]:
    """One chart per kind present in the results, in the order of MEASURES."""
    present = set(frame["kind"])
    return [speed_chart(frame, kind, info, cases) for kind in MEASURES if kind in present]
