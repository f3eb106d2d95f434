"""Columnar judging: one engine's answers on a batch of pair cases, judged as numpy columns.

:func:`judge_batch` gives the same verdicts as :func:`crosscheck.truth.score.judge`
called row by row (``tests/truth/test_columnar.py`` checks every field on the whole
suite), at a fraction of the cost: the per-record path spends 35-65 us per case
in Python (norms with ``math.fsum``, Fractions for box bounds, one Verdict per
quantity), more than fast engines take to answer.

For each quantity over the batch, the common row (a plain value and a defined
truth, both finite) gets its error and agree bound from vectorised formulas that
round exactly as the per-record ones do:

- a norm is ``sqrt`` of the correctly rounded sum of squares, as ``math.fsum``
  gives it: the squares are added with TwoSum, and the rare row whose rounding
  errors do not add exactly is recomputed with :func:`crosscheck.core.geometry.norm`;
- a box's deciding axes come from a float filter with a wide error margin; a
  box whose axes the filter cannot settle gets :func:`~crosscheck.truth.bounds.bound`;
- a case that sets its own tolerance gets :func:`~crosscheck.truth.bounds.bound`.

A row agrees when its error is within the bound.  A plain row beyond it gets its
category and reason from :func:`~crosscheck.truth.categories.categorize`, with the
same error and bound that ``judge`` would pass it; every other row (an absent or
Undefined value, an undefined truth, a non-finite number, a normal whose length is not 1
to float64) is judged by the per-record :func:`~crosscheck.truth.score.judge`
itself.  So statuses, categories and reasons are those of the per-record path by
construction.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import norm
from crosscheck.core.model import Observation, Status, Value, quantities_of
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase
from crosscheck.truth.bounds import K_ANGLE, K_LENGTH, K_VELOCITY, TINY, U, bound
from crosscheck.truth.categories import categorize
from crosscheck.truth.score import Verdict, judge

F64 = NDArray[np.float64]
Mask = NDArray[np.bool_]

FILTER_MARGIN = 64.0
"""A box axis is settled in float when its test clears ``FILTER_MARGIN * u * magnitude``
(the float gap is off by at most ``3 u`` of it)."""


@dataclass(frozen=True)
class Columns:
    """The verdicts of one engine on a batch: one row per case x quantity, case-major,
    quantities in report order (:func:`~crosscheck.core.model.quantities_of`)."""

    case: list[int]
    """The index of each row's case in the batch."""
    quantity: list[str]
    status: list[Status]
    error: F64
    tolerance: F64
    category: list[str]
    reason: list[str]
    error_at_contact: F64

    def verdict(self, row: int) -> Verdict:
        """Row ``row`` as the per-record :class:`~crosscheck.truth.score.Verdict`."""
        return Verdict(self.status[row], float(self.error[row]), float(self.tolerance[row]),
                       self.category[row], self.reason[row], float(self.error_at_contact[row]))


def judge_batch(cases: Sequence[PairCase], conventions: Conventions,
                observations: Sequence[Observation], truths: Sequence[Observation]) -> Columns:
    """Judge every quantity of ``observations[i]`` (one engine's) against ``truths[i]``,
    the exact truth of ``cases[i]`` as declared, as :func:`judge` does row by row."""
    index = [(i, q) for i, case in enumerate(cases) for q in quantities_of(case.kind_enum)]
    n = len(index)
    status: list[Status] = [Status.AGREE] * n
    error, tolerance, at_contact = np.full(n, math.nan), np.full(n, math.nan), np.full(n, math.nan)
    category, reason = [""] * n, [""] * n
    by_quantity: dict[str, list[int]] = {}
    for row, (_, q) in enumerate(index):
        by_quantity.setdefault(q, []).append(row)
    for q, rows in by_quantity.items():
        at = [index[r][0] for r in rows]
        sub = [cases[i] for i in at]
        values = [observations[i].get(q) for i in at]
        wants = [truths[i].get(q) for i in at]
        err, tol = _fast(q, sub, values, wants, [truths[i] for i in at])
        agree = err <= tol
        error[rows] = np.where(agree, err, math.nan)
        tolerance[rows] = np.where(agree, tol, math.nan)
        for k in np.flatnonzero(~agree).tolist():
            i, row = at[k], rows[k]
            v = _disagree(cases[i], conventions, q, values[k], truths[i], observations[i],
                          float(err[k]), float(tol[k]))
            status[row], error[row], tolerance[row] = v.status, v.error, v.tolerance
            category[row], reason[row], at_contact[row] = v.category, v.reason, v.error_at_contact
    return Columns([i for i, _ in index], [q for _, q in index], status, error, tolerance,
                   category, reason, at_contact)


