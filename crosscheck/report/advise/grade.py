"""``advise``'s graded answer for one engine variant over a profile's envelope.

An engine's grade: how much of the envelope it answers (coverage), the share of
its answers within the needed accuracy, its worst error with the case, the command
that prints its repro script and the script when the run folder holds it, its failure
modes and declared conventions with their numbers, its cost (median wall-clock time per
query over cases, with the interquartile range, and, in a run made with ``--timer
instructions``, the median instructions per query over its counted cases, with theirs),
its coverage per kind and dimension (the part of the envelope it answers), its
robustness on the bad-input cases of the same kinds (judged apart), and how many of the
envelope's cases the repeat check asked again and how many of those answered differently
(``nondeterministic``).

A case is *within* when the engine answers it (some row not ``skip``) and no row
of it is ``wrong`` or ``failed`` (:mod:`crosscheck.report.advise.judge`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd

from crosscheck.core.model import Status
from crosscheck.report import repro_links
from crosscheck.report.advise.judge import CONVENTION, FAILED, SKIP, WRONG
from crosscheck.report.cost import Measure, cost_of
from crosscheck.report.profiles import BASELINES, worst_statuses
from crosscheck.results.run import Run
from crosscheck.results.store import repro_name, repro_path

PASSES, PARTIAL, FAILS, UNSUPPORTED = "passes", "partial", "fails", "unsupported"
"""The tiers: meets the accuracy on the whole envelope; on the part it answers; not on
every case it answers; answers no case of the envelope."""


@dataclass(frozen=True)
class Worst:
    """The worst answer of an engine: its case, what went wrong and by how much."""

    case_id: str
    quantity: str
    status: str
    category: str
    measure: float | None
    """The error (for a hit verdict: the pair's exact |gap|); None: no number."""
    allowed: float
    repro: str | None
    """The run's repro script of the case on this engine, when the run folder holds it
    (written by ``crosscheck repro RUN --all``)."""
    reason: str
    repro_command: str
    """The command that prints that script (:func:`crosscheck.report.repro_links.command`)."""


@dataclass(frozen=True)
class Mode:
    """One failure mode or convention: a quantity, status and category, with its numbers."""

    quantity: str
    status: str
    category: str
    cases: int
    largest: float | None
    """Largest error (for hit verdicts: largest exact |gap|); None: no number."""
    allowed: float
    """The accuracy allowed at the case of the largest."""
    example: str
    reason: str
    nature: str = ""
    """For category ``convention``: what the convention is, ``definition`` (excused, listed
    under ``conventions``) or ``behaviour`` (judged on its error like any answer)."""


@dataclass(frozen=True)
class Part:
    """The engine on one kind x dimension of the envelope."""

    kind: str
    dim: int
    cases: int
    answered: int
    within: int


@dataclass(frozen=True)
class EngineAdvice:
    """One engine variant's grade inside the envelope (see the module docstring)."""

    engine: str
    tier: str
    baseline: bool
    float32: bool
    cases: int
    """Cases of the envelope."""
    answered: int
    within: int
    coverage: float
    """answered / cases."""
    share_within: float | None
    """within / answered; None: answers nothing."""
    median_query_s: float | None
    query_iqr_s: float | None
    median_query_instructions: float | None
    """Median instructions per query over its counted cases (None: none counted)."""
    query_instructions_iqr: float | None
    """Their interquartile range over those cases."""
    worst: Worst | None
    failure_modes: tuple[Mode, ...]
    conventions: tuple[Mode, ...]
    parts: tuple[Part, ...]
    unsupported: tuple[str, ...]
    """Requested kinds and dimensions it skips entirely (``sphere_response``, ``3-D``)."""
    failing_cases: tuple[str, ...]
    """Answered cases not within, the worst first (all of them)."""
    robustness: dict[str, int]
    """Bad-input cases of the requested kinds and dimensions, by the worst status of each."""
    repeated: int = 0
    """Cases of the envelope the repeat check asked again (0: none, or no repeat check)."""
    nondeterministic: int = 0
    """Of those, the cases whose answer changed."""

    @property
    def passes(self) -> bool:
        return self.tier == PASSES

    @property
    def measure(self) -> Measure:
        """Its medians both ways (NaN: not measured so), as
        :func:`crosscheck.report.cost.rank` reads them."""
        return (math.nan if self.median_query_s is None else self.median_query_s,
                math.nan if self.median_query_instructions is None
                else self.median_query_instructions)


def grade(run: Run, engine: str, rows: pd.DataFrame, cases: int,
          bad: pd.DataFrame) -> EngineAdvice:
    """The grade of ``engine`` from its judged in-envelope ``rows`` and its ``bad`` rows."""
    info = next(e for e in run.info.engines if e["name"] == engine)
    answered_rows = rows[rows["judgment"] != SKIP]
    answered = set(answered_rows["case_id"])
    broken = answered_rows[answered_rows["judgment"].isin((WRONG, FAILED))]
    failing = _worst_first(broken)
    within = len(answered) - len(set(failing["case_id"]))
    parts = _parts(rows)
    unsupported = _unsupported(parts)
    float32 = is_float32(info)
    cost = cost_of(answered_rows)
    return EngineAdvice(
        engine=engine, tier=_tier(len(answered), within, cases),
        baseline=engine in BASELINES, float32=float32, cases=cases,
        answered=len(answered), within=within,
        coverage=len(answered) / cases if cases else 0.0,
        share_within=within / len(answered) if answered else None,
        median_query_s=cost.wall.median if cost.timed else None,
        query_iqr_s=cost.wall.iqr if cost.timed else None,
        median_query_instructions=cost.counted.median if cost.is_counted else None,
        query_instructions_iqr=cost.counted.iqr if cost.is_counted else None,
        worst=_worst(run, engine, failing), failure_modes=_modes(failing),
        conventions=_modes(_worst_first(answered_rows[answered_rows["judgment"] == CONVENTION])),
        parts=parts, unsupported=unsupported,
        failing_cases=tuple(dict.fromkeys(failing["case_id"])), robustness=worst_statuses(bad),
        **_repeats(rows))


def _repeats(rows: pd.DataFrame) -> dict[str, int]:
    """The cases of ``rows`` the repeat check asked again, and those that answered
    differently."""
    if "repeat_status" not in rows.columns:
        return {"repeated": 0, "nondeterministic": 0}
    asked = rows[rows["repeat_status"].astype(str) != ""]
    changed = asked[asked["nondeterministic"].astype(bool)]
    return {"repeated": int(asked["case_id"].nunique()),
            "nondeterministic": int(changed["case_id"].nunique())}


def _tier(answered: int, within: int, cases: int) -> str:
    if not answered:
        return UNSUPPORTED
    if within < answered:
        return FAILS
    return PASSES if answered == cases else PARTIAL


def is_float32(info: dict[str, object]) -> bool:
    """Declared float32 arithmetic: ``float32`` or ``f32`` in its settings or notes."""
    conventions = info.get("conventions")
    notes = conventions.get("notes", "") if isinstance(conventions, dict) else ""
    text = f"{info.get('settings', '')} {notes}".lower()
    return "float32" in text or "f32" in text


def _worst_first(rows: pd.DataFrame) -> pd.DataFrame:
    """Most severe status first, then the largest disagreement relative to its allowance."""
    if rows.empty:
        return rows
    ranked = rows.assign(severity=[Status(s).severity for s in rows["status"]],
                         ratio=[-_ratio(m, a) for m, a in
                                zip(rows["measure"], rows["allowed"], strict=True)])
    return ranked.sort_values(["severity", "ratio"], kind="stable")


def _ratio(measure: float, allowed: float) -> float:
    """How many times the allowance a disagreement is (no number: the worst)."""
    if not math.isfinite(measure):
        return math.inf
    if allowed > 0:
        return measure / allowed
    return math.inf if measure > 0 else 0.0


def _finite(value: object) -> float | None:
    number = float(str(value))
    return number if math.isfinite(number) else None


def _worst(run: Run, engine: str, failing: pd.DataFrame) -> Worst | None:
    if failing.empty:
        return None
    row = failing.iloc[0]
    case_id = str(row["case_id"])
    written = f"{repro_name(case_id, engine)}.py" in run.repros
    return Worst(case_id, str(row["quantity"]), str(row["status"]), _text(row["category"]),
                 _finite(row["measure"]), float(row["allowed"]),
                 str(repro_path(run.directory, case_id, engine)) if written else None,
                 _text(row["reason"]), repro_links.command(run.directory, case_id, engine))


def _text(value: object) -> str:
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) else str(value)


