"""Moved and resized scenes against the engine's own origin run (report/metamorphic.py)."""

from __future__ import annotations

import json
import math
from typing import Any

import pandas as pd
import pytest

from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from crosscheck.core.values import text_of
from crosscheck.report import metamorphic
from crosscheck.report.metamorphic import EXACT, TOLERANCE
from crosscheck.report.style import templates
from crosscheck.results.run import decoded

RADIUS = 0.125
DURATION = 10.0


def _case(case_id: str) -> AnyCase:
    return CASE_ADAPTER.validate_python({
        "id": case_id, "description": "d", "kind": "sphere_scene", "dim": 3,
        "duration": DURATION, "gravity": [0, 0, -9.81], "walls": [{"normal": [0, 0, 1]}],
        "bodies": [{"center": [0, 0, 1.125], "radius": RADIUS, "mass": 1,
                    "velocity": [0, 0, 0]}]})


def _rows(block: str, axis: str, at: float, engine: str, values: dict[str, Any],
          truth: dict[str, Any] | None = None) -> list[dict[str, Any]]:
    case_id = f"{block}.dt=0.0166667.{axis}={at:g}"
    coords = json.dumps({"dt": 1 / 60, axis: at})
    return [{"case_id": case_id, "engine": engine, "quantity": q, "value": text_of(v),
             "truth": text_of((truth or values)[q]), "origin": block, "coords": coords,
             "kind": "sphere_scene", "status": "agree"} for q, v in values.items()]


def _drop(shift: float = 0.0, times: float = 1.0, apexes: tuple[float, ...] = (1.0, 1.0),
          settle: float = 0.0, drift: float = 0.0) -> dict[str, Any]:
    """A drop's values at the origin (shift 0, times 1), shifted or scaled as a perfect
    engine would give them."""
    return {"settle": [settle * times], "apex": [a * times for a in apexes],
            "bounce_time": [0.45, 1.35], "energy_drift": drift,
            "positions": [[shift, shift, 1.125 * times + shift]]}


def _frame(*rows: list[dict[str, Any]]) -> pd.DataFrame:
    """The rows as a results frame with its values decoded, as the report reads a run."""
    frame = pd.DataFrame([r for group in rows for r in group])
    return frame.join(decoded(frame))


def _cases(frame: pd.DataFrame) -> dict[str, AnyCase]:
    return {str(c): _case(str(c)) for c in frame["case_id"].unique()}


def _by_point(frame: pd.DataFrame) -> dict[tuple[str, float], dict[Any, Any]]:
    """Each point's row of :func:`metamorphic.points`, by engine and offset or scale."""
    return {(str(r["engine"]), float(r["at"])): r
            for r in metamorphic.points(frame, _cases(frame)).to_dict("records")}


def test_a_perfectly_moved_engine_differs_by_nothing_and_never_leaves_the_tolerance() -> None:
    frame = _frame(*(_rows("drop-moved", "offset", at, "e", _drop(shift=at))
                     for at in (0.0, 1e3, 1e5)))
    table = metamorphic.points(frame, _cases(frame))
    mine = table[table["engine"] == "e"]
    assert list(mine["at"]) == [1e3, 1e5]  # the origin point is the reference, not a row
    assert mine["difference"].tolist() == [0.0, 0.0]
    assert not mine["beyond"].any() and mine["first_beyond"].isna().all()


def test_an_engine_that_skips_scenes_gets_no_rows() -> None:
    skipped = {q: None for q in _drop()}
    frame = _frame(*(_rows("drop-moved", "offset", at, "e", _drop(shift=at))
                     for at in (0.0, 1e3)),
                   *(_rows("drop-moved", "offset", at, "skipper", skipped, _drop(shift=at))
                     for at in (0.0, 1e3)))
    engines = set(metamorphic.points(frame, _cases(frame))["engine"])
    assert engines == {EXACT, "e"}


def test_positions_lose_the_offset_and_a_change_names_its_quantity_and_first_offset() -> None:
    frame = _frame(_rows("drop-moved", "offset", 0.0, "e", _drop()),
                   _rows("drop-moved", "offset", 1e3, "e", _drop(shift=1e3)),
                   _rows("drop-moved", "offset", 1e5, "e", _drop(shift=1e5, settle=1e-4)),
                   _rows("drop-moved", "offset", 1e7, "e", _drop(shift=1e7, settle=1e-6)))
    table = _by_point(frame)
    assert table[("e", 1e3)]["difference"] == 0.0
    # a settle gap of 1e-4 m against 0 at the origin: over the mean radius (the floor)
    assert table[("e", 1e5)]["difference"] == pytest.approx(1e-4 / RADIUS)
    assert table[("e", 1e5)]["quantity"] == "settle"
    assert table[("e", 1e7)]["first_beyond"] == 1e5
    assert bool(table[("e", 1e5)]["beyond"]) and not bool(table[("e", 1e3)]["beyond"])


