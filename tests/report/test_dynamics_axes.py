"""The dynamics axes of the stability matrix: an offset sweep of a scene at one time step, and
the time horizon of long scenes (each engine's ``divergence``)."""

from __future__ import annotations

import json
from typing import Any

import pandas as pd

from crosscheck.core.schema import CASE_ADAPTER, AnyCase, SceneCase
from crosscheck.report import stability
from crosscheck.results.run import decoded

DT = 1 / 60


def scene(case_id: str, duration: float, coords: dict[str, float]) -> SceneCase:
    case = CASE_ADAPTER.validate_python({
        "id": case_id, "description": "d", "kind": "sphere_scene", "dim": 2,
        "duration": duration, "dt": DT, "walls": [{"normal": [0.0, 1.0]}],
        "bodies": [{"center": [0.0, 1.0], "radius": 0.5, "mass": 1.0, "velocity": [0, 1]}]})
    assert isinstance(case, SceneCase)
    origin = case_id.split(".")[0]
    return case.model_copy(update={"origin": origin, "coords": coords})


def with_values(rows: list[dict[str, Any]]) -> pd.DataFrame:
    """The rows as a results frame with its values decoded, as the report reads a run."""
    frame = pd.DataFrame(rows)
    return frame.join(decoded(frame))


def row(case: SceneCase, engine: str, quantity: str, status: str, value: Any = 0.0
        ) -> dict[str, Any]:
    return {"case_id": case.id, "kind": "sphere_scene", "dim": 2, "engine": engine,
            "quantity": quantity, "value": json.dumps(value), "status": status,
            "error": 0.0, "tolerance": 1e-6, "category": "", "reason": "",
            "origin": case.origin, "coords": json.dumps(case.coords), "twin_of": ""}


def test_a_moved_scene_breaks_at_the_first_offset_its_rows_stop_agreeing() -> None:
    offsets = {0.0: "agree", 1e3: "agree", 1e5: "disagree", 1e7: "agree"}
    cases = {c.id: c for c in (scene(f"rest-moved.dt={DT:.6g}.offset={v:g}", 10.0,
                                     {"dt": DT, "offset": v}) for v in offsets)}
    frame = with_values([row(c, "e", "velocities", s)
                          for c, s in zip(cases.values(), offsets.values(), strict=True)])
    table = stability.thresholds(stability.sweep_points(frame, cases))
    shown = table[table["headline"].astype(bool)].to_dict("records")
    assert len(shown) == 1
    assert shown[0]["axis"] == stability.AXES["offset"]
    assert shown[0]["sweep"] == f"rest-moved (dt={DT:.6g})"
    assert (shown[0]["threshold"], shown[0]["recovers"]) == (1e5, True)


def long_gas(seconds: float = 60.0) -> dict[str, AnyCase]:
    case = scene(f"gas.dt={DT:.6g}", seconds, {"dt": DT})
    return {case.id: case}


def test_the_time_horizon_is_when_the_trajectory_left_the_tolerance() -> None:
    cases = long_gas()
    case = next(iter(cases.values()))
    assert isinstance(case, SceneCase)
    frame = with_values([row(case, "early", "divergence", "disagree", 2.5),
                          row(case, "never", "divergence", "agree", 60.0),
                          row(case, "broke", "divergence", "crash", None),
                          row(case, "early", "velocities", "disagree")])
    table = stability.with_horizons(stability.thresholds(stability.sweep_points(frame, cases)),
                                    frame, cases)
    cells = {r["engine"]: r for r in table.to_dict("records")}
    assert set(cells) == {"early", "never", "broke"}
    assert (cells["early"]["state"], cells["early"]["threshold"]) == ("breaks", 2.5)
    assert cells["early"]["reached"] == 2.5 / 60.0
    assert (cells["never"]["state"], cells["never"]["cell"]) == ("none", "none")
    assert cells["broke"]["state"] == "already"
    matrix = stability.matrix(table)
    assert [a["name"] for a in matrix["axes"]] == ["time horizon"]
    early = next(r for r in matrix["rows"] if r["engine"] == "early")["cells"][0]
    assert early["main"] == "2.5 s" and "divergence (s)" in early["lines"]


def test_a_short_scene_has_no_time_horizon_column() -> None:
    cases = long_gas(seconds=10.0)
    case = next(iter(cases.values()))
    assert isinstance(case, SceneCase)
    frame = with_values([row(case, "e", "divergence", "disagree", 2.5)])
    assert stability.horizons(frame, cases).empty
