"""Which engine for my scene: the engines that pass every stored case inside an envelope.

The user states the scene's envelope (dimensions, kinds, body sizes, distance
from the origin, speeds, mass ratios) and the accuracy it needs; :func:`advise`
reads a stored run and answers with the engine variants that pass every case
of the run inside that envelope, cheapest first, and names the cases that rule
each other engine out.  Cases are placed inside or outside the envelope from
their own typed inputs, never from their ids.

An answer (one row: case x engine x quantity) *passes* when its status is
``agree``; ``undefined`` (the truth itself is undefined); or ``disagree`` with
an error within the stated tolerance, except a wrong ``hit`` verdict, which
never passes.  ``error``, ``crash`` and ``timeout`` always fail; ``skip`` rows
are not answers and are left out, but an engine that skips a whole requested
kind or dimension is not recommended.

>>> row_passes("disagree", "distance", 0.5, 1.0), row_passes("disagree", "hit", 1.0, 2.0)
(True, False)
>>> row_passes("undefined", "normal", float("nan"), None), row_passes("timeout", "v1", 0.0, 1.0)
(True, False)
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import pandas as pd

from crosscheck.core.model import PAIR_KINDS, Status
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SceneCase
from crosscheck.results.store import StoredRun

CULPRITS = 3
"""Cases named per engine that is ruled out."""


class EnvelopeError(ValueError):
    """An envelope that cannot hold any scene; ``option`` names the offending option."""

    def __init__(self, option: str, message: str) -> None:
        super().__init__(f"{option}: {message}")
        self.option = option


@dataclass(frozen=True)
class Envelope:
    """The scene's envelope and the accuracy it needs; ``None`` or empty: no limit.

    >>> Envelope(scale=(5.0, 1.0)).check()
    Traceback (most recent call last):
    ...
    crosscheck.report.advise.EnvelopeError: --scale: LO must be <= HI, got 5.0:1.0
    """

    dims: tuple[int, ...] = ()
    kinds: tuple[str, ...] = ()
    scale: tuple[float, float] | None = None
    offset: float | None = None
    speed: float | None = None
    mass_ratio: float | None = None
    tolerance: float | None = None
    include_bad_input: bool = False

    def check(self) -> None:
        """Raise :class:`EnvelopeError` naming the option if a limit is impossible."""
        for dim in self.dims:
            if dim not in (2, 3):
                raise EnvelopeError("--dim", f"must be 2 or 3, got {dim}")
        if self.scale is not None:
            lo, hi = self.scale
            _non_negative("--scale", lo)
            _non_negative("--scale", hi)
            if lo > hi:
                raise EnvelopeError("--scale", f"LO must be <= HI, got {lo}:{hi}")
        for option, value in (("--offset", self.offset), ("--speed", self.speed),
                              ("--tolerance", self.tolerance)):
            if value is not None:
                _non_negative(option, value)
        if self.mass_ratio is not None and not self.mass_ratio >= 1.0:
            raise EnvelopeError("--mass-ratio", f"must be a number >= 1, got {self.mass_ratio}")

    def holds(self, case: AnyCase) -> bool:
        """Whether the case's own inputs lie inside this envelope."""
        if case.bad_input and not self.include_bad_input:
            return False
        if self.dims and case.dim not in self.dims:
            return False
        return (_within_scale(case, self.scale) and _within(centres(case), self.offset)
                and _within(velocity_components(case), self.speed)
                and _within([mass_ratio(case)], self.mass_ratio))


def _non_negative(option: str, value: float) -> None:
    if not (math.isfinite(value) and value >= 0.0):
        raise EnvelopeError(option, f"must be a finite number >= 0, got {value}")


def _within(values: Iterable[float], limit: float | None) -> bool:
    """Every |value| <= limit (NaN is never within); no limit: True."""
    return limit is None or all(abs(v) <= limit for v in values)


def _within_scale(case: AnyCase, scale: tuple[float, float] | None) -> bool:
    return scale is None or all(scale[0] <= s <= scale[1] for s in sizes(case))


def _bodies(case: AnyCase) -> tuple[Any, ...]:
    return case.bodies if isinstance(case, SceneCase) else (case.a, case.b)


def sizes(case: AnyCase) -> list[float]:
    """Each body's size: its radius, or its largest half-width (NaN if any is NaN).

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> sizes(CASE_ADAPTER.validate_python({"id": "b", "description": "d", "kind": "aabb",
    ...     "dim": 2, "a": {"center": [0, 0], "half": [1, 3]},
    ...     "b": {"center": [5, 0], "half": [2, 2]}}))
    [3.0, 2.0]
    """
    if isinstance(case, AabbCase):
        return [math.nan if any(math.isnan(h) for h in body.half) else max(body.half)
                for body in (case.a, case.b)]
    return [float(body.radius) for body in _bodies(case)]


def centres(case: AnyCase) -> list[float]:
    """Every centre coordinate of every body."""
    return [float(c) for body in _bodies(case) for c in body.center]


def velocity_components(case: AnyCase) -> list[float]:
    """Every velocity component of every body (none for detection cases)."""
    if not isinstance(case, ResponseCase | SceneCase):
        return []
    return [float(v) for body in _bodies(case) for v in body.velocity]


def mass_ratio(case: AnyCase) -> float:
    """max(m) / min(m) of the bodies (1 for detection cases; inf when a mass is <= 0)."""
    if not isinstance(case, ResponseCase | SceneCase):
        return 1.0
    masses = [float(body.mass) for body in _bodies(case)]
    if any(math.isnan(m) for m in masses):
        return math.nan
    return max(masses) / min(masses) if min(masses) > 0.0 else math.inf


