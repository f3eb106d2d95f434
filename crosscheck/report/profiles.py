"""The verdict on common ground: the standard scene profiles, each judged over the rows
that every ranked engine answers.

A share of agreeing rows taken over whatever each engine supports favours the engines
that skip: a 2-D-only engine is never asked a 3-D question, and an engine without a
separation query is never asked a separated pair's distance.  So each profile here
(3-D detection, 2-D detection, responses, scenes) is answered in three steps:

1. **The profile's rows**: the case x quantity rows of its kinds and dimension, bad-input
   cases left out (an answer to an invalid input is robustness, shown apart in
   :func:`robustness`, never accuracy).
2. **The ranked engines**: the engine variants that answer (any status but ``skip``) some
   row of every kind and dimension of the profile; the textbook formulas
   (:data:`BASELINES`) are scored beside them as baselines, never ranked.  An engine that
   answers only part of the profile's kinds or dimensions is listed as not ranked, with
   what it lacks.
3. **The common ground**: the rows that every ranked engine answers.  Each engine's score
   is agree / judged over those rows, so no engine gains by skipping; its coverage (rows
   it answers / the profile's rows) is shown beside the score.  Its top failure modes leave
   out the cases with a zero-size body (:mod:`crosscheck.report.aside`; their rows still
   count in the score), and say how many rows those hold.

Ranked engines are ordered by score, then by coverage, then by cost (cheapest first): of
two engines as right on the common ground, the one that answers more of the profile comes
first.  The cost is the median instructions per query over the profile's counted cases
when every ranked engine of the profile was counted (``crosscheck run --timer
instructions``; :mod:`crosscheck.report.cost`), else the median wall-clock query time
over its timed cases, as before counts existed.

>>> rows = pd.DataFrame([
...     {"case_id": c, "kind": "sphere", "dim": 3, "tags": "basic",
...      "engine": e, "quantity": "hit", "status": s, "category": "", "reason": "",
...      "query_s": 1e-6, "unstable": False}
...     for c, e, s in [("a", "fast", "agree"), ("b", "fast", "disagree"),
...                     ("a", "skipper", "agree"), ("b", "skipper", "skip")]])
>>> [(r.engine, r.score.text, r.coverage_text) for r in profile(rows, PROFILES[0]).ranked]
[('fast', '100%', '100%'), ('skipper', '100%', '50.0%')]
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from crosscheck.core.model import Status
from crosscheck.report.aside import bad_input
from crosscheck.report.cost import UNMEASURED, Cost, cost_of, rank
from crosscheck.report.text import instructions_iqr, with_iqr
from crosscheck.report.verdict import Cell, Mode, failure_modes, headline, share_text
from crosscheck.results.timings import Spread

BASELINES = ("reference", "reference-f32")
"""The textbook formulas: drawn beside the engines as baselines, never ranked."""
SHOWN = 2
"""Failure modes shown per engine and profile."""


@dataclass(frozen=True)
class Profile:
    """A standard scene profile: its kinds and dimensions (empty: any dimension)."""

    name: str
    kinds: tuple[str, ...]
    dims: tuple[int, ...] = ()

    def holds(self, kind: str, dim: int) -> bool:
        return kind in self.kinds and (not self.dims or dim in self.dims)


PROFILES = (
    Profile("3-D detection", ("aabb", "sphere"), (3,)),
    Profile("2-D detection", ("aabb", "sphere"), (2,)),
    Profile("responses", ("sphere_response",)),
    Profile("times of impact", ("sphere_toi",)),
    Profile("scenes", ("sphere_scene",)),
)


def _cases(measured: Spread) -> str:
    return f"{measured.n} case{'' if measured.n == 1 else 's'}"


@dataclass(frozen=True)
class EngineScore:
    """One engine on one profile: its score on the common ground, coverage, cost, modes."""

    engine: str
    score: Cell
    answered: int
    """Rows of the profile it answers (not ``skip``)."""
    total: int
    """Rows of the profile."""
    cost: Spread | None
    """Its per-case query times over the profile's timed cases; None: none timed."""
    modes: list[Mode] = field(default_factory=list)
    counted: Spread | None = None
    """Its per-case instructions per query over the profile's counted cases; None: none
    counted."""

    @property
    def coverage(self) -> float:
        return self.answered / self.total if self.total else 0.0

    @property
    def coverage_text(self) -> str:
        return share_text(self.coverage)

    @property
    def top(self) -> list[Mode]:
        return headline(self.modes)[:SHOWN]

    @property
    def headline_modes(self) -> int:
        return len(headline(self.modes))

    @property
    def set_aside(self) -> int:
        """Its breaking rows on zero-size bodies (left out of :attr:`top`)."""
        return sum(m.count for m in self.modes if m.aside)

    @property
    def cost_text(self) -> str:
        """Its median query time with the IQR over its timed cases ('-': none timed)."""
        if self.cost is None:
            return "\u2013"
        return f"{with_iqr(self.cost)}, {_cases(self.cost)}"

    @property
    def counted_text(self) -> str:
        """Its median instructions per query with the IQR over its counted cases ('-': none
        counted)."""
        if self.counted is None:
            return "\u2013"
        return f"{instructions_iqr(self.counted.median, self.counted.iqr)}, {_cases(self.counted)}"

    @property
    def both(self) -> Cost:
        """Its cost both ways (:class:`~crosscheck.report.cost.Cost`)."""
        return Cost(self.cost or UNMEASURED, self.counted or UNMEASURED, 0.0)


