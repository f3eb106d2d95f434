"""The repeat check asks every disagreeing pair again in a fresh worker and flags the pairs whose
answer changed: an engine that answers from its process's history is flagged, with both
answers; one that answers the same (right, wrong, raising or crashing) never is; agreeing
pairs and timeouts are not asked again, and a second asking that runs out of time flags
nothing; without the option nothing is; the command line prints what the check found and
keeps the option on resume."""

from __future__ import annotations

import json
import pickle
import time
from dataclasses import replace
from pathlib import Path
from typing import Any, ClassVar

import pandas as pd
import pytest

from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.core.contract import Adapter
from crosscheck.core.model import Observation, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.repeats import FILE, NOT_CHECKED
from crosscheck.results.run import read_run
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from crosscheck.run.repeat import RepeatJob
from crosscheck.testing.samples import sphere_pair
from crosscheck.truth import oracle
from tests import fakes
from tests.conftest import ROOT

CASES = load_paths([ROOT / "cases" / "sphere.toml"]).cases[:6]


def run_with(folder: Path, engines: list[Adapter], cases: list[AnyCase] | None = None,
             **options: Any) -> tuple[RunInfo, pd.DataFrame]:
    """A quick run of ``cases`` (the first sphere cases) into ``folder`` with the repeat check
    (unless ``options`` say otherwise): its info and rows."""
    cases = CASES if cases is None else cases
    chosen = replace(RunOptions(quick=True, repeat_check=True), **options)
    info = launch(ResultsStore(folder), cases, engines, chosen,
                  new_info(folder, "test", chosen, engines, cases)).info
    return info, read_run(folder).results


def distances(frame: pd.DataFrame, engine: str) -> pd.DataFrame:
    return frame[(frame["engine"] == engine) & (frame["quantity"] == "distance")]


def test_an_engine_answering_from_its_process_count_is_flagged_with_both_answers(
        tmp_path: Path) -> None:
    info, frame = run_with(tmp_path / "run", [fakes.DriftsWithEachQuery()])
    rows = distances(frame, "fake-drifts")
    assert len(rows) == len(CASES)
    order = [c.id for c in CASES]
    for row in rows.to_dict("records"):
        k = order.index(row["case_id"])
        truth = oracle.truth(CASES[k]).distance
        assert isinstance(truth, float)
        # asked again in a worker started for the batch (the fake's cases, in the reverse of
        # the run's order): the case's place in the batch is its query count there
        place = len(CASES) - k
        assert float(row["repeat_value"]) == truth + place * fakes.DriftsWithEachQuery.STEP
        assert row["repeat_status"] == Status.DISAGREE
        assert row["nondeterministic"] == (row["value"] != row["repeat_value"])
    flagged = rows[rows["nondeterministic"]]
    assert len(flagged) >= len(CASES) - 1  # one case may meet its first count again
    # every row of a flagged pair carries the flag, its other quantities their second answer
    pairs = frame[frame["case_id"].isin(flagged["case_id"])]
    assert pairs["nondeterministic"].all() and (pairs["repeat_status"] != "").all()
    assert info.repeat_check == {"pairs": len(CASES), "nondeterministic": len(flagged),
                                 "seconds": info.repeat_check["seconds"],  # type: ignore[index]
                                 "scenes": False}


def test_in_process_the_pair_is_asked_again_in_this_process(tmp_path: Path) -> None:
    _, frame = run_with(tmp_path / "run", [fakes.DriftsWithEachQuery()], isolate=False)
    rows = distances(frame, "fake-drifts")
    assert rows["nondeterministic"].all()  # the count went on: every answer changed
    assert (rows["repeat_value"] != rows["value"]).all()


def test_engines_that_answer_the_same_are_never_flagged(tmp_path: Path) -> None:
    cases = [*CASES[:2], sphere_pair(0.0, 2.0).model_copy(update={"id": "boom"})]
    _, frame = run_with(tmp_path / "run", [fakes.OffByOne(), fakes.Raises(),
                                           fakes.CrashesOnSpheresAt(), fakes.AlwaysRight()],
                        cases)
    assert not frame["nondeterministic"].any()
    asked = frame[frame["repeat_status"] != ""]
    assert set(asked["engine"]) == {"fake-off", "fake-raises", "fake-boom"}
    assert (asked["repeat_status"] == asked["status"]).all()
    assert (asked["repeat_value"] == asked["value"]).all()
    boom = asked[asked["engine"] == "fake-boom"]
    assert set(boom["case_id"]) == {"boom"} and (boom["repeat_status"] == Status.CRASH).all()
    agreeing = frame[frame["engine"] == "fake-right"]
    assert (agreeing["repeat_status"] == "").all() and agreeing["repeat_value"].isna().all()


