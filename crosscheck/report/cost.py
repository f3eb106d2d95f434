"""An engine's cost per query, measured two ways, and the one rule that ranks engines by it.

Every timed case x engine has its wall-clock time per query (``query_s``: the median of its
samples); a run made with ``crosscheck run --timer instructions`` also has, for the pairs
it counted, the instructions of one query (``query_instructions``, counted under Valgrind's
callgrind, the whole query call) and of those the ones inside the engine's own shared
objects (``engine_instructions``).  An engine's :class:`Cost` over some cases is the spread
(median and quartiles over the cases, :func:`crosscheck.results.timings.spread`) of each
measure: :func:`cost_of` is the one per-case cost spread of the report, ``advise``, the
tables and the tools.

A count does not drift with the machine's load as wall time does, so a group of engines
compared on cost (a speed chart's points, a verdict's kinds and profiles, an ``advise``
tier) is ranked by instructions per query **when every engine of the group was counted**
(:func:`by_counts`), and by the wall clock otherwise: one measure for the whole group, never
a count against a time.  :func:`rank` is the one ranking: cheapest first, unmeasured last,
ties in the given order.

>>> fast = Cost(spread([2e-6, 3e-6]), spread([9e4, 1e5]), 4e4)
>>> slow = Cost(spread([1e-6]), spread([]), math.nan)
>>> by_counts([fast.measure]), by_counts([fast.measure, slow.measure]), by_counts([])
(True, False, False)
>>> ranked = rank(["fast", "slow"], {"fast": fast, "slow": slow}.__getitem__)
>>> ranked.items, ranked.by_counts, ranked.places
(['slow', 'fast'], False, [1, 2])
>>> fast.text(True), slow.text(False)
('95 ± 5 k instr (2.5 ± 0.5 µs)', '1 ± 0 µs')
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, Protocol, TypeVar

import pandas as pd

from crosscheck.report.text import instructions_iqr, median_iqr
from crosscheck.results.timings import Spread, spread

COUNTED_TITLE = "median instructions per query (counted under callgrind)"
"""What the cost of a group ranked by counts is, in words (an axis title, a caption)."""
WALL_TITLE = "median wall-clock time per query (s)"
"""What the cost of a group ranked by the wall clock is, in words."""
UNMEASURED = spread([])
"""The spread of no case (``n == 0``, NaN figures)."""

Measure = tuple[float, float]
"""An engine's median wall-clock seconds and median instructions per query (NaN: not
measured so): what :func:`by_counts` and :func:`rank` read."""


def column(rows: pd.DataFrame, name: str) -> pd.Series:
    """The float column ``name`` of ``rows``, or NaN throughout when ``rows`` lacks it (a frame
    built before the count columns existed).

    >>> bool(column(pd.DataFrame({"a": [1]}), "query_instructions").isna().all())
    True
    """
    if name in rows.columns:
        return rows[name].astype(float)
    return pd.Series(math.nan, index=rows.index, dtype=float)


@dataclass(frozen=True, slots=True)
class Cost:
    """One engine's cost per query over some cases: each measure's spread over the cases
    (``n == 0``: none measured so)."""

    wall: Spread
    """Wall-clock seconds per query (each case's median of its samples)."""
    counted: Spread
    """Instructions per query, counted under callgrind."""
    in_engine: float
    """Median instructions per query inside the engine's own shared objects (NaN: not
    counted, or the adapter names none)."""

    @property
    def timed(self) -> bool:
        return self.wall.n > 0

    @property
    def is_counted(self) -> bool:
        return self.counted.n > 0

    @property
    def measure(self) -> Measure:
        """Its medians both ways, as :func:`rank` reads them."""
        return self.wall.median, self.counted.median

    def ranked_by(self, counts: bool) -> Spread:
        """The spread a group ranked by ``counts`` (or by the wall clock) compares."""
        return self.counted if counts else self.wall

    @property
    def wall_text(self) -> str:
        """The wall-clock median ± IQR ('n/a': not timed)."""
        return median_iqr(self.wall.median, self.wall.iqr) if self.timed else "n/a"

    @property
    def counted_text(self) -> str:
        """The instructions per query, median ± IQR ('n/a': not counted)."""
        return instructions_iqr(self.counted.median, self.counted.iqr) if self.is_counted \
            else "n/a"

    def text(self, counts: bool) -> str:
        """The cost in one line: counted, with the wall clock in brackets, for a group ranked
        by counts; the wall clock alone (as before counts existed) otherwise."""
        if not counts:
            return self.wall_text
        return f"{self.counted_text} ({self.wall_text})"


def cost_of(rows: pd.DataFrame) -> Cost:
    """The cost of one engine over the cases of ``rows`` (its rows: one value per case)."""
    keys = ["case_id", "engine"]
    per_case = rows.loc[~rows.duplicated(keys),  # the first row of each: the columns it reads
                        [c for c in rows.columns if c in _COSTS]]
    wall = column(per_case, "query_s").dropna()
    counted = column(per_case, "query_instructions").dropna()
    in_engine = column(per_case, "engine_instructions").dropna()
    return Cost(spread(wall.tolist()), spread(counted.tolist()),
                float(in_engine.median()) if len(in_engine) else math.nan)


_COSTS = frozenset({"query_s", "query_instructions", "engine_instructions"})
"""The columns :func:`cost_of` reads."""


def by_counts(measures: Iterable[Measure]) -> bool:
    """Whether a group is ranked by instructions: it has a measured engine, and every engine
    of it measured either way was counted (an engine measured neither way ranks last in
    both)."""
    measured = [m for m in measures if not (math.isnan(m[0]) and math.isnan(m[1]))]
    return bool(measured) and all(not math.isnan(counted) for _, counted in measured)


T = TypeVar("T")


class _Ordered(Protocol):
    def __lt__(self, other: Any, /) -> bool: ...


@dataclass(frozen=True)
class Ranking(Generic[T]):
    """A group ranked on cost: its items cheapest first, each one's value in the group's
    measure (NaN: not measured so), and which measure that is."""

    items: list[T]
    values: list[float]
    by_counts: bool

    @property
    def places(self) -> list[int | None]:
        """Each item's place among those measured (1 = cheapest; ties share the better place;
        None: not measured)."""
        known = [v for v in self.values if not math.isnan(v)]
        return [None if math.isnan(v) else 1 + sum(k < v for k in known) for v in self.values]


def _unranked(_: object) -> int:
    return 0


def rank(items: Sequence[T], cost: Callable[[T], Cost | Measure],
         first: Callable[[T], _Ordered] = _unranked) -> Ranking[T]:
    """``items`` by ``first`` (e.g. a tier's coverage), then cheapest first in the group's
    measure (:func:`by_counts`), unmeasured last, then in their given order."""
    measures = [_measure(cost(item)) for item in items]
    counts = by_counts(measures)
    values = [m[1] if counts else m[0] for m in measures]
    order = sorted(range(len(items)), key=lambda i: (
        first(items[i]), math.isnan(values[i]), 0.0 if math.isnan(values[i]) else values[i]))
    return Ranking([items[i] for i in order], [values[i] for i in order], counts)


def _measure(cost: Cost | Measure) -> Measure:
    return cost.measure if isinstance(cost, Cost) else cost
