"""The facts the report's "Which engine for my scene" form judges by, beside the results
table's packed rows.

The form in the page runs :func:`crosscheck.report.advise.advise`'s rules in JavaScript
(``_advise.html.j2``) over the results table's data; what a case's rows do not carry is
computed here, by the same functions the Python answer uses: each case's place in an
envelope (kind, dimension, bad input, its smallest and largest extent, largest
|coordinate|, largest |velocity component|, mass ratio), the length ``rtol`` is relative
to, and its exact gap; and each engine's role (baseline, float32).  A number that is not
finite is ``None`` (JSON has no NaN): the form then treats the case as outside every finite
limit, as the Python rules do.

>>> from crosscheck.core.schema import CASE_ADAPTER
>>> case = CASE_ADAPTER.validate_python({"id": "s", "description": "d", "kind": "sphere",
...     "dim": 3, "a": {"center": [0, 0, 0], "radius": 1}, "b": {"center": [3, 0, 0],
...     "radius": 0.5}})
>>> sorted(case_facts(case, 1.5).items())[:6]
[('bad', False), ('dim', 3), ('gap', 1.5), ('hi', 1.0), ('kind', 'sphere'), ('lo', 0.5)]
>>> sorted(case_facts(case, 1.5).items())[6:]
[('offset', 3.0), ('ratio', 1.0), ('size', 0.5), ('speed', 0.0)]
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import pandas as pd

from crosscheck.core.model import PAIR_KINDS, Status
from crosscheck.core.schema import AnyCase
from crosscheck.report.advise_grade import is_float32
from crosscheck.report.advise_judge import exact_gaps
from crosscheck.report.advise_profile import (
    LENGTHS,
    centres,
    extents,
    mass_ratio,
    smallest_size,
    velocity_components,
)
from crosscheck.report.profiles import BASELINES


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _largest(values: Iterable[float]) -> float | None:
    """max |value| (0 for none), None when one is not finite."""
    magnitudes = [abs(v) for v in values]
    return _finite(max(magnitudes, default=0.0)) if all(
        math.isfinite(m) for m in magnitudes) else None


def case_facts(case: AnyCase, gap: float) -> dict[str, Any]:
    """What the form needs of one case (see the module docstring)."""
    sizes = extents(case)
    finite = all(math.isfinite(s) for s in sizes)
    return {"kind": str(case.kind), "dim": case.dim, "bad": case.bad_input,
            "lo": min(sizes) if finite else None, "hi": max(sizes) if finite else None,
            "size": _finite(smallest_size(case)), "offset": _largest(centres(case)),
            "speed": _largest(velocity_components(case)), "ratio": _finite(mass_ratio(case)),
            "gap": _finite(gap)}


def form_data(frame: pd.DataFrame, cases: Mapping[str, AnyCase],
              engines: Iterable[Mapping[str, Any]]) -> dict[str, Any]:
    """The form's data: ``cases`` (facts by id), ``engines`` (run order, with ``baseline`` and
    ``float32``), ``pair_kinds`` (the default kinds), ``lengths`` and ``severity``."""
    gaps = exact_gaps(frame) if len(frame) else {}
    present = set(frame["kind"]) if len(frame) else set()
    return {
        "cases": {case_id: case_facts(case, gaps.get(case_id, math.nan))
                  for case_id, case in cases.items()},
        "engines": [{"name": str(e["name"]), "baseline": e["name"] in BASELINES,
                     "float32": is_float32(dict(e))} for e in engines],
        "pair_kinds": [k for k in PAIR_KINDS if k in present],
        "lengths": sorted(LENGTHS),
        "severity": {str(s): s.severity for s in Status}}