def _modes(rows: pd.DataFrame) -> tuple[Mode, ...]:
    """One mode per quantity x status x category (and nature), most cases first (rows worst
    first)."""
    modes = []
    for (quantity, status, category, nature), group in rows.groupby(
            ["quantity", "status", rows["category"].fillna(""), rows["nature"].fillna("")],
            sort=False):
        first = group.iloc[0]
        modes.append(Mode(str(quantity), str(status), str(category),
                          int(group["case_id"].nunique()), _finite(first["measure"]),
                          float(first["allowed"]), str(first["case_id"]),
                          _text(first["reason"]), str(nature)))
    return tuple(sorted(modes, key=lambda m: -m.cases))


def _parts(rows: pd.DataFrame) -> tuple[Part, ...]:
    parts = []
    for (kind, dim), group in rows.groupby(["kind", "dim"], sort=True):
        answered = group[group["judgment"] != SKIP]
        bad = set(answered[answered["judgment"].isin((WRONG, FAILED))]["case_id"])
        done = set(answered["case_id"])
        parts.append(Part(str(kind), int(str(dim)), int(group["case_id"].nunique()), len(done),
                          len(done - bad)))
    return tuple(parts)


def _unsupported(parts: tuple[Part, ...]) -> tuple[str, ...]:
    kinds = dict.fromkeys(p.kind for p in parts)
    dims = dict.fromkeys(p.dim for p in parts)
    return (tuple(k for k in kinds if not any(p.answered for p in parts if p.kind == k))
            + tuple(f"{d}-D" for d in dims if not any(p.answered for p in parts if p.dim == d)))

