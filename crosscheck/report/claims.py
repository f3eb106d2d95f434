"""Published claims against the measurement: each engine's claims checked on a stored run.

An engine variant declares its published accuracy claims (:class:`~crosscheck.core.claims.Claim`,
``Adapter.claims``); a run records them in run.json (:attr:`RunInfo.claims
<crosscheck.results.runinfo.RunInfo.claims>`), so this module reads them from the run and never
imports an engine.  :func:`evaluate` sets each claim beside the run's rows of its engine, its
quantity, its kinds and dimensions:

- a row is *inside* the claim's regime when its case's size (the largest radius or half-width of
  its bodies), its true signed gap (the exact ``distance`` of a box or sphere pair: the truth of
  the case's ``distance`` rows, else :mod:`reference_impl.exact`; no other kind has one, so a
  claim that bounds the gap leaves them out) and its block (``origin``, else its id) are
  inside it;
- a row is *measured* when its status is scored (agree, disagree): its ``error`` is in the
  quantity's error unit (:attr:`crosscheck.core.kinds.Quantity.unit`: m for a distance, rad for
  a normal, 0 or 1 for a ``hit`` verdict), the unit of the claim's bound.  Every other row
  (skip, undefined, error, crash, timeout) is counted apart by status, never read as 0 error;
- the verdict: ``holds`` when every measured row inside is within the bound (for a relative
  claim, the bound times the row's size or length), ``fails`` with the worst row otherwise,
  ``untested`` (with why) when no measured row is inside: the engine is not in the run, no row
  answers the claim's quantity on its kinds, no case is in the regime, or every row inside
  went unanswered.

The worst row is the largest error (relative claims: the largest error over the row's size or
length).  :func:`cells` writes each check as the text every table shows (the page, the CLI),
:func:`frame` as numbers (``claims.csv``).

>>> from crosscheck.core.claims import Claim
>>> check = ClaimCheck("e", Claim("distance", ("sphere",), 1e-6, "s", "u"), "untested",
...                    "engine not in the run")
>>> cells(check)["verdict"], cells(check)["why"]
('untested', 'engine not in the run')
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
import pandas as pd

from crosscheck.core.claims import ALL, Claim
from crosscheck.core.model import Status
from crosscheck.core.schema import AabbCase, AnyCase, SceneCase, SphereCase
from crosscheck.report import text
from crosscheck.results.run import Run
from reference_impl import exact
from reference_impl.types import Undefined

__all__ = ["COLUMNS", "ClaimCheck", "Worst", "case_facts", "cells", "evaluate", "frame"]

Verdict = Literal["holds", "fails", "untested"]
GAP_KINDS = ("aabb", "sphere")
"""The kinds whose cases have a true signed gap (their exact ``distance``)."""
COLUMNS = ("engine", "quantity", "kinds", "regime", "bound", "inside", "worst_inside",
           "worst_inside_case", "unanswered", "outside", "worst_outside", "worst_outside_case",
           "verdict", "why", "statement", "source")
"""The columns of ``claims.csv`` and of :func:`cells`, in order."""


@dataclass(frozen=True)
class Worst:
    """The worst measured row of a set: its error, its case, the bound at its size (its
    limit) and its relative error (error over its size or length; NaN for an absolute claim)."""

    error: float
    case_id: str
    limit: float
    relative: float = math.nan


@dataclass(frozen=True)
class ClaimCheck:
    """One claim of one engine against the run (module docstring)."""

    engine: str
    claim: Claim
    verdict: Verdict
    why: str = ""
    """Untested: why; fails: the worst row's error against its bound; holds: ''."""
    inside: int = 0
    """Measured rows inside the regime."""
    worst_inside: Worst | None = None
    unanswered: dict[str, int] = field(default_factory=dict)
    """Rows inside the regime without a measured error, by status."""
    outside: int = 0
    """Measured rows of the claim's kinds and quantity outside the regime."""
    worst_outside: Worst | None = None


