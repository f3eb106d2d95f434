"""``series.jsonl``: each recorded scene's relative energy against time, written by the run."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import adapters
from crosscheck.core.model import Observation, Trajectory
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.results.series import (
    EXACT,
    FILE,
    MAX_POINTS,
    SeriesRecord,
    downsample,
    read_series,
    series_of,
)
from crosscheck.results.store import ResultsStore
from crosscheck.run.casework import Executed
from crosscheck.run.execute import Outcome
from crosscheck.run.runner import energy_series, run
from crosscheck.truth.scene_measures import energy_scale


def drop(duration: float = 1.0, **extra: object) -> SceneCase:
    """A sphere dropped 1 m onto a ground under g = 10 (energy scale m g h = 15 J: h is its
    centre's height)."""
    case = CASE_ADAPTER.validate_python({
        "id": "drop", "description": "d", "kind": "sphere_scene", "dim": 2,
        "duration": duration, "dt": 0.01, "gravity": [0.0, -10.0], "restitution": 1.0,
        "walls": [{"normal": [0.0, 1.0]}],
        "bodies": [{"center": [0.0, 1.5], "radius": 0.5, "mass": 1.0, "velocity": [0, 0]}],
        **extra})
    assert isinstance(case, SceneCase)
    return case


def trajectory(energy: list[float]) -> Trajectory:
    n = len(energy)
    state = (((0.0, 1.5),),) * n
    return Trajectory(tuple(k * 0.01 for k in range(n)), state, state, tuple(energy))


def test_downsampling_keeps_at_most_the_limit_with_the_first_and_the_last() -> None:
    values = list(range(1001))
    kept = downsample(values)
    assert len(kept) <= MAX_POINTS and kept[0] == 0 and kept[-1] == 1000
    assert kept == sorted(set(kept))
    assert downsample([1, 2, 3]) == [1, 2, 3]


def test_the_energy_is_relative_to_the_start_over_the_energy_scale() -> None:
    case = drop()
    assert energy_scale(case) == pytest.approx(15.0)
    record = series_of(case, "e", trajectory([3.0, 3.0, 1.5, 10.5]))
    assert record is not None
    assert record.energy == pytest.approx((0.0, 0.0, -0.1, 0.5))
    assert record.times == pytest.approx((0.0, 0.01, 0.02, 0.03))
    assert (record.case_id, record.engine, record.origin) == ("drop", "e", "drop")
    assert series_of(case, "e", None) is None


def test_reading_keeps_the_last_line_of_a_pair_and_skips_a_half_written_one(
        tmp_path: Path) -> None:
    old = SeriesRecord("c", "e", "b", {"dt": 0.5}, (0.0, 1.0), (0.0, 0.25))
    new = SeriesRecord("c", "e", "b", {"dt": 0.5}, (0.0, 1.0), (0.0, math.inf))
    other = SeriesRecord("c", EXACT, "b", {}, (0.0,), (0.0,))
    (tmp_path / FILE).write_text(f"{old.to_json()}\n{other.to_json()}\n{new.to_json()}\n"
                                 '{"case_id": "c", "eng')
    read = read_series(tmp_path)
    assert [r.engine for r in read] == ["e", EXACT]
    assert math.isnan(read[0].energy[-1])


class Named:
    """The one adapter attribute energy_series reads."""

    def __init__(self, name: str) -> None:
        self.name = name


def test_the_runner_writes_the_exact_series_and_each_recorded_engine() -> None:
    case = drop()
    truth = Observation(trajectory=trajectory([0.0, 0.0]))
    seen = Outcome(Observation(trajectory=trajectory([0.0, -7.5])))
    unseen = Outcome(Observation())
    executed = Executed(case, truth, ((0, seen), (1, unseen)))
    found = energy_series(executed, [Named("a"), Named("b")])  # type: ignore[list-item]
    assert [(r.engine, r.energy[-1]) for r in found] == [(EXACT, 0.0), ("a", -0.5)]


@pytest.mark.engine
def test_a_run_stores_a_series_per_recorded_scene_and_engine(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path / "run")
    try:
        run([drop(duration=0.5)], [adapters.get("pybullet")], store, RunOptions())
    finally:
        store.close()
    found = {r.engine: r for r in read_series(tmp_path / "run")}
    assert set(found) == {EXACT, "pybullet"}
    assert found[EXACT].times[0] == 0.0 and found[EXACT].times[-1] == pytest.approx(0.5)
    assert abs(found[EXACT].energy[-1]) < 1e-9
