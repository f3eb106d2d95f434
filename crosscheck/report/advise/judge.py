"""``advise``'s rules for one answer (case x engine x quantity) under a scene profile.

Each row gets a *judgment*:

- ``within``: ``agree``; ``undefined`` (the truth itself is undefined); or
  ``disagree`` by at most the accuracy allowed (:meth:`Envelope.allowed`: the tolerance of
  the quantity's unit).  A ``hit`` verdict is judged by the pair's exact gap: a wrong verdict
  on a pair whose exact |gap| is within the accuracy is within it, as a distance error of
  that size would be;
- ``convention``: a ``disagree`` the engine's declared conventions explain (category
  ``convention``) where every convention it rests on is a *definition*
  (:class:`~crosscheck.core.conventions.Nature`: a touching rule, the reading of an input,
  a declared no-value rule; :func:`crosscheck.truth.convention_fields.nature`).  It is
  reported with its numbers and fails only when the profile says it matters:
  ``touching_contact`` for a hit verdict on a touching pair (exact gap 0),
  ``strict_conventions`` for every definition (then judged as below).  A convention that
  is a *behaviour* (damping, soft contact, a restitution threshold, a speed cap, a rest
  band) changes the outcome asked for: its row is judged on its error like any answer;
- ``wrong``: a ``disagree`` beyond the accuracy;
- ``failed``: ``error``, ``crash`` or ``timeout``;
- ``skip``: not an answer; rows of quantities the profile leaves out are dropped.

>>> p = Envelope(tolerance=1e-9)
>>> judge(p, "disagree", "hit", "tolerance", 1.0, gap=1e-12, allowed=1e-9)
'within'
>>> judge(p, "disagree", "hit", "error", 1.0, gap=0.5, allowed=1e-9)
'wrong'
>>> judge(p, "disagree", "hit", "convention", 1.0, gap=0.0, allowed=1e-9, nature=DEFINITION)
'convention'
>>> judge(Envelope(touching_contact=True), "disagree", "hit", "convention", 1.0, 0.0, 0.0,
...       nature=DEFINITION)
'wrong'
>>> judge(p, "disagree", "energy_drift", "convention", 0.9, math.nan, 1e-3, nature=BEHAVIOUR)
'wrong'
>>> judge(p, "timeout", "v1", "", math.nan, gap=math.nan, allowed=1e-9)
'failed'
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from crosscheck.core.conventions import Conventions, Nature
from crosscheck.core.model import Category, Status
from crosscheck.core.schema import AnyCase
from crosscheck.report.advise.profile import Envelope, smallest_size
from crosscheck.results.run import DECODED
from crosscheck.truth import convention_fields
from crosscheck.truth.bounds import failed

WITHIN, CONVENTION, WRONG, FAILED, SKIP = "within", "convention", "wrong", "failed", "skip"
DEFINITION, BEHAVIOUR = str(Nature.DEFINITION), str(Nature.BEHAVIOUR)


def judge(profile: Envelope, status: str, quantity: str, category: str, error: float,
          gap: float, allowed: float, *, nature: str = "") -> str:
    """The judgment of one row (see the module docstring); ``nature``: what a ``convention``
    row rests on (anything but :data:`DEFINITION`: judged on its error)."""
    if status == Status.SKIP:
        return SKIP
    if status in (Status.AGREE, Status.UNDEFINED):
        return WITHIN
    if status != Status.DISAGREE:
        return FAILED
    excused = category == Category.CONVENTION and nature == DEFINITION
    if excused and not profile.strict_conventions:
        touching = quantity == "hit" and gap == 0.0
        return WRONG if touching and profile.touching_contact else CONVENTION
    return WITHIN if measure(quantity, error, gap) <= allowed else WRONG


def engine_conventions(engines: Sequence[Mapping[str, Any]]) -> dict[str, Conventions]:
    """Each engine's declared conventions, as its run recorded them (``run.json``)."""
    return {str(e["name"]): Conventions.from_json(dict(e.get("conventions") or {}))
            for e in engines}


def no_value(value: Any) -> bool:
    """Whether a stored answer (its decoded ``value``) has no finite value: none at all, a
    number that is not finite or the largest double (what a declared no-value rule speaks for).

    >>> no_value(None), no_value([1.0, math.nan]), no_value([1.0, 0.0]), no_value(True)
    (True, True, False, False)
    """
    if value is None:
        return True
    return failed(tuple(value) if isinstance(value, list) else value)


def natures(rows: pd.DataFrame, cases: Mapping[str, AnyCase],
            conventions: Mapping[str, Conventions]) -> list[str]:
    """Per row, what a ``convention`` row rests on (:data:`DEFINITION` or :data:`BEHAVIOUR`;
    '' for any other row); ``rows`` carry their decoded values
    (:func:`crosscheck.results.run.decoded`)."""
    out = []
    for case_id, engine, category, value in zip(rows["case_id"], rows["engine"],
                                                rows["category"], rows[DECODED["value"]],
                                                strict=True):
        if category != Category.CONVENTION:
            out.append("")
            continue
        conv = conventions.get(str(engine), Conventions())
        out.append(str(convention_fields.nature(cases[str(case_id)], conv, no_value(value))))
    return out


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


def judged(rows: pd.DataFrame, cases: Mapping[str, AnyCase], profile: Envelope,
           conventions: Mapping[str, Conventions]) -> pd.DataFrame:
    """``rows`` (of the quantities that matter, with their decoded values) with ``gap``,
    ``allowed``, ``measure``, ``nature`` and ``judgment`` columns; ``conventions``: each
    engine's declared ones."""
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
    rows["category"] = rows["category"].fillna("").astype(str)
    rows["nature"] = natures(rows, cases, conventions)
    rows["judgment"] = [
        judge(profile, s, q, c, e, g, a, nature=n) for s, q, c, e, g, a, n in zip(
            rows["status"], rows["quantity"], rows["category"], errors, rows["gap"],
            rows["allowed"], rows["nature"], strict=True)]
    return rows
