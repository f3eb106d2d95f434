"""The timing phase: a seeded sample timed in interleaved rounds, every sample kept with its
round's yardstick, the yardsticks and binding costs in run.json.

No measured time is asserted.  The real phase is checked for what it records and how; how
the machine's drift and a slower engine read, in the phase and in ``compare``, is checked on
injected times: a :class:`Machine` behind the phase's ``sampler`` seam."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from crosscheck.compare.runs import compare
from crosscheck.core.contract import Adapter
from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.results.run import read_run
from crosscheck.results.store import ResultsStore
from crosscheck.results.timings import read_timings
from crosscheck.run.execute import Outcome
from crosscheck.run.launch import launch, new_info
from crosscheck.run.rounds import MARK_SAMPLES, Pair, run_rounds, steps
from crosscheck.run.timing import Timing
from crosscheck.run.timing_phase import time_phase
from crosscheck.testing.samples import scene
from tests import fakes
from tests.conftest import sphere

CASES = [sphere(0.0, 2.0 + i / 10, id=f"s{i}") for i in range(12)]
OPTIONS = RunOptions(min_sample_s=0.001, samples=12, timing_cases=8, isolate=False)


def timed_run(folder: Path, engine: Adapter, options: RunOptions = OPTIONS) -> Path:
    launch(ResultsStore(folder), CASES, [engine], options,
           new_info(folder, "test", options, [engine], CASES))
    return folder


# --- the real phase: what it records ------------------------------------------------------------


def test_every_sample_is_kept_with_its_rounds_yardstick(tmp_path: Path) -> None:
    folder = timed_run(tmp_path / "run", fakes.BusyLoop())
    timings = read_timings(folder)
    assert len(timings) == 8 and set(timings["engine"]) == {"fake-busy"}
    assert (timings["n"] == 12).all() and all(len(v) == 12 for v in timings["values"])
    rounds = json.loads((folder / "run.json").read_text())["timing"]["rounds"]["yardstick_s"]
    for sticks in timings["yardstick"]:  # every pair sampled once in each of the same rounds
        assert list(sticks) == rounds
    assert np.isfinite(timings["normalised_median"].astype(float)).all()
    results = read_run(folder).results.drop_duplicates("case_id").set_index("case_id")
    for row in timings.itertuples():  # the results rows carry the samples' median
        assert results.loc[row.case_id, "query_s"] == row.median_s


def test_run_json_states_the_method_the_yardsticks_and_the_binding(tmp_path: Path) -> None:
    info = json.loads((timed_run(tmp_path / "run", fakes.BusyLoop()) / "run.json").read_text())
    timing = info["timing"]
    assert "interleaved rounds" in timing["method"] and "(seed 0)" in timing["method"]
    assert timing["sampled"] == 8 and timing["failed"] == 0
    for moment in ("start", "end"):
        for workload in ("numpy", "python"):
            assert len(timing["yardstick"][moment][workload]["values"]) == 12
            assert math.isfinite(timing["yardstick"][moment][workload]["median_s"])
    rounds = timing["rounds"]
    assert rounds["count"] == 12 == len(rounds["yardstick_s"])
    assert rounds["drift"] == max(rounds["yardstick_s"]) / min(rounds["yardstick_s"])
    assert timing["binding"]["fake-busy"] == {"none": "no binding: the engine runs in Python"}
    assert timing["pinned"]


def test_quick_and_zero_cases_mean_no_timing_phase(tmp_path: Path) -> None:
    for name, options in (("quick", RunOptions(quick=True, isolate=False)),
                          ("none", RunOptions(timing_cases=0, isolate=False))):
        folder = timed_run(tmp_path / name, fakes.BusyLoop(), options)
        assert read_run(folder).info.timing is None and read_timings(folder).empty


def test_a_resumed_run_does_not_time_a_pair_twice(tmp_path: Path) -> None:
    folder = timed_run(tmp_path / "run", fakes.BusyLoop())
    before = (folder / "timings.jsonl").read_text()
    store = ResultsStore(folder, resume=True)
    assert len(store.timed) == 8
    launch(store, CASES, [fakes.BusyLoop()], OPTIONS, read_run(folder).info.resume())
    assert (folder / "timings.jsonl").read_text() == before


@pytest.mark.parametrize("isolate", [True, False])
def test_timing_runs_in_the_engine_worker_or_in_process(tmp_path: Path, isolate: bool) -> None:
    options = RunOptions(min_sample_s=0.001, samples=12, timing_cases=3, isolate=isolate)
    folder = timed_run(tmp_path / "run", fakes.AlwaysRight(), options)
    timings = read_timings(folder)
    assert len(timings) == 3 and all(len(y) == 12 for y in timings["yardstick"])
    rounds = json.loads((folder / "run.json").read_text())["timing"]["rounds"]
    assert rounds["count"] == 12 and all(math.isfinite(y) for y in rounds["yardstick_s"])


def test_too_few_samples_are_unknown_never_changed(tmp_path: Path) -> None:
    options = replace(OPTIONS, samples=5)
    first = timed_run(tmp_path / "a", fakes.BusyLoop(), options)
    slower = timed_run(tmp_path / "c", fakes.BusyLoopTwice(), options)
    result = compare(first, slower, tmp_path / "cmp")
    assert result.timing_counts["unknown"] == 8
    assert result.timing_counts["slower"] == result.timing_counts["same"] == 0


# --- injected times -------------------------------------------------------------------------------


class Machine:
    """A sampler of injected times (the phase's ``sampler`` seam); it runs no engine.

    A query costs its engine's ``ITERATIONS`` ns (``fakes.BusyLoop``: 20,000;
    ``BusyLoopTwice``: twice that; others 10,000) times ``1 + i / 10`` for case ``s<i>``;
    a scene run 1 ms.  Every time, the yardstick's workloads' included, is multiplied by
    the machine's slowness when it is taken (1, then ``slows`` from the ``after``-th
    sample on) and by a seeded noise of 2%.  ``log`` lists every call; ``fail_at`` and
    ``stop_at`` make that sample an engine error or a Ctrl-C.
    """

    def __init__(self, slows: float = 1.0, after: int = 0, seed: int = 0,
                 fail_at: int = -1, stop_at: int = -1) -> None:
        self.slows, self.after, self.fail_at, self.stop_at = slows, after, fail_at, stop_at
        self.taken = 0
        self.rng = np.random.default_rng(seed)
        self.log: list[str] = []

    def _now(self) -> float:
        """The slowness now, times the noise."""
        slowness = self.slows if self.taken >= self.after else 1.0
        return slowness * float(self.rng.lognormal(0.0, 0.02))

    def binding(self, adapter: Adapter) -> Timing | str:
        self.log.append(f"binding {adapter.name}")
        return "no binding: injected times"

    def step(self, adapter: Adapter, case: AnyCase, calibrated: Timing | None) -> Outcome:
        if calibrated is None:
            self.log.append(f"calibrate {case.id} {adapter.name}")
            unit = "scene" if isinstance(case, SceneCase) else "call"
            return Outcome(None, timing=Timing((), 1 if unit == "scene" else 100, 0.0, unit))
        self.log.append(f"sample {case.id} {adapter.name}")
        if self.taken == self.stop_at:
            raise KeyboardInterrupt
        if self.taken == self.fail_at:
            self.taken += 1
            return Outcome(None, Status.CRASH, "worker killed by SIGSEGV")
        cost = 1e-3 if isinstance(case, SceneCase) else (
            getattr(adapter, "ITERATIONS", 10_000) * 1e-9 * (1 + int(case.id[1:]) / 10))
        value = cost * self._now()
        self.taken += 1
        return Outcome(None, timing=replace(calibrated, values=(value,)))

    def yardstick(self, samples: int) -> dict[str, Timing] | str:
        self.log.append(f"yardstick {samples}")
        return {name: Timing(tuple(base * self._now() for _ in range(samples)), 10, 0.0)
                for name, base in (("numpy", 1e-4), ("python", 4e-5))}

    def close(self) -> None:
        self.log.append("close")


ENGINES: list[Adapter] = [fakes.BusyLoop(), fakes.AlwaysRight()]
HALF = len(ENGINES) * OPTIONS.timing_cases * OPTIONS.samples // 2
"""The samples of half a run of :data:`ENGINES`: its first six rounds."""


def injected_run(folder: Path, machine: Machine, engines: Sequence[Adapter] = ENGINES) -> Path:
    """A run of CASES whose verdict pass runs the fake engines and whose timing phase takes
    ``machine``'s injected times."""
    info = new_info(folder, "test", OPTIONS, engines, CASES)
    launch(ResultsStore(folder), CASES, engines, replace(OPTIONS, quick=True), info)
    store = ResultsStore(folder, resume=True)
    try:
        timing = time_phase(store, read_run(folder), engines, OPTIONS,
                            sampler=lambda *_: machine)
        store.write_run_info(replace(info, timing=timing).finish())
    finally:
        store.close()
    return folder


