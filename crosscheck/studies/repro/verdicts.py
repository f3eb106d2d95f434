"""What a repro script says about the run's judgement: the truth, the bound, the verdict, the rules.

A script prints, after the engine's answer, what the run recorded beside it (all of it from
the stored run: results.csv's rows and run.json's declared conventions):

- ``expected <quantity> = <text>``: the exact answer of the harness's oracle (the ``truth``
  column, the same JSON text as the answer's);
- one ``# <quantity>: ...`` line per quantity: the status and category, the error against
  the float64 bound (``tolerance``: how far a correct float64 computation of the textbook
  formula can be; a scene's is its relative tolerance) and the reason, and whether the
  run's repeat check found the answer not reproducible (``nondeterministic``);
- ``# conventions consulted (<engine>): ...``: the engine's declared rules that the
  categories of that kind are judged by (precision, margins, touching rules, restitution,
  time step, friction...), as run.json records them.

>>> verdict_line({"quantity": "distance", "status": "disagree", "category": "tolerance",
...               "error": 3e-7, "tolerance": 1e-15, "reason": "within rtol",
...               "kind": "sphere"})
'# distance: disagree/tolerance: error 3e-07 = 3e+08 x the float64 bound 1e-15: within rtol'
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from crosscheck.core.contract import TEXTBOOK_TOUCHING
from crosscheck.core.schema import AnyCase, ResponseCase, SceneCase

Row = Mapping[str, Any]


def _number(x: object) -> float:
    try:
        return float(x)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return math.nan


def comment(text: object) -> str:
    """``text`` made safe for one comment line (control characters escaped)."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


def against_bound(row: Row) -> str:
    """The row's error against its bound, in words ('' when the row has no error).

    >>> against_bound({"error": 2.0, "tolerance": 0.5, "kind": "aabb"})
    'error 2 = 4 x the float64 bound 0.5'
    >>> against_bound({"error": 0.25, "tolerance": 1e-9, "kind": "sphere_scene"})
    'error 0.25 (relative) = 2.5e+08 x the allowed 1e-09'
    """
    error, bound = _number(row.get("error")), _number(row.get("tolerance"))
    if math.isnan(error):
        return ""
    scene = row.get("kind") == "sphere_scene"
    what = "the allowed" if scene else "the float64 bound"
    text = f"error {error:.3g}" + (" (relative)" if scene else "")
    if math.isnan(bound):
        return text
    if bound > 0 and math.isfinite(error):
        return f"{text} = {error / bound:.3g} x {what} {bound:.3g}"
    return f"{text}, {what} {bound:.3g}"


def verdict_line(row: Row) -> str:
    """One ``# <quantity>: <status>[/<category>]: <error against the bound>: <reason>`` line."""
    head = str(row["status"]) + (f"/{row['category']}" if row.get("category") else "")
    parts = [f"# {row['quantity']}: {head}"]
    parts += [p for p in (against_bound(row), str(row.get("reason") or "")) if p]
    if str(row.get("nondeterministic")) == "True":  # a bool, or numpy's
        parts.append(f"not reproducible: asked again in a fresh worker, the engine answered "
                     f"{row.get('repeat_value')} ({row.get('repeat_status')})")
    return comment(": ".join(parts))


def truths(rows: Iterable[Row]) -> dict[str, str]:
    """The exact answer of each quantity, as the ``truth`` column holds it."""
    return {str(r["quantity"]): str(r["truth"]) for r in rows}


def _touching(conv: Mapping[str, Any], features: Iterable[str]) -> str:
    touching: Mapping[str, bool] = conv.get("touching") or {}
    return ", ".join(f"{f} {'contact' if touching.get(f, TEXTBOOK_TOUCHING[f]) else 'apart'}"
                     for f in features)


def _margins(conv: Mapping[str, Any], features: Iterable[str]) -> str:
    margins: Mapping[str, float] = conv.get("margins") or {}
    return ", ".join(f"{f} {margins.get(f, 0.0):g}" for f in features)


def _response_rules(conv: Mapping[str, Any]) -> list[str]:
    step = conv.get("time_step")
    model = conv.get("restitution_model") or ""
    return [f"restitution {conv.get('restitution', '')}",
            *([f"restitution model {model}"] if model else []),
            f"restitution threshold {conv.get('restitution_threshold', 0.0):g}",
            "bodies already separating get " + (
                "the textbook exchange" if conv.get("resolves_separating", True)
                else "no impulse"),
            f"time step {step:g} s" if step else "no fixed time step",
            f"friction {conv.get('friction', 0.0):g}",
            f"zero mass {conv.get('zero_mass') or 'as the textbook'}",
            f"rtol {conv.get('rtol', 0.0):.3g}"]


def _detection_rules(conv: Mapping[str, Any], case: AnyCase) -> list[str]:
    features = ("sphere",) if case.kind == "sphere" else ("face", "edge", "corner")
    return [f"normal {conv.get('normal', '')}", f"touching: {_touching(conv, features)}",
            f"margin: {_margins(conv, features)}", f"rtol {conv.get('rtol', 0.0):.3g}",
            f"negative sizes {conv.get('negative_extents') or 'literal or refused'}",
            *([f"box extents {conv.get('box_extents', '')}"] if case.kind == "aabb" else [])]


def conventions_line(info: Mapping[str, Any], case: AnyCase) -> str:
    """The engine's declared rules for the case's kind, as one comment line."""
    conv: Mapping[str, Any] = info.get("conventions") or {}
    if not conv:
        return "# conventions consulted: (the run does not record this engine's conventions)"
    if isinstance(case, SceneCase):
        parts = [f"restitution {conv.get('restitution', '')}",
                 f"damping {conv.get('damping', 0.0):g} per s",
                 "a step-late impact lag is the time step's"]
    elif isinstance(case, ResponseCase):
        parts = _response_rules(conv)
    else:
        parts = _detection_rules(conv, case)
    return comment(f"# conventions consulted ({info.get('name', '')}, declared in run.json): "
                   + "; ".join(parts))