def case_facts(run: Run) -> pd.DataFrame:
    """Per case id of the run: ``size`` (largest |radius| or |half-width| of its bodies),
    ``length`` (largest |coordinate|, radius or half-width), ``offset`` (largest |coordinate|
    of a centre; inf with a non-finite one: inside no bounded offset), ``gap`` (the exact
    signed gap of a box or sphere pair, NaN otherwise or where it has none) and ``block``
    (origin, else id)."""
    truths = _distance_truths(run)
    rows = []
    for case_id, case in run.cases.items():
        size, length, offset = _scales(case)
        gap = truths.get(case_id, math.nan)
        if case_id not in truths and isinstance(case, AabbCase | SphereCase):
            gap = _exact_gap(case)
        rows.append((case_id, size, length, offset, gap, case.origin or case_id))
    return pd.DataFrame(rows, columns=["case_id", "size", "length", "offset", "gap",
                                       "block"]).set_index("case_id")


def _distance_truths(run: Run) -> dict[str, float]:
    """The true signed distance of every box and sphere pair that has a ``distance`` row."""
    results = run.results
    if results.empty:
        return {}
    mask = (results["quantity"] == "distance") & results["kind"].isin(GAP_KINDS)
    ids = results.loc[mask, "case_id"]
    values = run.decoded.loc[mask, "truth_decoded"]
    out: dict[str, float] = {}
    for case_id, value in zip(ids, values, strict=True):
        if case_id not in out:
            out[str(case_id)] = float(value) if isinstance(value, int | float) else math.nan
    return out


def _exact_gap(case: AabbCase | SphereCase) -> float:
    if isinstance(case, AabbCase):
        contact = exact.aabb_contact(case.a.center, case.a.half, case.b.center, case.b.half)
    else:
        contact = exact.sphere_contact(case.a.center, case.a.radius, case.b.center,
                                       case.b.radius)
    distance = getattr(contact, "distance", None)
    return math.nan if isinstance(contact, Undefined) or distance is None else float(distance)


def _scales(case: AnyCase) -> tuple[float, float, float]:
    bodies = case.bodies if isinstance(case, SceneCase) else (case.a, case.b)
    sizes: list[float] = []
    centres: list[float] = []
    for body in bodies:
        half = getattr(body, "half", None)
        sizes += list(half) if half is not None else [float(getattr(body, "radius"))]  # noqa: B009
        centres += list(body.center)
    finite = [abs(x) for x in sizes if math.isfinite(x)]
    size = max(finite, default=math.nan)
    offset = (max((abs(x) for x in centres), default=math.nan)
              if all(math.isfinite(x) for x in centres) else math.inf)
    length = max([*finite, *(abs(x) for x in centres if math.isfinite(x))], default=math.nan)
    return size, length, offset


def evaluate(run: Run, claims: Mapping[str, Sequence[Claim]] | None = None) -> list[ClaimCheck]:
    """Every claim checked on the run: ``claims`` by engine name (default: those the run
    recorded, :attr:`RunInfo.claims <crosscheck.results.runinfo.RunInfo.claims>`); an engine
    that is not in the run gets ``untested``."""
    declared = run.info.claims if claims is None else claims
    if not any(declared.values()):
        return []
    facts = case_facts(run)
    columns = ["case_id", "kind", "dim", "engine", "quantity", "error", "status"]
    rows = run.results[columns].join(facts, on="case_id") if len(run.results) else None
    in_run = set(run.info.engine_names)
    return [_check(engine, claim, rows if engine in in_run else None)
            for engine, those in declared.items() for claim in those]


def _check(engine: str, claim: Claim, rows: pd.DataFrame | None) -> ClaimCheck:
    if rows is None:
        return ClaimCheck(engine, claim, "untested", "engine not in the run")
    mine = rows[(rows["engine"] == engine) & (rows["quantity"] == claim.quantity)
                & rows["kind"].isin(claim.kinds) & rows["dim"].isin(claim.dims)]
    if mine.empty:
        dims = "/".join(f"{d}-D" for d in claim.dims)
        return ClaimCheck(engine, claim, "untested",
                          f"no row of {engine} answers {claim.quantity} on "
                          f"{', '.join(claim.kinds)} in {dims} in this run")
    inside = _inside(claim, mine)
    scored = mine["status"].isin(Status.members("scored")).to_numpy()
    measured, rest = mine[inside & scored], mine[inside & ~scored]
    unanswered = {str(s): int(n) for s, n in rest["status"].value_counts(sort=False).items()}
    outside = mine[~inside & scored]
    worst_in, worst_out = _worst(claim, measured), _worst(claim, outside)
    base = ClaimCheck(engine, claim, "untested", "", len(measured), worst_in, unanswered,
                      len(outside), worst_out)
    if worst_in is None:
        why = (f"every row inside the regime went unanswered ({_counts(unanswered)})"
               if unanswered else f"no case in the regime ({len(mine)} rows outside it)")
        return replace(base, verdict="untested", why=why)
    if _beyond(claim, worst_in):
        why = f"error {text.error(worst_in.error)} > {text.error(worst_in.limit)}"
        return replace(base, verdict="fails", why=why)
    return replace(base, verdict="holds")