@dataclass(frozen=True)
class NotRanked:
    """An engine that answers only part of a profile: what it lacks."""

    engine: str
    answered: int
    lacks: tuple[str, ...]
    """The profile's kinds and dimensions it answers nothing of, e.g. ``sphere 3-D``."""


@dataclass(frozen=True)
class ProfileVerdict:
    """One profile's answer."""

    profile: Profile
    total: int
    """The profile's rows (bad input left out)."""
    common: int
    """Rows every ranked engine answers."""
    cases: int
    """Cases with a row on the common ground."""
    ranked: list[EngineScore] = field(default_factory=list)
    baselines: list[EngineScore] = field(default_factory=list)
    not_ranked: list[NotRanked] = field(default_factory=list)
    by_counts: bool = False
    """Every ranked engine was counted: ties after score and coverage are broken by median
    instructions per query, and the cost column shows them (the wall clock beside)."""


def _answered(rows: pd.DataFrame) -> pd.DataFrame:
    return rows[rows["status"] != Status.SKIP]


def _slots(rows: pd.DataFrame) -> list[str]:
    """The (kind, dim) slots of these rows, as ``sphere 3-D``."""
    return [f"{k} {d}-D" for k, d in sorted(set(zip(rows["kind"], rows["dim"], strict=True)))]


def profile_rows(frame: pd.DataFrame, wanted: Profile) -> pd.DataFrame:
    """The rows of ``wanted``'s kinds and dimensions, bad-input cases left out."""
    inside = frame["kind"].isin(wanted.kinds)
    if wanted.dims:
        inside &= frame["dim"].isin(wanted.dims)
    rows: pd.DataFrame = frame[inside.to_numpy(dtype=bool) & ~bad_input(frame).to_numpy()]
    return rows


def _score(engine: str, mine: pd.DataFrame, common: pd.Index, total: int,
           repros: Collection[str], zero_sized: Collection[str]) -> EngineScore:
    """``engine`` on the profile, from its rows of it (``mine``)."""
    on_ground = mine[_keys(mine).isin(common)]
    judged = on_ground[on_ground["status"].isin(Status.members("judged"))]
    cost = cost_of(mine)
    return EngineScore(
        engine, Cell(int((judged["status"] == Status.AGREE).sum()), len(judged)),
        len(_answered(mine)), total, cost.wall if cost.timed else None,
        failure_modes(on_ground, repros, zero_sized), cost.counted if cost.is_counted else None)


def _keys(rows: pd.DataFrame) -> pd.Index:
    return pd.Index(rows["case_id"].astype(str) + "\x00" + rows["quantity"].astype(str))


def _by_engine(rows: pd.DataFrame) -> dict[str, pd.DataFrame]:
    """The rows of each engine, split once (not a mask over every row per engine)."""
    return {str(engine): group for engine, group in rows.groupby("engine", sort=False)}


