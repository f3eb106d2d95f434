"""The stability study's points: each stored row of a sweep as a point of its axis of
difficulty (the sweep's parameter, its value, its walk), with the relative error the walks compare
(each kind's headline quantity, and the scale each error is divided by, are its spec's:
:mod:`crosscheck.core.kinds`)."""

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass

import pandas as pd

from crosscheck.core.kinds import is_kind, quantity_named
from crosscheck.core.schema import (
    AabbCase,
    AnyCase,
    ResponseCase,
    SphereCase,
)
from crosscheck.truth.categories import length_scale, velocity_scale
from crosscheck.truth.scene_rules import PASSED_THROUGH

_GAP = "gap or overlap relative to size"
AXES: dict[str, str] = {"offset": "distance from origin", "scale": "body scale", "gap": _GAP,
                        "overlap": _GAP, "mass_ratio": "mass ratio", "speed": "approach speed",
                        "step_travel": "per-step travel (fast bodies)"}
"""Sweep parameter -> the axis of difficulty it probes."""
HORIZON_AXIS = "time horizon"
"""The axis of :func:`horizons` (no sweep: parameter ``time_horizon``)."""



@dataclass(frozen=True, slots=True)
class Direction:
    """One walk along a sweep: which values it covers and which way difficulty grows."""

    name: str
    harder_up: bool
    """True: larger values are harder."""
    low: float = -math.inf
    high: float = math.inf


_UP, _DOWN = Direction("larger", True), Direction("smaller", False)
DIRECTIONS: dict[str, tuple[Direction, ...]] = {
    "offset": (_UP,), "gap": (_DOWN,), "overlap": (_DOWN,), "mass_ratio": (_UP,), "speed": (_DOWN,),
    "step_travel": (_UP,), "time_horizon": (Direction("longer", True),),
    "scale": (Direction("tiny", False, high=1.0), Direction("huge", True, low=1.0))}
POINT_COLUMNS = ["sweep", "family", "axis", "param", "value", "direction", "kind", "dim", "engine",
                 "quantity", "status", "category", "error", "rel_error", "rel_tolerance",
                 "case_id"]
TABLE_COLUMNS = ["sweep", "family", "axis", "param", "direction", "harder", "kind", "dim", "engine",
                 "quantity", "headline", "column", "threshold", "status", "category", "verdict",
                 "state", "cell", "reached", "recovers", "recovered_at", "checked", "easiest",
                 "hardest", "points"]

# --- points ---------------------------------------------------------------------------------


def _scales(cases: Mapping[str, AnyCase], ids: set[str]) -> dict[str, tuple[float, float]]:
    """Length and velocity scale of each case (NaN for a case the run did not store)."""
    out = dict.fromkeys(ids, (math.nan, math.nan))
    for case_id in ids & cases.keys():
        case = cases[case_id]
        if isinstance(case, AabbCase | SphereCase | ResponseCase):
            out[case_id] = (length_scale(case), velocity_scale(case))
    return out


def relative_error(quantity: str, error: float, scales: tuple[float, float]) -> float:
    """Distance error / length scale, velocity error / velocity scale, normal and hit as is.

    >>> relative_error("distance", 3e-9, (2.0, 0.0)), relative_error("normal", 0.5, (9, 9))
    (1.5e-09, 0.5)
    """
    to = quantity_named(quantity).relative_to
    scale = scales[0] if to == "length" else scales[1] if to == "velocity" else 1.0
    return error / scale if scale > 0 else math.nan


SCENE_CONTEXT = ("dt", "iterations", "phase")
"""Coordinates of a fast-body scene point that are not its difficulty: each time step (and
iteration count) is a sweep of its own; the impact phases of one travel are walked together,
so the travel breaks where any phase breaks."""
SCENE_SWEEPS = ("step_travel", "offset", "scale")
"""The difficulties a scene point may sweep beside its :data:`SCENE_CONTEXT`: fast bodies,
and a scene with gravity or walls moved from the origin or resized."""