def _disagree(case: PairCase, conventions: Conventions, q: str, value: Value | None,
              truth: Observation, observation: Observation, err: float, tol: float) -> Verdict:
    """The verdict of a row that does not agree: a plain row (its error and bound are
    judge's) goes straight to ``categorize`` as judge would send it; any other to judge."""
    if math.isnan(err) or math.isnan(tol):
        return judge(case, conventions, q, value, truth, observation)
    assert value is not None
    explained = categorize(case, conventions, q, value, err, truth, observation, tol)
    return Verdict(Status.DISAGREE, err, tol, explained.category, explained.reason,
                   explained.error_at_contact)


def _fast(q: str, cases: list[PairCase], values: list[Value | None], wants: list[Value | None],
          truths: list[Observation]) -> tuple[F64, F64]:
    """Errors and agree bounds of the plain rows; NaN error where the row needs ``judge``."""
    if q == "hit":
        err = np.array([(0.0 if v == w else 1.0) if type(v) is bool and type(w) is bool
                        else math.nan for v, w in zip(values, wants, strict=True)])
        return err, np.zeros(len(err))
    if q == "distance":
        err = np.array([abs(v - w) if type(v) is float and type(w) is float else math.nan
                        for v, w in zip(values, wants, strict=True)])
        err[~np.isfinite(err)] = math.nan
        return err, _length_bounds(q, cases, truths, err)
    plain = [type(v) is tuple and type(w) is tuple and len(v) == len(w) and 2 <= len(v) <= 3
             for v, w in zip(values, wants, strict=True)]
    ok = np.array(plain, dtype=bool)
    vs = _padded([v if p else (0.0, 0.0) for v, p in zip(values, plain, strict=True)])
    ws = _padded([w if p else (0.0, 0.0) for w, p in zip(wants, plain, strict=True)])
    diff = _norms(vs - ws)
    if q == "normal":
        # a normal not of length 1 to float64 is judged per record (its length against the
        # engine's precision, then by its direction): bounds.unit_allowance, score.judge
        unit = np.abs(_norms(vs) - 1.0) <= K_ANGLE * U
        err = np.array([2.0 * math.asin(min(1.0, d / 2.0)) for d in diff.tolist()])
        err[~(ok & unit & np.isfinite(err) & np.isfinite(diff))] = math.nan
        return err, _length_bounds(q, cases, truths, err)
    diff[~(ok & np.isfinite(diff))] = math.nan
    return diff, _velocity_bounds(q, cases, diff)


def _padded(vectors: Sequence[Any]) -> F64:
    """2- and 3-vectors as rows of an (n, 3) array (a 2-vector gets z = 0, which adds 0 to
    every sum of squares)."""
    return np.array([v if len(v) == 3 else (*v, 0.0) for v in vectors],
                    dtype=np.float64).reshape(-1, 3)


def _two_sum(a: F64, b: F64) -> tuple[F64, F64]:
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _norms(x: F64) -> F64:
    """``sqrt(fsum(row**2))`` of every row of ``x`` (n, 3), rounded as :func:`norm` rounds it."""
    with np.errstate(all="ignore"):
        sq = x * x
        s, e1 = _two_sum(sq[:, 0], sq[:, 1])
        t, e2 = _two_sum(s, sq[:, 2])
        g, r = _two_sum(e1, e2)
        out: F64 = np.sqrt(t + g)
    odd = np.flatnonzero(~((r == 0) & np.isfinite(out)) & np.isfinite(x).all(axis=1))
    for k in odd.tolist():  # the rounding errors did not add exactly: the exact sum, by fsum
        try:
            out[k] = norm(x[k].tolist())
        except OverflowError:  # fsum's intermediate overflow: judge() decides such a row
            out[k] = math.nan
    return out


def _velocity_bounds(q: str, cases: list[PairCase], err: F64) -> F64:
    """``bound(case, 'v1'|'v2')`` of every row."""
    tol = np.full(len(cases), math.nan)
    plain = [isinstance(c, ResponseCase) and c.tolerance is None for c in cases]
    rows = [k for k, p in enumerate(plain) if p]
    if rows:
        moving = [cast(ResponseCase, cases[k]) for k in rows]
        va = _norms(_padded([c.a.velocity for c in moving]))
        vb = _norms(_padded([c.b.velocity for c in moving]))
        with np.errstate(all="ignore"):
            tol[rows] = K_VELOCITY * (U * (va + vb) + TINY)
    _by_record(q, cases, err, tol, [not p for p in plain])
    return _finite(tol)


