"""The verdict block: which engine can I trust, and what breaks it.

Per engine, one row: its share of agreeing rows per kind and overall, its speed
rank per kind (by median instructions per query where every engine of the kind with a
cost was counted, else by median wall-clock query time: :mod:`crosscheck.report.cost`),
and its failure modes.  A failure mode is the (status, category,
reason pattern) of breaking rows (disagree, error, crash, timeout), where the
reason pattern is the reason with every number replaced by ``#``: reasons that
differ only in their numbers are one mode.  Its example case shows the command that prints
its repro script, and links the script when the run folder holds it
(:mod:`crosscheck.report.repro_links`).  The modes of bad-input cases and of zero-size bodies
are kept apart (:mod:`crosscheck.report.aside`): never among an engine's top modes, counted
beside them, and labelled in the list of all modes.

The share of an engine on a kind is agree / (agree + breaking rows): skip rows
(the engine cannot do it) and undefined rows (no defined value, whatever the
engine did) count neither way, as in the engines x case groups matrix.

The block also says what the repeat check found (:func:`repeat_counts`): how many pairs it
asked again and, per engine, how many answered differently (``nondeterministic``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Collection
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from crosscheck.core.kinds import KIND_ORDER
from crosscheck.core.model import Status
from crosscheck.report import aside, repro_links
from crosscheck.report.cost import cost_of, rank
from crosscheck.report.frames import records
from crosscheck.report.summary_tables import share_colour
from crosscheck.results.jsonlines import each_distinct

SHOWN = 3
"""Failure modes shown per engine in the block (all of them are in the list below it)."""
DASH = "\u2013"

_NUMBER = re.compile(
    r"(?<![\w.])(?:[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|inf)(?:inity)?)(?!\w)")


def reason_pattern(reason: str) -> str:
    """The reason with every number replaced by ``#`` (digits inside words stay).

    >>> reason_pattern("error 1.2e-06 beyond the agree bound 3.5e-15 (size 4)")
    'error # beyond the agree bound # (size #)'
    >>> reason_pattern("error 4e-07 beyond the agree bound 0.0002 (size 10)")
    'error # beyond the agree bound # (size #)'
    >>> reason_pattern("|gap| -0.5 after 360 steps; v1 is nan, float32 gives inf")
    '|gap| # after # steps; v1 is #, float32 gives #'
    >>> reason_pattern("worker killed by SIGSEGV")
    'worker killed by SIGSEGV'
    """
    return _NUMBER.sub("#", reason)


def share_text(share: float | None) -> str:
    """A share as a percentage that never rounds up to 100% (:data:`DASH`: nothing judged).

    >>> share_text(1.0), share_text(0.9996), share_text(0.5), share_text(None) == DASH
    ('100%', '99.9%', '50.0%', True)
    """
    if share is None:
        return DASH
    return "100%" if share >= 1 else f"{int(share * 1000) / 10:.1f}%"


@dataclass(frozen=True)
class Cell:
    """One engine on one kind: agreeing share and speed rank (``None``: nothing to show)."""

    agree: int
    judged: int
    rank: int | None = None
    ranked: int = 0
    median_s: float | None = None
    median_instructions: float | None = None
    """Median instructions per query over the counted cases (None: none counted)."""
    by_counts: bool = False
    """The rank is by instructions per query (every engine of the kind was counted)."""

    @property
    def share(self) -> float | None:
        return self.agree / self.judged if self.judged else None

    @property
    def text(self) -> str:
        return share_text(self.share)

    @property
    def colour(self) -> str:
        return share_colour(self.share)

    @property
    def speed(self) -> str:
        return DASH if self.rank is None else f"{self.rank} of {self.ranked}"


@dataclass(frozen=True)
class Mode:
    """One failure mode of one engine: how many rows, one example case and its repro script."""

    engine: str
    status: str
    category: str
    pattern: str
    count: int
    example: str
    repro: str
    """``repro/<name>.py`` when the example's script is in the run folder, else ``""`` (the
    page gives the command that prints it either way:
    :func:`crosscheck.report.repro_links.command`)."""
    reason: str = ""
    """The example row's own reason, its numbers intact."""
    aside: str = ""
    """Why the headline leaves this mode out (:func:`crosscheck.report.aside.labels`: bad
    input, zero size), ``""``: it is a headline mode."""

    @property
    def label(self) -> str:
        return f"{self.status} / {self.category}" if self.category else self.status


