"""The facts the report's "Which engine for my scene" form judges by, beside the results
table's packed rows.

The form in the page runs :func:`crosscheck.report.advise.recommend.advise`'s rules in JavaScript
(``_advise.html.j2``) over the results table's data; what a case's rows do not carry is
computed here, by the same functions the Python answer uses: each case's place in an
envelope (kind, dimension, tags, bad input, its smallest and largest extent, largest
|coordinate|, largest body speed, mass ratio; a scene's time step, per-step travel and
simulated time, and whether the run asked it at all; a time of impact's interval), the
length ``rtol`` is relative to, and its exact gap; each quantity's unit and the options
that apply to some kinds only; each engine's role (baseline, float32); and the
``convention`` rows that rest on a definition (the others are judged on their error).  A
number that is not finite is ``None`` (JSON has no NaN): the form then treats the case as
outside every finite limit, as the Python rules do.

>>> from crosscheck.core.schema import CASE_ADAPTER
>>> case = CASE_ADAPTER.validate_python({"id": "s", "description": "d", "kind": "sphere",
...     "dim": 3, "a": {"center": [0, 0, 0], "radius": 1}, "b": {"center": [3, 0, 0],
...     "radius": 0.5}})
>>> facts = case_facts(case, 1.5, asked=True)
>>> [facts[k] for k in ("kind", "dim", "lo", "hi", "size", "offset", "speed", "ratio")]
['sphere', 3, 0.5, 1.0, 0.5, 3.0, 0.0, 1.0]
>>> facts["gap"], facts["dt"], facts["travel"], facts["interval"], facts["lasts"]
(1.5, None, None, None, None)
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import pandas as pd

from crosscheck.core.model import PAIR_KINDS, Category, Kind, Status, quantities_of
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.report.advise.grade import is_float32
from crosscheck.report.advise.judge import DEFINITION, engine_conventions, exact_gaps, natures
from crosscheck.report.advise.profile import (
    centres,
    extents,
    interval,
    mass_ratio,
    simulated,
    smallest_size,
    speeds,
    step_travel,
    time_step,
)
from crosscheck.report.advise.units import KIND_OPTIONS, TOLERANCE_OPTIONS, UNITS
from crosscheck.report.profiles import BASELINES


def _finite(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None


def _largest(values: Iterable[float]) -> float | None:
    """max |value| (0 for none), None when one is not finite."""
    magnitudes = [abs(v) for v in values]
    return _finite(max(magnitudes, default=0.0)) if all(
        math.isfinite(m) for m in magnitudes) else None


def case_facts(case: AnyCase, gap: float, asked: bool) -> dict[str, Any]:
    """What the form needs of one case (see the module docstring); ``asked``: the run asked
    the engines this case (not a scene a ``--quick`` run left out)."""
    sizes = extents(case)
    finite = all(math.isfinite(s) for s in sizes)
    return {"kind": str(case.kind), "dim": case.dim, "bad": case.bad_input,
            "tags": list(case.tags), "asked": asked,
            "lo": min(sizes) if finite else None, "hi": max(sizes) if finite else None,
            "size": _finite(smallest_size(case)), "offset": _largest(centres(case)),
            "speed": _largest(speeds(case)), "ratio": _finite(mass_ratio(case)),
            "gap": _finite(gap), "dt": time_step(case), "travel": _finite(step_travel(case)),
            "interval": _finite(interval(case)), "lasts": simulated(case)}


def definitions(frame: pd.DataFrame, cases: Mapping[str, AnyCase],
                engines: Iterable[Mapping[str, Any]]) -> dict[str, dict[str, list[str]]]:
    """The ``convention`` rows that rest on a definition, as engine -> case id -> quantities
    (every other ``convention`` row rests on a behaviour, judged on its error)."""
    rows = frame[frame["category"].fillna("").astype(str) == Category.CONVENTION]
    rows = rows[rows["case_id"].isin(list(cases))]
    out: dict[str, dict[str, list[str]]] = {}
    for (engine, case_id, quantity), nature in zip(
            zip(rows["engine"], rows["case_id"], rows["quantity"], strict=True),
            natures(rows, cases, engine_conventions(list(engines))), strict=True):
        if nature == DEFINITION:
            out.setdefault(str(engine), {}).setdefault(str(case_id), []).append(str(quantity))
    return out


def form_data(frame: pd.DataFrame, cases: Mapping[str, AnyCase],
              engines: Iterable[Mapping[str, Any]],
              options: RunOptions | None = None) -> dict[str, Any]:
    """The form's data: ``cases`` (facts by id), ``engines`` (run order, with ``baseline`` and
    ``float32``), ``pair_kinds`` (the default kinds), ``units`` (each quantity's),
    ``tolerance_options`` (each unit's), ``kind_quantities`` (each kind's quantities),
    ``kind_options`` (the options that apply to some kinds only), ``definitions`` and
    ``severity``; ``options``: the run's (a ``--quick``
    run asked no engine its long scenes)."""
    engines = list(engines)
    run = options or RunOptions()
    gaps = exact_gaps(frame) if len(frame) else {}
    present = set(frame["kind"]) if len(frame) else set()
    return {
        "cases": {case_id: case_facts(case, gaps.get(case_id, math.nan), not (
            isinstance(case, SceneCase) and run.skips(case.step_count)))
                  for case_id, case in cases.items()},
        "engines": [{"name": str(e["name"]), "baseline": e["name"] in BASELINES,
                     "float32": is_float32(dict(e))} for e in engines],
        "pair_kinds": [k for k in PAIR_KINDS if k in present],
        "units": UNITS, "tolerance_options": TOLERANCE_OPTIONS,
        "kind_quantities": {str(k): list(quantities_of(k)) for k in Kind},
        "kind_options": {option: list(kinds) for option, (kinds, _) in KIND_OPTIONS.items()},
        "definitions": definitions(frame, cases, engines) if len(frame) else {},
        "severity": {str(s): s.severity for s in Status}}