def profile(frame: pd.DataFrame, wanted: Profile, repros: Collection[str] = (),
            zero_sized: Collection[str] = ()) -> ProfileVerdict:
    """``wanted`` judged on common ground (see the module docstring); ``zero_sized``: the
    cases with a zero-size body (:func:`crosscheck.report.aside.zero_size`)."""
    rows = profile_rows(frame, wanted)
    slots = set(_slots(rows))
    engines = [str(e) for e in rows["engine"].unique()]
    answered = _answered(rows)
    rows_of, answered_of = _by_engine(rows), _by_engine(answered)
    none = answered.iloc[:0]
    ranked, not_ranked = [], []
    for engine in (e for e in engines if e not in BASELINES):
        mine = answered_of.get(engine, none)
        lacks = tuple(sorted(slots - set(_slots(mine))))
        if lacks:
            not_ranked.append(NotRanked(engine, len(mine), lacks))
        else:
            ranked.append(engine)
    per_engine = [set(_keys(answered_of.get(e, none))) for e in ranked]
    common = pd.Index(sorted(set.intersection(*per_engine))) if per_engine else pd.Index([])
    total = len(rows.drop_duplicates(["case_id", "quantity"]))
    scores = rank([_score(e, rows_of[e], common, total, repros, zero_sized) for e in ranked],
                  lambda s: s.both,
                  lambda s: (s.score.share is None, -(s.score.share or 0.0), -s.coverage))
    baselines = [_score(e, rows_of[e], common, total, repros, zero_sized) for e in engines
                 if e in BASELINES and len(answered_of.get(e, none))]
    cases = len({str(key).split("\x00")[0] for key in common})
    return ProfileVerdict(wanted, total, len(common), cases, scores.items, baselines,
                          not_ranked, scores.by_counts)


def profiles(frame: pd.DataFrame, repros: Collection[str] = (),
             zero_sized: Collection[str] = ()) -> list[ProfileVerdict]:
    """The standard profiles that have rows in ``frame``."""
    needed = {"dim", "tags"}
    if not needed <= set(frame.columns):
        return []
    made = [profile(frame, p, repros, zero_sized) for p in PROFILES]
    return [v for v in made if v.total]


def worst_statuses(rows: pd.DataFrame) -> dict[str, int]:
    """Each case of ``rows`` once, by its worst status (the report's severity order): how
    many cases ended in each status.  ``advise`` and the verdict block both count an
    engine's bad-input answers this way."""
    if rows.empty:
        return {}
    ranked = rows.assign(severity=[Status(s).severity for s in rows["status"]])
    worst = ranked.sort_values("severity", kind="stable").drop_duplicates("case_id")
    return {str(k): int(v) for k, v in worst["status"].value_counts().items()}


@dataclass(frozen=True)
class Robustness:
    """One engine on the bad-input cases: how many it answered, and how many of those
    ended (by their worst row) in a crash, a timeout or an error."""

    engine: str
    answered: int
    crash: int
    timeout: int
    error: int


def robustness(frame: pd.DataFrame) -> list[Robustness]:
    """Per engine, what became of its answers to the bad-input cases (none: empty)."""
    if "tags" not in frame.columns:
        return []
    bad = frame[bad_input(frame)]
    out = []
    for engine in (str(e) for e in dict.fromkeys(bad["engine"])):
        counts = worst_statuses(_answered(bad[bad["engine"] == engine]))
        out.append(Robustness(engine, sum(counts.values()), counts.get(Status.CRASH, 0),
                              counts.get(Status.TIMEOUT, 0), counts.get(Status.ERROR, 0)))
    return out


def context(frame: pd.DataFrame, repros: Collection[str] = (),
            zero_sized: Collection[str] = ()) -> dict[str, Any]:
    """The profile part of the verdict section's context (``zero_sized``: the cases with a
    zero-size body, left out of the top failure modes)."""
    made = profiles(frame, repros, zero_sized)
    return {"profiles": made, "robustness": robustness(frame), "profile_shown": SHOWN,
            "profiles_counted": any(p.by_counts for p in made)}
