"""``advise``'s rules for one answer (case x engine x quantity) under a scene profile.

Each row gets a *judgment*:

- ``within``: ``agree``; ``undefined`` (the truth itself is undefined); or
  ``disagree`` by at most the accuracy allowed (:meth:`Envelope.allowed`).  A
  ``hit`` verdict is judged by the pair's exact gap: a wrong verdict on a pair
  whose exact |gap| is within the accuracy is within it, as a distance error
  of that size would be;
- ``convention``: a ``disagree`` the engine's declared conventions explain
  (category ``convention``: a touching rule, a margin, soft contact).  It is
  reported with its numbers and fails only when the profile says it matters:
  ``touching_contact`` for a hit verdict on a touching pair (exact gap 0),
  ``strict_conventions`` for every convention (then judged as above);
- ``wrong``: a ``disagree`` beyond the accuracy;
- ``failed``: ``error``, ``crash`` or ``timeout``;
- ``skip``: not an answer; rows of quantities the profile leaves out are dropped.

>>> p = Envelope(tolerance=1e-9)
>>> judge(p, "disagree", "hit", "tolerance", 1.0, gap=1e-12, allowed=1e-9)
'within'
>>> judge(p, "disagree", "hit", "error", 1.0, gap=0.5, allowed=1e-9)
'wrong'
>>> judge(p, "disagree", "hit", "convention", 1.0, gap=0.0, allowed=1e-9)
'convention'
>>> judge(Envelope(touching_contact=True), "disagree", "hit", "convention", 1.0, 0.0, 0.0)
'wrong'
>>> judge(p, "timeout", "v1", "", math.nan, gap=math.nan, allowed=1e-9)
'failed'
"""

from __future__ import annotations

import math

import pandas as pd

from crosscheck.core.model import Category, Status
from crosscheck.core.schema import AnyCase
from crosscheck.report.advise_profile import Envelope, smallest_size

WITHIN, CONVENTION, WRONG, FAILED, SKIP = "within", "convention", "wrong", "failed", "skip"


def judge(profile: Envelope, status: str, quantity: str, category: str, error: float,
          gap: float, allowed: float) -> str:
    """The judgment of one row (see the module docstring)."""
    if status == Status.SKIP:
        return SKIP
    if status in (Status.AGREE, Status.UNDEFINED):
        return WITHIN
    if status != Status.DISAGREE:
        return FAILED
    if category == Category.CONVENTION and not profile.strict_conventions:
        touching = quantity == "hit" and gap == 0.0
        return WRONG if touching and profile.touching_contact else CONVENTION
    return WITHIN if measure(quantity, error, gap) <= allowed else WRONG


def measure(quantity: str, error: float, gap: float) -> float:
    """The size of a disagreement: the exact |gap| for a hit verdict, else the error
    (NaN, never within, when unknown)."""
    value = abs(gap) if quantity == "hit" else error
    return float(value) if value is not None and math.isfinite(value) else math.nan


def exact_gaps(rows: pd.DataFrame) -> dict[str, float]:
    """Per case, the exact gap: the truth of its ``distance`` rows (every engine's row of a
    case holds the same truth; a case without one has no entry)."""
    distance = rows[(rows["quantity"] == "distance")].dropna(subset=["truth"])
    gaps: dict[str, float] = {}
    for case_id, truth in zip(distance["case_id"], distance["truth"], strict=True):
        if case_id not in gaps:
            gaps[str(case_id)] = _number(truth)
    return gaps


def _number(value: object) -> float:
    try:
        return float(str(value))
    except ValueError:
        return math.nan


def judged(rows: pd.DataFrame, cases: dict[str, AnyCase], profile: Envelope) -> pd.DataFrame:
    """``rows`` (of the quantities that matter) with ``gap``, ``allowed``, ``measure`` and
    ``judgment`` columns."""
    if profile.quantities:
        rows = rows[rows["quantity"].isin(profile.quantities)]
    rows = rows.copy()
    gaps = exact_gaps(rows)
    size = {case_id: smallest_size(cases[case_id]) for case_id in rows["case_id"].unique()}
    rows["gap"] = [gaps.get(c, math.nan) for c in rows["case_id"]]
    rows["allowed"] = [profile.allowed(q, size[c])
                       for q, c in zip(rows["quantity"], rows["case_id"], strict=True)]
    errors = pd.to_numeric(rows["error"], errors="coerce")
    rows["measure"] = [measure(q, e, g) for q, e, g in
                       zip(rows["quantity"], errors, rows["gap"], strict=True)]
    categories = rows["category"].fillna("").astype(str)
    rows["judgment"] = [
        judge(profile, s, q, c, e, g, a) for s, q, c, e, g, a in zip(
            rows["status"], rows["quantity"], categories, errors, rows["gap"],
            rows["allowed"], strict=True)]
    return rows