def _inside(claim: Claim, rows: pd.DataFrame) -> np.ndarray:
    """Which rows are inside the claim's regime (a NaN size or gap is inside only an
    unbounded range)."""
    keep = np.ones(len(rows), dtype=bool)
    if claim.size != ALL:
        size = rows["size"].to_numpy(dtype=float)
        keep &= (size >= claim.size[0]) & (size <= claim.size[1])
    if claim.gap != ALL or claim.clear_of_touching > 0:
        gap = rows["gap"].to_numpy(dtype=float)
        keep &= (gap >= claim.gap[0]) & (gap <= claim.gap[1])
        keep &= np.abs(gap) >= claim.clear_of_touching
    if math.isfinite(claim.offset):
        keep &= rows["offset"].to_numpy(dtype=float) <= claim.offset
    if claim.blocks:
        keep &= rows["block"].map(claim.in_block).to_numpy(dtype=bool)
    return keep


def _worst(claim: Claim, rows: pd.DataFrame) -> Worst | None:
    """The measured row with the largest error (relative claims: over its size or length)."""
    if rows.empty:
        return None
    error = rows["error"].to_numpy(dtype=float)
    scale = rows[claim.relative_to].to_numpy(dtype=float)
    if claim.relative:
        with np.errstate(divide="ignore", invalid="ignore"):
            key = np.where(error == 0, 0.0, error / scale)
    else:
        key = error
    key = np.where(np.isnan(key), math.inf, key)  # a measured row without a number: worst
    at = int(np.argmax(key))
    return Worst(float(error[at]), str(rows["case_id"].iloc[at]),
                 claim.limit(float(scale[at])) if claim.relative else claim.bound,
                 float(key[at]) if claim.relative else math.nan)


def _beyond(claim: Claim, worst: Worst) -> bool:
    value = worst.relative if claim.relative else worst.error
    return not value <= claim.bound


def _counts(counts: Mapping[str, int]) -> str:
    return ", ".join(f"{status} {n}" for status, n in counts.items())


def _worst_words(claim: Claim, worst: Worst | None) -> str:
    if worst is None:
        return ""
    if claim.relative:
        return f"{text.error(worst.error)} ({text.error(worst.relative)} x {claim.relative_to})"
    return text.error(worst.error)


def cells(check: ClaimCheck) -> dict[str, str]:
    """One check as the text of a table row, in :data:`COLUMNS` order."""
    c = check.claim
    return {"engine": check.engine, "quantity": c.quantity, "kinds": ", ".join(c.kinds),
            "regime": c.regime_words(), "bound": c.bound_words(),
            "inside": str(check.inside), "worst_inside": _worst_words(c, check.worst_inside),
            "worst_inside_case": check.worst_inside.case_id if check.worst_inside else "",
            "unanswered": _counts(check.unanswered), "outside": str(check.outside),
            "worst_outside": _worst_words(c, check.worst_outside),
            "worst_outside_case": check.worst_outside.case_id if check.worst_outside else "",
            "verdict": check.verdict, "why": check.why, "statement": c.statement,
            "source": c.source}


def frame(checks: Sequence[ClaimCheck]) -> pd.DataFrame:
    """The checks as numbers (``claims.csv``): a row per check in :data:`COLUMNS`, then
    ``unit`` and ``relative_to`` ('' for an absolute bound); the bound and the errors as
    floats (NaN: none), counts as integers, the rest as text."""
    rows = []
    for check in checks:
        row: dict[str, object] = dict(cells(check))
        row["bound"] = check.claim.bound
        row["unit"] = check.claim.unit
        row["relative_to"] = check.claim.relative_to if check.claim.relative else ""
        row["inside"], row["outside"] = check.inside, check.outside
        for side, worst in (("inside", check.worst_inside), ("outside", check.worst_outside)):
            row[f"worst_{side}"] = worst.error if worst else math.nan
        rows.append(row)
    return pd.DataFrame(rows, columns=[*COLUMNS, "unit", "relative_to"])