def row_passes(status: str, quantity: str, error: float, tolerance: float | None) -> bool:
    """Whether one answer is good enough for the scene (see the module docstring)."""
    if status in (Status.AGREE, Status.UNDEFINED):
        return True
    if status != Status.DISAGREE or quantity == "hit" or tolerance is None:
        return False
    return bool(error <= tolerance)


@dataclass(frozen=True)
class Culprit:
    """A case that rules an engine out: its worst failing answer there."""

    case_id: str
    quantity: str
    status: str
    category: str
    error: float | None


@dataclass(frozen=True)
class EngineAdvice:
    """One engine variant's verdict inside the envelope."""

    engine: str
    cases: int
    """In-envelope cases it answered (some quantity not ``skip``)."""
    median_query_s: float | None
    """Median query time over its timed in-envelope cases; None: none timed."""
    failing_cases: int
    culprits: tuple[Culprit, ...] = ()
    """Up to :data:`CULPRITS` failing cases, the worst first."""
    unsupported: tuple[str, ...] = ()
    """Requested kinds and dimensions it skips entirely, such as ``sphere_response`` or ``3-D``."""

    @property
    def passes(self) -> bool:
        return not self.failing_cases and not self.unsupported and self.cases > 0


@dataclass(frozen=True)
class Advice:
    """The answer: engines that pass (cheapest first), then the others (fewest failures first)."""

    envelope: Envelope
    kinds: tuple[str, ...]
    dims: tuple[int, ...]
    cases: int
    """Cases of the run inside the envelope."""
    passing: list[EngineAdvice] = field(default_factory=list)
    failing: list[EngineAdvice] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (missing numbers are None, never NaN)."""
        data: dict[str, Any] = _json_safe(asdict(self))
        return data


def _json_safe(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_json_safe(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def requested_kinds(run: StoredRun, envelope: Envelope) -> tuple[str, ...]:
    """The envelope's kinds, or every pair kind the run holds; EnvelopeError if one is absent."""
    present = [str(k) for k in run.results["kind"].unique()]
    for kind in envelope.kinds:
        if kind not in present:
            raise EnvelopeError("--kind", f"the run holds no {kind} cases "
                                          f"(it holds {', '.join(sorted(present))})")
    return envelope.kinds or tuple(k for k in PAIR_KINDS if k in present)


def envelope_rows(run: StoredRun, envelope: Envelope) -> pd.DataFrame:
    """The rows of the in-envelope cases of the requested kinds."""
    kinds = requested_kinds(run, envelope)
    inside = {case_id for case_id, case in run.cases.items()
              if case.kind_enum in kinds and envelope.holds(case)}
    rows = run.results[run.results["case_id"].isin(inside)].copy()
    rows["passes"] = pd.Series(
        [row_passes(s, q, e, envelope.tolerance) for s, q, e in
         zip(rows["status"], rows["quantity"], rows["error"], strict=True)],
        index=rows.index, dtype=bool)
    return rows


def advise(run: StoredRun, envelope: Envelope) -> Advice:
    """Which engines pass every case of ``run`` inside ``envelope``, cheapest first."""
    envelope.check()
    rows = envelope_rows(run, envelope)
    kinds = tuple(k for k in requested_kinds(run, envelope) if k in set(rows["kind"]))
    dims = tuple(sorted(int(d) for d in rows["dim"].unique()))
    verdicts = [_engine_advice(name, rows[rows["engine"] == name], kinds, dims)
                for name in run.info.engine_names]
    order = {name: i for i, name in enumerate(run.info.engine_names)}
    passing = sorted((v for v in verdicts if v.passes), key=lambda v: (
        v.median_query_s is None, v.median_query_s or 0.0, order[v.engine]))
    failing = sorted((v for v in verdicts if not v.passes), key=lambda v: (
        bool(v.unsupported), v.failing_cases, order[v.engine]))
    return Advice(envelope, kinds, dims, int(rows["case_id"].nunique()), passing, failing)


def _engine_advice(engine: str, rows: pd.DataFrame, kinds: Sequence[str],
                   dims: Sequence[int]) -> EngineAdvice:
    answered = rows[rows["status"] != Status.SKIP]
    failed = answered[~answered["passes"]]
    return EngineAdvice(
        engine=engine, cases=int(answered["case_id"].nunique()),
        median_query_s=_median_query(answered), failing_cases=int(failed["case_id"].nunique()),
        culprits=_culprits(failed), unsupported=_unsupported(answered, kinds, dims))


def _median_query(rows: pd.DataFrame) -> float | None:
    times = rows.drop_duplicates("case_id")["query_s"].dropna()
    return float(times.median()) if len(times) else None


def _unsupported(answered: pd.DataFrame, kinds: Sequence[str],
                 dims: Sequence[int]) -> tuple[str, ...]:
    kinds_done, dims_done = set(answered["kind"]), set(answered["dim"])
    return (tuple(k for k in kinds if k not in kinds_done)
            + tuple(f"{d}-D" for d in dims if d not in dims_done))


def _culprits(failed: pd.DataFrame) -> tuple[Culprit, ...]:
    """Each failing case once, by its worst row: most severe status, then largest error."""
    if failed.empty:
        return ()
    ranked = failed.assign(
        severity=[Status(s).severity for s in failed["status"]],
        hit_first=failed["quantity"] != "hit",
        magnitude=-failed["error"].fillna(math.inf))
    ranked = ranked.sort_values(["severity", "hit_first", "magnitude"], kind="stable")
    worst = ranked.drop_duplicates("case_id").head(CULPRITS)
    return tuple(Culprit(str(r["case_id"]), str(r["quantity"]), str(r["status"]),
                         str(r["category"]), _finite(r["error"]))
                 for r in worst.to_dict("records"))


def _finite(value: Any) -> float | None:
    number = float(value)
    return number if math.isfinite(number) else None