def test_a_timeout_is_not_asked_again(tmp_path: Path) -> None:
    _, frame = run_with(tmp_path / "run", [fakes.SleepsForever()], CASES[:1], timeout_s=0.5)
    assert (frame["status"] == Status.TIMEOUT).all()
    assert (frame["repeat_status"] == "").all()
    assert not (tmp_path / "run" / FILE).exists()


class HangsWhenFresh(fakes.OffByOne):
    """Wrong by 1.0 on the distance; on the case :data:`SLOW`, asked first in its process (as
    the repeat check asks it: the last case of the run, first in its reversed batch), it
    never returns."""

    name: ClassVar[str] = "fake-hangs-when-fresh"
    asked: ClassVar[int] = 0

    def query(self, prepared: Any) -> Observation:
        HangsWhenFresh.asked += 1
        while prepared.id == SLOW and HangsWhenFresh.asked == 1:
            time.sleep(1.0)
        return super().query(prepared)


SLOW = CASES[2].id


def test_a_second_asking_that_runs_out_of_time_flags_nothing(tmp_path: Path) -> None:
    _, frame = run_with(tmp_path / "run", [HangsWhenFresh()], CASES[:3], timeout_s=0.5)
    assert (frame[frame["quantity"] == "distance"]["status"] == Status.DISAGREE).all()
    slow = frame[frame["case_id"] == SLOW]
    assert (slow["repeat_status"] == Status.TIMEOUT).all()
    assert not frame["nondeterministic"].any()


def test_without_the_option_nothing_is_asked_again(tmp_path: Path) -> None:
    info, frame = run_with(tmp_path / "run", [fakes.DriftsWithEachQuery()], repeat_check=False)
    assert info.repeat_check is None
    assert not (tmp_path / "run" / FILE).exists()
    for name, value in NOT_CHECKED.items():
        assert frame[name].map(lambda v, value=value: v == value or v is value).all(), name
    stored = json.loads((tmp_path / "run" / "run.json").read_text())
    assert stored["repeat_check"] is None and stored["options"]["repeat_check"] is False


def test_the_command_line_runs_the_check_says_what_it_found_and_resume_keeps_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    spheres = str(ROOT / "cases" / "sphere.toml")
    assert main(["run", spheres, "--engine", "reference-f32", "--quick", "--repeat-check",
                 "--out", str(out)]) == 0
    stored = read_run(out)
    check = stored.info.repeat_check
    assert stored.info.options.repeat_check and check is not None
    asked = stored.results[stored.results["repeat_status"] != ""]
    assert check["pairs"] == len(asked.drop_duplicates(["case_id", "engine"])) > 0
    printed = " ".join(capsys.readouterr().out.split())
    assert (f"repeat check: {check['pairs']} pairs asked again in {check['seconds']:.0f} s; "
            f"{check['nondeterministic']} answered differently (nondeterministic)") in printed
    assert main(["run", "--resume", str(out), "--repeat-check"]) == 2  # it keeps its options
    assert "--repeat-check" in " ".join(capsys.readouterr().err.split())


def test_the_repeat_job_travels_to_a_dask_worker_as_the_adapters_classes() -> None:
    job = RepeatJob((fakes.OffByOne(), fakes.DriftsWithEachQuery()), RunOptions(quick=True))
    copy = pickle.loads(pickle.dumps(job))
    assert [type(a) for a in copy.adapters] == [fakes.OffByOne, fakes.DriftsWithEachQuery]
    assert copy.options == job.options


FAST = [c for c in load_paths([ROOT / "cases" / "fast.toml"]).cases
        if c.id.startswith("fast-head-on.dt=0.0166667.step_travel=0.5,")][:2]


@pytest.mark.parametrize("files, asked", [(["cases/fast.toml"], False),
                                          (["cases/fast.toml", "cases-deep/scenes.toml"], True)])
def test_scene_pairs_are_asked_again_in_the_deep_tier_only(
        tmp_path: Path, files: list[str], asked: bool) -> None:
    from crosscheck.cli.engines import select

    engines = select(["pymunk"])
    chosen = RunOptions(repeat_check=True, timing_cases=0)
    folder = tmp_path / "run"
    info = launch(ResultsStore(folder), FAST, engines, chosen,
                  new_info(folder, "test", chosen, engines, FAST, files)).info
    frame = read_run(folder).results
    disagreeing = frame[frame["status"] == Status.DISAGREE]["case_id"].nunique()
    assert disagreeing == len(FAST)  # the fast head-on pass-through: pymunk misses it
    assert info.tier == ("deep" if asked else "standard")
    assert info.repeat_check is not None and info.repeat_check["scenes"] is asked
    assert info.repeat_check["pairs"] == (len(FAST) if asked else 0)
    assert ((frame["repeat_status"] != "").all() if asked
            else (frame["repeat_status"] == "").all())