def _length_bounds(q: str, cases: list[PairCase], truths: list[Observation], err: F64) -> F64:
    """``bound(case, 'distance'|'normal', gap)`` of every row: spheres and boxes in columns,
    a case with its own tolerance (or an unsettled box) by record."""
    tol = np.full(len(cases), math.nan)
    spheres = [k for k, c in enumerate(cases)
               if c.tolerance is None and not isinstance(c, AabbCase)]
    if spheres:
        tol[spheres] = _sphere_bounds(q, [cases[k] for k in spheres])
    for dim in (2, 3):  # boxes of one dimension at a time: an axis is never padded
        boxes = [k for k, c in enumerate(cases)
                 if c.tolerance is None and isinstance(c, AabbCase) and c.dim == dim]
        if boxes:
            gaps = np.array([_gap(truths[k]) for k in boxes])
            tol[boxes] = _box_bounds(q, [cast(AabbCase, cases[k]) for k in boxes], gaps)
    _by_record(q, cases, err, tol, [c.tolerance is not None for c in cases], truths)
    return _finite(tol)


def _by_record(q: str, cases: list[PairCase], err: F64, tol: F64, which: list[bool],
               truths: list[Observation] | None = None) -> None:
    """``bound`` itself for the rows in ``which`` (or unsettled) whose error is plain."""
    for k, case in enumerate(cases):
        if (which[k] or math.isnan(tol[k])) and not math.isnan(err[k]):
            tol[k] = bound(case, q, _gap(truths[k]) if truths else math.nan)


def _gap(truth: Observation) -> float:
    return truth.distance if isinstance(truth.distance, float) else math.nan


def _finite(x: F64) -> F64:
    x[~np.isfinite(x)] = math.nan
    return x


def _sphere_bounds(q: str, cases: list[PairCase]) -> F64:
    if q == "normal":
        return np.full(len(cases), K_ANGLE * U)
    a = _padded([c.a.center for c in cases])
    b = _padded([c.b.center for c in cases])
    r = np.array([(c.a.radius, c.b.radius) for c in cases],  # type: ignore[union-attr]
                 dtype=np.float64)
    with np.errstate(all="ignore"):
        length = _norms(b - a) + r[:, 0] + r[:, 1]
        out: F64 = K_LENGTH * (U * length + TINY)
    return out


def _box_bounds(q: str, cases: list[AabbCase], gaps: F64) -> F64:
    """The box bounds where the float filter settles the deciding axes; NaN elsewhere."""
    length, separated = _box_lengths(cases)
    with np.errstate(all="ignore"):
        scaled = K_LENGTH * (U * length + TINY)
        if q == "distance":
            return scaled
        scaled = _finite(scaled)  # bound's _finite, before the tilt
        tilt = K_ANGLE * U + np.minimum(math.pi, scaled / gaps)
    out: F64 = np.where(gaps > 0, tilt, np.where(separated | np.isnan(gaps), math.nan,
                                                 K_ANGLE * U))
    out[np.isnan(length)] = math.nan
    return out


def _box_lengths(cases: list[AabbCase]) -> tuple[F64, Mask]:
    """Per case: ``length_magnitude`` (the largest magnitude of the deciding axes) where the
    float filter settles which axes decide, NaN elsewhere; and whether the boxes are apart.

    Apart (some axis surely separated): the axes whose gap is above minus the slack,
    each surely on its side.  Overlapping (every axis surely overlapping): the axis of least
    overlap alone, when it leads the next by far more than rounding (were another within
    rounding of it, both would decide and the normal could point anywhere: ``bound``
    decides such a case).
    """
    ca, cb, ha, hb = (np.array([getattr(getattr(c, side), name) for c in cases],
                               dtype=np.float64)
                      for side, name in (("a", "center"), ("b", "center"), ("a", "half"),
                                         ("b", "half")))
    with np.errstate(all="ignore"):
        gap = (np.abs(cb - ca) - ha) - hb  # within 3 u x mag of the exact gap
        mag = (np.abs(cb - ca) + ha) + hb  # what bounds.length_magnitude combines
        margin = FILTER_MARGIN * U * mag
        separated: Mask = np.asarray((gap > margin).any(axis=1))
        overlapping = (gap < -margin).all(axis=1)
        x = gap + K_LENGTH * U * mag
        apart_length = np.where(x > 0, mag, -np.inf).max(axis=1)
        apart_sure = (np.abs(x) > margin).all(axis=1)
        top = np.sort(gap, axis=1)
        least_sure = (top[:, -1] - top[:, -2]) > 2 * FILTER_MARGIN * U * mag.max(axis=1)
        least_length = mag[np.arange(len(cases)), np.argmax(gap, axis=1)]
    length: F64 = np.where(separated, apart_length, least_length)
    sure = np.where(separated, apart_sure, overlapping & least_sure) & np.isfinite(mag).all(axis=1)
    length[~sure] = math.nan
    return length, separated