def test_scaled_lengths_are_divided_by_the_scale_and_times_are_not() -> None:
    origin = _drop()
    scaled = _drop(times=4.0)  # lengths x 4, bounce times unchanged: no difference
    stretched = _drop(times=0.25) | {"bounce_time": [0.45, 1.35 * 4]}  # a time scaled: wrong
    frame = _frame(_rows("drop-scaled", "scale", 1.0, "e", origin),
                   _rows("drop-scaled", "scale", 4.0, "e", scaled),
                   _rows("drop-scaled", "scale", 0.25, "e", stretched))
    table = _by_point(frame)
    assert table[("e", 4.0)]["difference"] == 0.0
    assert table[("e", 0.25)]["quantity"] == "bounce_time"
    assert table[("e", 0.25)]["difference"] == pytest.approx(3 * 1.35 / DURATION)
    # each side of the origin has its own first point beyond
    assert table[("e", 0.25)]["first_beyond"] == 0.25
    assert math.isnan(float(table[("e", 4.0)]["first_beyond"]))


def test_energy_drift_is_compared_unscaled_and_within_the_tolerance_is_not_beyond() -> None:
    small = TOLERANCE / DURATION / 2  # half the tolerance, as a share of the energy scale
    frame = _frame(_rows("drop-scaled", "scale", 1.0, "e", _drop(drift=0.0)),
                   _rows("drop-scaled", "scale", 2.0, "e", _drop(times=2.0, drift=small)),
                   _rows("drop-scaled", "scale", 8.0, "e", _drop(times=8.0, drift=4 * small)))
    table = _by_point(frame)
    assert table[("e", 2.0)]["difference"] == pytest.approx(TOLERANCE / 2)
    assert not bool(table[("e", 2.0)]["beyond"])
    assert table[("e", 8.0)]["quantity"] == "energy_drift"
    assert table[("e", 8.0)]["first_beyond"] == 8.0


def test_a_bounce_more_or_a_missing_value_is_infinite_with_a_note() -> None:
    frame = _frame(_rows("drop-moved", "offset", 0.0, "e", _drop()),
                   _rows("drop-moved", "offset", 1e3, "e",
                         _drop(shift=1e3, apexes=(1.0, 1.0, 1.0))),
                   _rows("drop-moved", "offset", 1e5, "e", _drop(shift=1e5) | {"settle": None}))
    table = _by_point(frame)
    assert math.isinf(float(table[("e", 1e3)]["difference"]))
    assert table[("e", 1e3)]["note"] == "apex: 3 values here, 2 at the origin"
    assert table[("e", 1e5)]["note"] == "settle: no value here"


def test_the_exact_reference_is_checked_from_the_truth_column() -> None:
    frame = _frame(_rows("drop-moved", "offset", 0.0, "e", _drop(), _drop()),
                   _rows("drop-moved", "offset", 1e3, "e", _drop(shift=1e3, drift=0.01),
                         _drop(shift=1e3)))
    table = _by_point(frame)
    assert table[(EXACT, 1e3)]["difference"] == 0.0
    # a drift of 0.01 of the energy scale per second against 0: over the run's 10 s
    assert table[("e", 1e3)]["difference"] == pytest.approx(0.01 * DURATION)


def test_rows_without_a_world_sweep_are_left_out() -> None:
    plain = _rows("drop", "dt", 1 / 60, "e", _drop())
    frame = _frame(plain)
    assert metamorphic.points(frame, _cases(frame)).empty
    assert list(metamorphic.points(frame, {}).columns) == list(metamorphic.COLUMNS)


def test_the_page_shows_the_first_point_beyond_per_sweep_and_engine() -> None:
    frame = _frame(_rows("drop-moved", "offset", 0.0, "e", _drop()),
                   _rows("drop-moved", "offset", 1e5, "e", _drop(shift=1e5, settle=1e-3),
                         _drop(shift=1e5)),
                   _rows("drop-moved", "offset", 1e7, "e", _drop(shift=1e7, settle=1e-3),
                         _drop(shift=1e7)))
    built = metamorphic.section(metamorphic.points(frame, _cases(frame)), ["e"])
    assert built["engines"] == [EXACT, "e"]
    cell = built["blocks"][0]["cells"]["e"]
    assert cell["first"] == "offset 1e+05" and cell["beyond"]
    assert cell["largest"] == "0.008 at 1e+05 (settle)"
    page = templates().get_template("_dynamics.html.j2").render(dynamics={
        "runs": 1, "scenes": [], "engines": [], "charts": [], "energy": None,
        "metamorphic": built})
    assert 'id="dynamics-metamorphic-table"' in page and "<b>offset 1e+05</b>" in page
    assert "none to 1e+07" in page  # the exact column: no change along the sweep