def per_pair(folder: Path) -> pd.DataFrame:
    return read_timings(folder).set_index(["case_id", "engine"]).sort_index()


def test_the_rounds_sample_every_pair_once_a_round_between_yardstick_marks(
        tmp_path: Path) -> None:
    machine = Machine()
    folder = injected_run(tmp_path / "run", machine)
    pairs = [f"{c} {e}" for e, c in read_timings(folder)[["engine", "case_id"]].itertuples(
        index=False)]
    assert len(pairs) == 16
    calibration = ["binding fake-busy", *(f"calibrate {p}" for p in pairs[:8]),
                   "binding fake-right", *(f"calibrate {p}" for p in pairs[8:])]
    one_round = [*(f"sample {p}" for p in pairs), f"yardstick {MARK_SAMPLES}"]
    assert machine.log == ["yardstick 12", *calibration, f"yardstick {MARK_SAMPLES}",
                           *one_round * OPTIONS.samples, "yardstick 12", "close"]


def test_a_machine_slowing_mid_run_leaves_every_normalised_time_unaffected(
        tmp_path: Path) -> None:
    steady = per_pair(injected_run(tmp_path / "steady", Machine()))
    drifting = per_pair(injected_run(tmp_path / "drift", Machine(slows=1.5, after=HALF)))
    assert list(steady.index) == list(drifting.index) and len(steady) == 16
    raw = drifting["median_s"] / steady["median_s"]
    normalised = drifting["normalised_median"] / steady["normalised_median"]
    assert (raw > 1.15).all()  # the drift reaches every pair's raw median...
    assert normalised.between(0.95, 1.05).all()  # ...and none of the normalised ones
    info = read_run(tmp_path / "drift").info.timing or {}
    assert info["rounds"]["drift"] == pytest.approx(1.5, rel=0.1)