@dataclass(frozen=True)
class EngineVerdict:
    """One row of the block: an engine, its cells per kind, overall share and failure modes."""

    engine: str
    cells: list[Cell]
    overall: Cell
    modes: list[Mode] = field(default_factory=list)
    nondeterministic: int = 0
    """Its case x engine pairs that answered differently when the repeat check asked again."""

    @property
    def top(self) -> list[Mode]:
        return headline(self.modes)[:SHOWN]

    @property
    def headline_modes(self) -> int:
        return len(headline(self.modes))

    @property
    def set_aside(self) -> int:
        """Its breaking rows on bad input or zero-size bodies (left out of :attr:`top`)."""
        return sum(m.count for m in self.modes if m.aside)

    @property
    def breaking(self) -> int:
        return sum(m.count for m in self.modes)


def headline(modes: list[Mode]) -> list[Mode]:
    """The modes a headline shows: those not set aside (bad input, zero size)."""
    return [m for m in modes if not m.aside]


def kinds_of(frame: pd.DataFrame) -> list[str]:
    """The kinds of the run: those of :data:`~crosscheck.core.kinds.KIND_ORDER` present, then
    any other, in run order."""
    present = [str(k) for k in dict.fromkeys(frame["kind"])]
    return [k for k in KIND_ORDER if k in present] + [k for k in present if k not in KIND_ORDER]


def agreement(frame: pd.DataFrame) -> pd.DataFrame:
    """Per engine x kind: ``agree`` and ``judged`` (agree + breaking) row counts."""
    judged = frame[frame["status"].isin(Status.members("judged"))]
    agree = judged["status"].eq("agree").rename("agree")
    counts = agree.groupby([judged["engine"], judged["kind"]]).agg(["sum", "count"])
    return counts.rename(columns={"sum": "agree", "count": "judged"}).astype(int)


def speed_ranks(frame: pd.DataFrame) -> pd.DataFrame:
    """Per engine x kind with a cost: median ``query_s`` of its timed cases and median
    ``query_instructions`` of its counted ones, whether its kind is ranked ``by_counts``
    (every engine of the kind with a cost was counted), its rank in that measure among the
    engines of the kind measured so (1 = cheapest; ties share the better rank) and how many."""
    rows = []
    for kind, of_kind in frame.groupby("kind", sort=False):
        costs = {str(e): cost_of(r) for e, r in of_kind.groupby("engine", sort=False)}
        ranking = rank(list(costs), costs.__getitem__)
        places = [(e, p) for e, p in zip(ranking.items, ranking.places, strict=True) if p]
        rows += [{"engine": e, "kind": str(kind), "median_s": costs[e].wall.median,
                  "median_instructions": costs[e].counted.median,
                  "by_counts": ranking.by_counts, "rank": place, "ranked": len(places)}
                 for e, place in places]
    columns = ["engine", "kind", "median_s", "median_instructions", "by_counts", "rank", "ranked"]
    return pd.DataFrame(rows, columns=columns).set_index(["engine", "kind"])


_MODE_COLUMNS = frozenset({"case_id", "engine", "status", "category", "reason", "tags"})
"""The columns :func:`failure_modes` reads (``tags``: which rows :mod:`~crosscheck.report.aside`
sets aside)."""


def failure_modes(frame: pd.DataFrame, written: Collection[str] = (),
                  zero_sized: Collection[str] = ()) -> list[Mode]:
    """Every failure mode of every engine, most rows first (ties: in the order first seen).

    The example of a mode is its first row whose repro script is in ``written``
    (file names), else its first row.  The rows of bad-input cases and of the cases in
    ``zero_sized`` (:func:`crosscheck.report.aside.zero_size`) are modes of their own,
    marked :attr:`Mode.aside`.
    """
    read = [c for c in frame.columns if c in _MODE_COLUMNS]  # the rest is not carried along
    bad = frame.loc[frame["status"].isin(Status.members("breaking")).to_numpy(), read]
    if bad.empty:
        return []
    links = [repro_links.link(str(c), str(e), written)
             for c, e in zip(bad["case_id"], bad["engine"], strict=True)]
    reasons = bad["reason"].fillna("").astype(str)
    bad = bad.assign(_pattern=each_distinct(reasons, reason_pattern), _reason=reasons,
                     _category=bad["category"].fillna("").astype(str), _repro=links,
                     _has=[bool(link) for link in links],
                     _aside=aside.labels(bad, zero_sized))
    keys = ["engine", "status", "_category", "_pattern", "_aside"]
    counts = bad.groupby(keys, sort=False).size().rename("count")
    firsts = bad.sort_values("_has", ascending=False, kind="stable").groupby(
        keys, sort=False)[["case_id", "_repro", "_has", "_reason"]].first()
    modes = counts.to_frame().join(firsts).reset_index()
    modes = modes.sort_values("count", ascending=False, kind="stable")
    return [Mode(engine=str(r["engine"]), status=str(r["status"]), category=str(r["_category"]),
                 pattern=str(r["_pattern"]), count=int(r["count"]), example=str(r["case_id"]),
                 repro=str(r["_repro"]),
                 reason=str(r["_reason"]), aside=str(r["_aside"]))
            for r in records(modes)]


