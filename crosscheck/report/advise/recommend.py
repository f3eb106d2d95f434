"""Which engine for my scene: a graded, ranked answer from a stored run.

The user states a scene profile (:mod:`crosscheck.report.advise.profile`);
:func:`advise` judges every answer of the run's in-envelope cases under it
(:mod:`crosscheck.report.advise.judge`) and grades each engine variant
(:mod:`crosscheck.report.advise.grade`).  The answer is never empty:

1. ``passing``: engines that answer every case of the envelope within the
   needed accuracy, cheapest first: by median instructions per query when every
   passing engine was counted (``crosscheck run --timer instructions``), else by
   median wall-clock query time (``cost_by`` says which);
2. ``partial``: engines within the accuracy on the part they answer, the most
   coverage first (``parts`` says which part);
3. ``failing``: the others, by the share of the *whole envelope* they answer
   within the accuracy (skipping never helps), then by cost (each tier's ties are
   broken by instructions when every engine of the tier was counted, else by time);
4. ``unsupported``: engines that answer no case (a 2-D-only engine for a 3-D
   scene): listed, never ranked;
5. ``baselines``: the textbook formulas (``reference``, ``reference-f32``),
   graded alike but shown apart, never contenders.

A float32 engine ranks only when the profile accepts float32 (else it is
listed under ``excluded``).  When nothing passes, ``closest`` names the best
ranked engine and the few cases that decide it.

The answer says what it rests on: the envelope's cases (``cases``), the cases each engine
answers (``rests_on``) and the cells of the configuration space they cover (``cells``), and
the cases of the envelope the run never asked because it was a
``--quick`` run (``not_asked``: scenes over
:data:`~crosscheck.core.options.QUICK_SCENE_STEPS` steps, left out of the envelope).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import pandas as pd

from crosscheck.cases.cover import coverage
from crosscheck.core.model import PAIR_KINDS
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.report.advise.grade import (
    FAILS,
    PARTIAL,
    PASSES,
    UNSUPPORTED,
    EngineAdvice,
    Mode,
    Part,
    Worst,
    grade,
)
from crosscheck.report.advise.judge import engine_conventions, judged
from crosscheck.report.advise.profile import Envelope, EnvelopeError
from crosscheck.report.cells import cell_of
from crosscheck.report.cost import by_counts, rank
from crosscheck.results.run import Run

__all__ = ["INSTRUCTIONS", "WALL", "Advice", "EngineAdvice", "Envelope", "EnvelopeError", "Mode",
           "Part", "Worst", "advise"]

DECIDING = 5
"""Cases named as deciding the closest engine when nothing passes."""
INSTRUCTIONS, WALL = "instructions", "wall"
"""What a tier's cost is: median instructions per query, or median wall-clock time."""


@dataclass(frozen=True)
class Advice:
    """The answer (see the module docstring)."""

    envelope: Envelope
    kinds: tuple[str, ...]
    dims: tuple[int, ...]
    quantities: tuple[str, ...]
    cases: int
    """Cases of the run inside the envelope."""
    bad_input_cases: int
    """Bad-input cases of the same kinds and dimensions: each engine's robustness."""
    passing: list[EngineAdvice] = field(default_factory=list)
    partial: list[EngineAdvice] = field(default_factory=list)
    failing: list[EngineAdvice] = field(default_factory=list)
    unsupported: list[EngineAdvice] = field(default_factory=list)
    excluded: list[EngineAdvice] = field(default_factory=list)
    """Float32 engines when the profile does not accept float32."""
    baselines: list[EngineAdvice] = field(default_factory=list)
    closest: str | None = None
    """When nothing passes: the best ranked engine."""
    deciding: tuple[str, ...] = ()
    """When nothing passes: the cases that keep ``closest`` from passing."""
    repeat_checked: bool = False
    """Whether the run made the repeat check (each engine's ``repeated`` and
    ``nondeterministic`` say what it found in the envelope)."""
    cost_by: str = WALL
    """How ``passing`` is ordered, cheapest first: :data:`INSTRUCTIONS` (every passing engine
    was counted) or :data:`WALL`."""
    quick: bool = False
    """Whether the run was a ``--quick`` run (no timing phase, long scenes not asked)."""
    not_asked: int = 0
    """Cases inside the profile that the run asked no engine (``--quick``): not in ``cases``."""
    rests_on: dict[str, int] = field(default_factory=dict)
    """The cases each engine's grade rests on (those it answers), by engine."""
    cells: dict[str, tuple[int, int]] = field(default_factory=dict)
    """Per kind and dimension (``aabb 3-D``): the 2-way cells of the configuration space
    (:mod:`crosscheck.cases.space`) the answer's cases cover, of all its cells."""

    @property
    def passing_order(self) -> str:
        """How :attr:`passing` is listed, in words: cheapest first (by instructions per query
        when :attr:`cost_by` says so) when one of them has a cost, else in run order (none
        was timed: a ``--quick`` run, or none in the timing sample)."""
        if all(e.median_query_s is None and e.median_query_instructions is None
               for e in self.passing):
            return "none timed: in run order"
        return "cheapest first" + (" by instructions per query"
                                   if self.cost_by == INSTRUCTIONS else "")

    @property
    def ranking(self) -> list[EngineAdvice]:
        """The contenders, best first: passing, then partial, then failing."""
        return self.passing + self.partial + self.failing

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (missing numbers are None, never NaN)."""
        data: dict[str, Any] = _json_safe(asdict(self))
        data["ranking"] = [e.engine for e in self.ranking]
        return data


def _json_safe(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_json_safe(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def requested_kinds(run: Run, envelope: Envelope) -> tuple[str, ...]:
    """The envelope's kinds, or every pair kind the run holds; EnvelopeError if one is absent."""
    present = [str(k) for k in run.results["kind"].unique()]
    for kind in envelope.kinds:
        if kind not in present:
            raise EnvelopeError("--kind", f"the run holds no {kind} cases "
                                          f"(it holds {', '.join(sorted(present))})")
    return envelope.kinds or tuple(k for k in PAIR_KINDS if k in present)