@pytest.mark.parametrize("slows, after", [(1.5, HALF), (1.5, 16), (2.0, 0)],
                         ids=["mid-run", "early", "all-along"])
def test_compare_never_calls_a_drift_only_change_slower(tmp_path: Path, slows: float,
                                                         after: int) -> None:
    steady = injected_run(tmp_path / "a", Machine(seed=1))
    drifting = injected_run(tmp_path / "b", Machine(slows=slows, after=after, seed=2))
    result = compare(steady, drifting, tmp_path / "cmp")
    assert result.timing_counts["slower"] == result.timing_counts["faster"] == 0
    assert result.timing_counts["same"] + result.timing_counts["unknown"] == 16
    assert result.normalised and "its round's yardstick" in result.normalisation
    changes = pd.read_csv(tmp_path / "cmp" / "timing_changes.csv")
    assert changes["ratio"].between(0.95, 1.05).all()
    if after < HALF:  # raw, every pair is slower by the drift: unknown, the drift said
        assert (changes["verdict"] == "unknown").all()
        assert changes["reason"].str.contains(r"slower raw, (?:within|beyond) the machine").all()
        drift = changes["reason"].str.extract(r"drift x([\d.]+) measured")[0].astype(float)
        assert drift.between(slows / 1.1, slows * 1.1).all()


