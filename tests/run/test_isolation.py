"""Isolation: engines that hang or die cost one case x engine, never the run.

Fakes with known behaviour test the mechanism; tests/guarantees/test_engine_faults.py
checks it with real engine inputs that crash or hang today.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from crosscheck.core.contract import HANG_PROBE_S, Adapter
from crosscheck.core.model import quantities_of
from crosscheck.core.options import RunOptions
from crosscheck.results.run import read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.runner import run
from tests import fakes
from tests.conftest import response, sphere

CASES = [sphere(0.0, 2.0, id="before"), sphere(0.0, 1.5, id="boom"), sphere(0.0, 3.0, id="after")]


def run_isolated(tmp_path: Path, engines: list[Adapter], timeout_s: float = 1.0) -> pd.DataFrame:
    store = ResultsStore(tmp_path / "run")
    run(CASES, engines, store, RunOptions(quick=True, timeout_s=timeout_s))
    store.close()
    return read_results(tmp_path / "run")


def by_case(frame: pd.DataFrame, engine: str) -> dict[str, set[str]]:
    rows = frame[frame["engine"] == engine]
    return {str(k): set(v) for k, v in rows.groupby("case_id")["status"]}


def test_hang_is_a_timeout_and_the_run_goes_on(tmp_path: Path) -> None:
    # The outcome, not the clock: every hang is a timeout naming the run's limit (the one the
    # worker waited for), and the engine after it still answered every case.
    frame = run_isolated(tmp_path, [fakes.SleepsForever(), fakes.AlwaysRight()], timeout_s=0.5)
    assert by_case(frame, "fake-hangs") == {c.id: {"timeout"} for c in CASES}
    assert by_case(frame, "fake-right") == {c.id: {"agree"} for c in CASES}
    reasons = set(frame[frame["engine"] == "fake-hangs"]["reason"])
    assert reasons == {"no answer within 0.5 s"}


def test_declared_hang_is_probed_briefly_and_still_measured(tmp_path: Path) -> None:
    frame = run_isolated(tmp_path, [fakes.DeclaresHangs()], timeout_s=30.0)
    # the reason names the limit the worker waited for: the probe's, not the run's 30 s
    assert by_case(frame, "fake-declared-hang") == {"before": {"agree"}, "boom": {"timeout"},
                                                    "after": {"agree"}}
    boom = frame[frame["case_id"] == "boom"]
    assert set(boom["reason"]) == {
        f"no answer within {HANG_PROBE_S:g} s (declared known hang: stuck in a loop)"}


def by_quantity(frame: pd.DataFrame, case_id: str) -> dict[str, tuple[str, str]]:
    rows = frame[frame["case_id"] == case_id]
    return {str(q): (str(s), str(r)) for q, s, r in zip(rows["quantity"], rows["status"],
                                                       rows["reason"], strict=True)}


def test_a_hang_declared_on_one_quantity_costs_only_that_quantity(tmp_path: Path) -> None:
    frame = run_isolated(tmp_path, [fakes.HangsOnDistance()], timeout_s=30.0)
    declared = f"no answer within {HANG_PROBE_S:g} s (declared known hang: distance loops)"
    assert by_quantity(frame, "boom") == {"hit": ("agree", ""), "normal": ("agree", ""),
                                          "distance": ("timeout", declared)}
    for case_id in ("before", "after"):
        assert set(frame[frame["case_id"] == case_id]["status"]) == {"agree"}


def test_the_rest_of_a_declared_hang_keeps_its_own_outcome(tmp_path: Path) -> None:
    frame = run_isolated(tmp_path, [fakes.HangsOnDistanceRestRaises()], timeout_s=30.0)
    boom = by_quantity(frame, "boom")
    assert boom["distance"][0] == "timeout" and "declared known hang" in boom["distance"][1]
    for quantity in ("hit", "normal"):
        status, reason = boom[quantity]
        assert status == "error" and reason.startswith("RuntimeError: no verdict either")


def test_an_adapter_declaring_a_hang_hangs_every_quantity_by_default() -> None:
    adapter = fakes.DeclaresHangs()
    boom, before = CASES[1], CASES[0]
    assert adapter.hanging_quantities(boom) == frozenset(quantities_of(boom.kind_enum))
    assert adapter.hanging_quantities(before) == frozenset()
    assert adapter.query_without(before, frozenset({"distance"})) == adapter.query(before)


def test_abort_is_a_crash_naming_the_signal(tmp_path: Path) -> None:
    frame = run_isolated(tmp_path, [fakes.Aborts()])
    assert set(frame["status"]) == {"crash"}
    assert set(frame["reason"]) == {"worker killed by SIGABRT"}


def test_worker_is_restarted_after_a_crash(tmp_path: Path) -> None:
    frame = run_isolated(tmp_path, [fakes.CrashesOnSpheresAt()])
    assert by_case(frame, "fake-boom") == {"before": {"agree"}, "boom": {"crash"},
                                           "after": {"agree"}}
    boom = frame[frame["case_id"] == "boom"]
    assert set(boom["reason"]) == {"worker killed by SIGSEGV"}


def test_claimed_capability_without_answers_is_skip_per_quantity(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path / "run")
    case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0])
    run([case], [fakes.ClaimsResponse()], store, RunOptions(quick=True))
    store.close()
    frame = read_results(tmp_path / "run")
    assert set(frame["status"]) == {"skip"}
    assert set(frame["reason"]) == {"engine reported no v1", "engine reported no v2"}


def test_in_process_mode_gives_the_same_records(tmp_path: Path) -> None:
    engines: list[Adapter] = [fakes.AlwaysRight(), fakes.OffByOne(), fakes.Raises()]
    frames = []
    for isolate in (True, False):
        store = ResultsStore(tmp_path / str(isolate))
        run(CASES, engines, store, RunOptions(quick=True, isolate=isolate))
        store.close()
        frames.append(read_results(tmp_path / str(isolate)).drop(columns=["setup_s"]))
    pd.testing.assert_frame_equal(frames[0], frames[1])