def envelope_rows(run: Run, envelope: Envelope
                  ) -> tuple[pd.DataFrame, pd.DataFrame, int]:
    """The judged rows of the in-envelope cases of the requested kinds, the rows of the
    bad-input cases of those kinds and dimensions, and how many in-envelope cases the run
    asked no engine (``--quick``)."""
    kinds = requested_kinds(run, envelope)
    carried = {tag for case in run.cases.values() for tag in case.tags}
    for tag in envelope.tags:
        if tag not in carried:
            raise EnvelopeError("--tag", f"no case of the run carries the tag {tag!r} "
                                         f"(its tags: {', '.join(sorted(carried)) or 'none'})")
    mine = {i: c for i, c in run.cases.items() if c.kind_enum in kinds
            and (not envelope.dims or c.dim in envelope.dims)}
    inside = {i for i, c in mine.items() if envelope.holds(c)}
    not_asked = {i for i in inside if isinstance(case := mine[i], SceneCase)
                 and run.info.options.skips(case.step_count)}
    bad = {i for i, c in mine.items() if c.bad_input}
    results = run.results
    rows = judged(results[results["case_id"].isin(inside - not_asked)].join(run.decoded),
                  run.cases, envelope, engine_conventions(run.info.engines))
    return rows, results[results["case_id"].isin(bad)], len(not_asked)


def advise(run: Run, envelope: Envelope) -> Advice:
    """The graded, ranked answer of ``run`` for the scene ``envelope`` describes."""
    envelope.check()
    rows, bad, not_asked = envelope_rows(run, envelope)
    kinds = tuple(k for k in requested_kinds(run, envelope) if k in set(rows["kind"]))
    dims = tuple(sorted(int(d) for d in rows["dim"].unique()))
    cases = int(rows["case_id"].nunique())
    rows_of, bad_of = _by_engine(rows), _by_engine(bad)
    grades = [grade(run, name, rows_of.get(name, rows.iloc[:0]), cases,
                    bad_of.get(name, bad.iloc[:0]))
              for name in run.info.engine_names]
    contenders = [g for g in grades if not g.baseline and g.tier != UNSUPPORTED
                  and (envelope.float32 or not g.float32)]

    def tier(name: str, first: Callable[[EngineAdvice], int]) -> list[EngineAdvice]:
        """The contenders of a tier (in run order), by ``first`` then cost (in the tier's
        measure)."""
        return rank([g for g in contenders if g.tier == name], lambda g: g.measure,
                    first).items

    passing = tier(PASSES, lambda g: 0)
    partial = tier(PARTIAL, lambda g: -g.answered)
    failing = tier(FAILS, lambda g: -g.within)
    closest = None if passing or not (partial or failing) else (partial + failing)[0]
    return Advice(
        envelope, kinds, dims, tuple(dict.fromkeys(rows["quantity"])), cases,
        int(bad["case_id"].nunique()), passing, partial, failing,
        unsupported=[g for g in grades if not g.baseline and g.tier == UNSUPPORTED],
        excluded=[g for g in grades if not g.baseline and g.tier != UNSUPPORTED
                  and g.float32 and not envelope.float32],
        baselines=[g for g in grades if g.baseline],
        closest=None if closest is None else closest.engine,
        deciding=() if closest is None else _deciding(closest),
        repeat_checked=run.info.repeat_check is not None,
        cost_by=INSTRUCTIONS if by_counts(g.measure for g in passing) else WALL,
        quick=run.info.options.quick, not_asked=not_asked,
        rests_on={g.engine: g.answered for g in grades},
        cells=cells_of([run.cases[i] for i in rows["case_id"].unique()]))


def _by_engine(rows: pd.DataFrame) -> dict[str, pd.DataFrame]:
    """The rows of each engine, split once (not a mask over every row per engine)."""
    return {str(engine): group for engine, group in rows.groupby("engine", sort=False)}


def cells_of(cases: Sequence[AnyCase]) -> dict[str, tuple[int, int]]:
    """The 2-way cells of the configuration space ``cases`` cover, per kind and dimension
    that holds one of them (scenes have no space)."""
    return {f"{c.kind.value} {c.dim}-D": (c.covered, c.cells)
            for c in coverage(cases, 2, cell_of) if c.cases}


def _deciding(engine: EngineAdvice) -> tuple[str, ...]:
    """The failing cases of a failing engine, or the parts a partial one skips."""
    if engine.failing_cases:
        return engine.failing_cases[:DECIDING]
    return tuple(f"{p.kind} {p.dim}-D: {p.cases - p.answered} of {p.cases} cases skipped"
                 for p in engine.parts if p.answered < p.cases)[:DECIDING]