def test_compare_flags_a_twice_slower_engine_on_every_pair_despite_the_drift(
        tmp_path: Path) -> None:
    steady = injected_run(tmp_path / "a", Machine(seed=1))
    slower = injected_run(tmp_path / "b", Machine(slows=1.5, after=HALF, seed=2),
                          [fakes.BusyLoopTwice(), fakes.AlwaysRight()])
    compare(steady, slower, tmp_path / "cmp")
    changes = pd.read_csv(tmp_path / "cmp" / "timing_changes.csv")
    busy, right = (changes[changes["engine"] == name] for name in ("fake-busy", "fake-right"))
    assert len(busy) == 8 and (busy["verdict"] == "slower").all()
    assert busy["ratio"].between(1.9, 2.1).all()
    assert not right["verdict"].isin(["slower", "faster"]).any()


def rounds_of(folder: Path, machine: Machine, pairs: Sequence[Pair],
              ticks: list[int] | None = None) -> int:
    """Run the rounds alone on ``pairs`` into a store in ``folder``; how many failed."""
    store = ResultsStore(folder, resume=folder.exists())
    try:
        engines = list({id(a): a for _, a in pairs}.values())
        return run_rounds(store, pairs, engines, OPTIONS, machine,
                          ticks.append if ticks is not None else None).failed
    finally:
        store.close()


def test_a_phase_stopped_midway_keeps_the_complete_pairs_and_a_resume_times_the_rest(
        tmp_path: Path) -> None:
    engine = fakes.BusyLoop()
    options = replace(OPTIONS, scene_repeats=3)
    pairs: list[Pair] = [(CASES[0], engine), (scene(3).case, engine), (CASES[1], engine)]
    folder = tmp_path / "run"
    machine = Machine(stop_at=3 * 4)  # in round 5, after the scene's third and last run
    with pytest.raises(KeyboardInterrupt):
        store = ResultsStore(folder)
        try:
            run_rounds(store, pairs, [engine], options, machine)
        finally:
            store.close()
    kept = read_timings(folder)
    assert list(kept["case_id"]) == ["kit-scene-3d"]  # complete: its 3 runs
    assert list(kept["n"]) == [3] and len(kept["yardstick"][0]) == 3
    store = ResultsStore(folder, resume=True)
    todo = [(c, a) for c, a in pairs if (c.id, a.name) not in store.timed]
    store.close()
    assert rounds_of(folder, Machine(), todo) == 0
    assert sorted(read_timings(folder)["case_id"]) == ["kit-scene-3d", "s0", "s1"]
    assert (read_timings(folder).set_index("case_id").loc[["s0", "s1"], "n"] == 12).all()


def test_a_pair_failing_in_a_round_is_counted_dropped_and_not_stored(tmp_path: Path) -> None:
    pairs: list[Pair] = [(case, fakes.BusyLoop()) for case in CASES[:3]]
    ticks: list[int] = []
    failed = rounds_of(tmp_path / "run", Machine(fail_at=3 * 4 + 1), pairs, ticks)  # s1, round 5
    assert failed == 1
    stored = read_timings(tmp_path / "run")
    assert list(stored["case_id"]) == ["s0", "s2"] and (stored["n"] == 12).all()
    assert sum(ticks) == steps(pairs, OPTIONS) == 3 * 13  # the progress bar reaches its end