def _single_parameter(coords: str) -> tuple[str, float, str] | None:
    """``(param, value, context)`` of a one-parameter sweep point's coordinates, else None.

    A fast-body scene point (``step_travel``, with its ``dt`` and ``phase``) is a point of
    the ``step_travel`` sweep at its ``dt`` (the context, which names the sweep).

    >>> _single_parameter('{"gap": 1e-09}'), _single_parameter(""), _single_parameter('{"dt": 0.1}')
    (('gap', 1e-09, ''), None, None)
    >>> _single_parameter('{"dt": 0.0166667, "step_travel": 2.0, "phase": 0.5}')
    ('step_travel', 2.0, 'dt=0.0166667')
    >>> _single_parameter('{"dt": 0.0166667, "offset": 1000.0}')
    ('offset', 1000.0, 'dt=0.0166667')
    """
    if not coords:
        return None
    point = json.loads(coords)
    context = ""
    swept = [p for p in SCENE_SWEEPS if p in point]
    if len(swept) == 1 and set(point) <= {*swept, *SCENE_CONTEXT} and len(point) > 1:
        context = ",".join(f"{k}={point[k]:.6g}" for k in ("dt", "iterations") if k in point)
        point = {swept[0]: point[swept[0]]}
    if len(point) != 1:
        return None
    ((param, value),) = point.items()
    return (param, float(value), context) if param in DIRECTIONS else None


def _missed_impacts_only(rows: pd.DataFrame) -> pd.DataFrame:
    """On the ``step_travel`` axis a point breaks only where the impact is missed: a row
    whose reason names the bodies passing through each other (:data:`PASSED_THROUGH`), or
    a failed one.  Any other disagreement there (the step lag of an impact resolved a step
    late, a speed cap, a restitution threshold) counts as the impact caught: it is
    ``agree`` in the walk, its category cleared."""
    fast = rows["param"] == "step_travel"
    if not fast.any():
        return rows
    missed = rows["reason"].fillna("").str.contains(PASSED_THROUGH, regex=False)
    caught = fast & (rows["status"] == "disagree") & ~missed
    out = rows.copy()
    out.loc[caught, "status"] = "agree"
    out.loc[caught, "category"] = ""
    return out


def _family(case_id: str, origin: str, cases: Mapping[str, AnyCase]) -> str:
    """The sweep column a point is shown in: a 2-D twin's is its 3-D case's sweep.

    >>> _family("g.2d.gap=0.1", "g.2d", {})
    'g.2d'
    """
    case = cases.get(case_id)
    original = cases.get(case.from_3d) if case is not None and case.from_3d else None
    return original.origin if original is not None and original.origin else origin


def sweep_points(frame: pd.DataFrame, cases: Mapping[str, AnyCase]) -> pd.DataFrame:
    """One row per sweep case x engine x quantity (x walk: scale 1 is in both scale walks).

    A sweep point is a case with one sweep coordinate (``coords``) that is not a
    swapped twin; its sweep is the block it came from (``origin``), its ``family``
    the 3-D sweep of a 2-D twin (read from ``cases``), else its sweep.
    """
    parsed: dict[str, tuple[str, float, str] | None] = {}  # each case's coords on every row
    found = [None if twin else parsed[text] if (text := str(coords)) in parsed
             else parsed.setdefault(text, _single_parameter(text))
             for coords, twin in zip(frame["coords"].tolist(), frame["twin_of"].tolist(),
                                     strict=True)]
    keep = [f is not None and is_kind(kind)
            for f, kind in zip(found, frame["kind"].tolist(), strict=True)]
    if not any(keep):
        return pd.DataFrame(columns=POINT_COLUMNS)
    chosen = [f for f, k in zip(found, keep, strict=True) if k and f is not None]
    rows = frame[keep].drop(columns=["value"]).assign(
        param=[p for p, _, _ in chosen], value=[v for _, v, _ in chosen])
    rows["sweep"] = [f"{origin} ({context})" if context else origin
                     for origin, (_, _, context) in zip(rows["origin"], chosen, strict=True)]
    rows["family"] = [_family(str(c), str(s), cases)
                      for c, s in zip(rows["case_id"], rows["sweep"], strict=True)]
    rows["axis"] = rows["param"].map(AXES)
    scales = _scales(cases, set(rows["case_id"]))
    for column, of in (("rel_error", "error"), ("rel_tolerance", "tolerance")):
        rows[column] = [relative_error(q, float(x), scales[c]) for q, x, c
                        in zip(rows["quantity"], rows[of], rows["case_id"], strict=True)]
    rows = _missed_impacts_only(rows)
    walks = [rows[(rows["param"] == p) & rows["value"].between(d.low, d.high)].assign(
        direction=d.name) for p, ds in DIRECTIONS.items() for d in ds]
    points = pd.concat(walks).sort_index(kind="stable").reset_index(drop=True)
    points["category"] = points["category"].fillna("")
    return points[POINT_COLUMNS]