def cells(frame: pd.DataFrame) -> dict[tuple[str, str], Cell]:
    """Per engine x kind with rows: its :class:`Cell` (counts from :func:`agreement`, speed
    from :func:`speed_ranks`)."""
    agreed, ranks = agreement(frame), speed_ranks(frame)
    counts = {(str(e), str(k)): (int(a), int(j)) for (e, k), a, j in zip(
        agreed.index, agreed["agree"], agreed["judged"], strict=True)}
    timed = {(str(e), str(k)): r for (e, k), r in zip(
        ranks.index, records(ranks), strict=True)}
    out = {}
    for key in dict.fromkeys([*counts, *timed]):
        agree, judged = counts.get(key, (0, 0))
        out[key] = _ranked(Cell(agree, judged), timed[key]) if key in timed else Cell(
            agree, judged)
    return out


def _ranked(cell: Cell, rank: dict[Any, Any]) -> Cell:
    """``cell`` with its speed rank and medians (a row of :func:`speed_ranks`)."""
    instructions = float(rank["median_instructions"])
    return Cell(cell.agree, cell.judged, int(rank["rank"]), int(rank["ranked"]),
                float(rank["median_s"]), None if math.isnan(instructions) else instructions,
                bool(rank["by_counts"]))


def repeat_counts(frame: pd.DataFrame) -> tuple[int, dict[str, int]]:
    """The pairs the repeat check asked again, and per engine those that answered differently
    (every engine of the run, 0 when none did; a frame without the repeat columns: none).

    >>> rows = pd.DataFrame({"case_id": ["a", "a", "b"], "engine": ["e", "e", "f"],
    ...     "repeat_status": ["disagree", "agree", ""], "nondeterministic": [True, True, False]})
    >>> repeat_counts(rows)
    (1, {'e': 1, 'f': 0})
    """
    counts = dict.fromkeys((str(e) for e in dict.fromkeys(frame["engine"])), 0)
    if "repeat_status" not in frame.columns:
        return 0, counts
    asked = frame[frame["repeat_status"].astype(str) != ""].drop_duplicates(["case_id", "engine"])
    for engine, changed in zip(asked["engine"], asked["nondeterministic"], strict=True):
        counts[str(engine)] += bool(changed)
    return len(asked), counts


def verdicts(frame: pd.DataFrame, written: Collection[str] = (),
             zero_sized: Collection[str] = ()) -> list[EngineVerdict]:
    """One verdict per engine, best overall agreeing share first (nothing judged: last);
    ``zero_sized``: the cases with a zero-size body, set aside with the bad-input ones."""
    made, modes = cells(frame), failure_modes(frame, written, zero_sized)
    _, changed = repeat_counts(frame)
    rows = []
    for engine in (str(e) for e in dict.fromkeys(frame["engine"])):
        row = [made.get((engine, kind), Cell(0, 0)) for kind in kinds_of(frame)]
        overall = Cell(sum(c.agree for c in row), sum(c.judged for c in row))
        rows.append(EngineVerdict(engine, row, overall,
                                  [m for m in modes if m.engine == engine], changed[engine]))
    return sorted(rows, key=lambda v: 1.0 if v.overall.share is None else -v.overall.share)


def verdict(frame: pd.DataFrame, repros: Collection[str] = (),
            repeat_check: dict[str, Any] | None = None,
            zero_sized: Collection[str] = ()) -> dict[str, Any]:
    """The verdict section's context: ``zero_sized`` the cases with a zero-size body
    (:func:`crosscheck.report.aside.zero_size`); ``repros`` are the file names of the run's repro
    scripts (:attr:`crosscheck.results.run.Run.repros`), ``repeat_check`` the run's
    summary of its repeat check (None: not run)."""
    rows = verdicts(frame, repros, zero_sized)
    asked, changed = repeat_counts(frame)
    return {"kinds": kinds_of(frame), "rows": rows, "shown": SHOWN,
            "kinds_counted": any(c.by_counts for row in rows for c in row.cells),
            "modes": [m for row in rows for m in row.modes],
            "repeat": None if repeat_check is None else {
                "asked": asked, "changed": {e: n for e, n in changed.items() if n}}}
