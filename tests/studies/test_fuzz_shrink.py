"""Shrinking fuzz findings: a noisy case shrinks to the minimal case that fails the same way,
a candidate that crashes the engine is rejected, the call budget holds, and a campaign writes
each group's shrunk case beside its original (also when resumed)."""

from __future__ import annotations

import json
import os
import re
import time
from dataclasses import replace
from pathlib import Path
from typing import Any, ClassVar

import pytest

from crosscheck.cases.load import load_paths
from crosscheck.core.contract import Adapter
from crosscheck.core.model import Kind, Observation, Record
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, AabbCase, AnyCase
from crosscheck.run.execute import Outcome, execute
from crosscheck.run.scoring import score_case
from crosscheck.run.worker import WorkerPool
from crosscheck.studies.fuzz import campaign
from crosscheck.studies.fuzz.findings import Signature
from crosscheck.studies.fuzz.shrink import (
    HANGS,
    MAX_CALLS,
    build,
    complexity,
    in_contact,
    numbers,
    shrink_case,
)
from crosscheck.testing.fakes import AlwaysRight, OffByOne
from crosscheck.truth import oracle


def gap_along_y(case: AabbCase) -> float:
    return abs(case.b.center[1] - case.a.center[1]) - (case.a.half[1] + case.b.half[1])


class WrongApartAlongY(AlwaysRight):
    """Boxes: the distance 0.5 too large whenever B is apart from A along y by more than 1."""

    name: ClassVar[str] = "fake-wrong-apart-along-y"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        if gap_along_y(prepared) > 1:
            assert isinstance(truth.distance, float)
            return replace(truth, distance=truth.distance + 0.5)
        return truth


class AbortsAtTheOrigin(WrongApartAlongY):
    """As WrongApartAlongY, but kills its process (SIGABRT) when A's centre is the origin."""

    name: ClassVar[str] = "fake-aborts-at-the-origin"

    def query(self, prepared: Any) -> Observation:
        if not any(prepared.a.center):
            os.abort()
        return super().query(prepared)


class HangsAlways(AlwaysRight):
    """Never answers."""

    name: ClassVar[str] = "fake-hangs-always"

    def query(self, prepared: Any) -> Observation:
        while True:
            time.sleep(0.05)


NOISY = CASE_ADAPTER.validate_python({
    "id": "noisy", "description": "offset 1e6 on every axis, 17-digit numbers", "kind": "aabb",
    "dim": 3,
    "a": {"center": [1000000.1234567891, 1000000.9876543211, 999999.6180339887],
          "half": [0.7310585786300049, 0.41421356237309515, 0.8660254037844386]},
    "b": {"center": [1000000.4142135624, 1000003.9602847568, 999999.7320508076],
          "half": [0.5772156649015329, 0.6931471805599453, 0.3183098861837907]}})
WRONG_DISTANCE = Signature("distance", "disagree", "error")
OPTIONS = RunOptions(quick=True)


class Counted:
    """An in-process executor that counts its calls."""

    def __init__(self) -> None:
        self.calls = 0

    def __call__(self, adapter: Adapter, case: AnyCase, options: RunOptions,
                 timed: bool = False, skip: frozenset[str] = frozenset()) -> Outcome:
        self.calls += 1
        return execute(adapter, case, options, timed, skip)


def failing_record(case: AnyCase, adapter: Adapter, signature: Signature,
                   outcome: Outcome | None = None) -> Record | None:
    """The record of ``case`` on ``adapter``, scored by the harness, that has ``signature``."""
    outcome = outcome or execute(adapter, case, OPTIONS)
    records = score_case(case, adapter, outcome, oracle.truth(case))
    return next((r for r in records if signature.matches(r)), None)


def verdict(record: Record | None) -> tuple[Any, ...] | None:
    """What a record says (its timings aside)."""
    if record is None:
        return None
    return (record.case_id, record.engine, record.quantity, record.status, record.category,
            record.value, record.truth, record.error)


def boxes(case: AnyCase) -> tuple[list[float], ...]:
    assert isinstance(case, AabbCase)
    return list(case.a.center), list(case.a.half), list(case.b.center), list(case.b.half)


def test_a_noisy_finding_shrinks_to_the_minimal_case_that_fails_the_same_way() -> None:
    engine, counted = WrongApartAlongY(), Counted()
    assert failing_record(NOISY, engine, WRONG_DISTANCE) is not None  # the finding
    shrunk = shrink_case(NOISY, engine, WRONG_DISTANCE, counted, OPTIONS)
    # the offset is gone, every number is round; B's half-height 0.7 keeps the y gap above 1
    # (1 would close it to exactly 1) and is nearer 1 than 0.5, as is B at y = 3 than at 4
    assert boxes(shrunk.case) == ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0],
                                  [0.0, 3.0, 0.0], [1.0, 0.7, 1.0])
    assert shrunk.changed and shrunk.crashed == 0
    assert shrunk.calls == counted.calls < MAX_CALLS
    again = failing_record(shrunk.case, engine, WRONG_DISTANCE)
    assert again is not None and verdict(again) == verdict(shrunk.record)
    assert (again.value, again.truth) == ("1.8", "1.3")  # distance 1.3, the engine's +0.5
    assert complexity(numbers(shrunk.case)) < complexity(numbers(NOISY))
    assert [kind for kind, _ in shrunk.steps[:3]] == ["translated"] * 3
    minimal = shrink_case(shrunk.case, engine, WRONG_DISTANCE, Counted(), OPTIONS)
    assert minimal.case == shrunk.case and not minimal.steps  # nothing simpler fails


def test_a_candidate_that_crashes_the_engine_is_rejected_and_the_shrink_goes_on() -> None:
    engine = AbortsAtTheOrigin()
    pool = WorkerPool(OPTIONS)
    try:
        shrunk = shrink_case(NOISY, engine, WRONG_DISTANCE, pool, OPTIONS)
        outcome = pool(engine, shrunk.case, OPTIONS)
    finally:
        pool.close()
    assert shrunk.crashed >= 1 and pool.started >= 2  # it crashed, a fresh worker went on
    # as without the crash, but A's centre is never the origin, where the engine aborts
    assert boxes(shrunk.case) == ([0.0, 0.0, -1.0], [1.0, 1.0, 1.0],
                                  [0.0, 3.0, 0.0], [1.0, 0.7, 1.0])
    assert outcome.status is None  # the shrunk case itself runs, and fails the same way
    assert verdict(failing_record(shrunk.case, engine, WRONG_DISTANCE, outcome)) == verdict(
        shrunk.record)


@pytest.mark.parametrize("budget", [1, 2, 7, 20])
def test_the_call_budget_is_respected_and_the_best_so_far_still_fails(budget: int) -> None:
    counted = Counted()
    shrunk = shrink_case(NOISY, WrongApartAlongY(), WRONG_DISTANCE, counted, OPTIONS,
                         max_calls=budget)
    assert shrunk.calls == counted.calls == budget
    assert shrunk.changed == (budget > 1)  # the first call re-runs the finding itself
    again = failing_record(shrunk.case, WrongApartAlongY(), WRONG_DISTANCE)
    assert again is not None and verdict(again) == verdict(shrunk.record)


def test_hanging_candidates_stop_the_shrink_after_a_few() -> None:
    options = RunOptions(quick=True, timeout_s=0.2)
    pool = WorkerPool(options)
    try:
        shrunk = shrink_case(NOISY, HangsAlways(), Signature("distance", "timeout", ""), pool,
                             options)
    finally:
        pool.close()
    assert shrunk.calls == shrunk.crashed == HANGS  # each hung: the same way, and costly
    assert shrunk.changed and shrunk.record is not None


@pytest.mark.parametrize("signature", [Signature("distance", "disagree", "convention"),
                                       Signature("hit", "disagree", "error")])
def test_a_finding_that_does_not_fail_the_same_way_again_is_not_shrunk(
        signature: Signature) -> None:
    counted = Counted()
    shrunk = shrink_case(NOISY, WrongApartAlongY(), signature, counted, OPTIONS)
    assert (shrunk.record, shrunk.case, shrunk.calls, counted.calls) == (None, NOISY, 1, 1)
    assert not shrunk.changed


# --- in a campaign --------------------------------------------------------------------------

def blocks(path: Path) -> list[AnyCase]:
    loaded = load_paths([path])
    assert loaded.errors == []
    return [c for c in loaded.cases if "swapped" not in c.tags]


def shrunk_pairs(directory: Path) -> list[tuple[AnyCase, AnyCase]]:
    """(shrunk case, the original just after it) in every file of a campaign."""
    pairs = []
    for path in sorted(directory.glob("*.toml")):
        cases = blocks(path)
        for i, case in enumerate(cases):
            if "shrunk" in case.tags:
                assert cases[i + 1].id + "-shrunk" == case.id
                pairs.append((case, cases[i + 1]))
    return pairs


N = 40


def test_a_campaign_writes_each_groups_shrunk_case_before_its_original(tmp_path: Path) -> None:
    engine = OffByOne()
    groups = campaign.fuzz(Kind.SPHERE, N, 3, tmp_path / "on", [engine],
                           RunOptions(quick=True, jobs=1), per_group=2)
    written = [g for g in groups if g.chosen]
    pairs = shrunk_pairs(tmp_path / "on")
    assert written and len(pairs) == len(written)  # the first representative of each group
    assert all(g.shrunk == [g.chosen[0] + "-shrunk"] for g in written)
    for small, original in pairs:
        words = small.description
        assert words.startswith(f"Shrunk from {original.id} in ")
        assert re.search(r"Fails the same way: fake-off distance \S+ vs truth \S+ "
                         r"\(error, error 1\)\. The original: fake-off distance", words)
        assert complexity(numbers(small)) < complexity(numbers(original))
        assert failing_record(small, engine, WRONG_DISTANCE) is not None
    whole = json.loads((tmp_path / "on" / "fuzz.json").read_text())
    info = whole["shrink"]
    assert whole["shrink_per_group"] == 1 and info["written"] == len(pairs)
    assert info["calls"] == sum(f["calls"] for f in info["findings"]) <= MAX_CALLS * len(pairs)
    on, off = tmp_path / "on", tmp_path / "off"
    campaign.fuzz(Kind.SPHERE, N, 3, off, [engine], RunOptions(quick=True), per_group=2,
                  shrink=0)
    assert shrunk_pairs(off) == [] and toml_files(off).keys() == toml_files(on).keys()
    for path in sorted(off.glob("*.toml")):  # the same originals, in the same files
        assert [(c.id, c.description) for c in blocks(path)] == [
            (c.id, c.description) for c in blocks(on / path.name) if "shrunk" not in c.tags]
    assert (on / "findings.csv").read_text() == (off / "findings.csv").read_text()


def toml_files(directory: Path) -> dict[str, str]:
    return {p.name: p.read_text() for p in sorted(directory.glob("*.toml"))}


def test_a_resumed_campaign_shrinks_as_an_uninterrupted_one(tmp_path: Path) -> None:
    """Killed after its chunk, before its findings were written; its plan from before
    shrinking existed (no ``shrink`` in campaign.json): resumed, it shrinks by default."""
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    for directory in (whole, killed):
        campaign.fuzz(Kind.SPHERE, N, 5, directory, [OffByOne()], RunOptions(quick=True),
                      per_group=2, command="cmd")
    for path in [*killed.glob("*.toml"), killed / "fuzz.json", killed / "findings.csv"]:
        path.unlink()
    plan = json.loads((killed / campaign.PLAN).read_text())
    del plan["shrink"]
    (killed / campaign.PLAN).write_text(json.dumps(plan))
    campaign.resume(killed, lambda names: [OffByOne() for _ in names])
    assert toml_files(killed) == toml_files(whole) and any(
        "-shrunk" in text for text in toml_files(whole).values())
    info = json.loads((killed / "fuzz.json").read_text())
    assert info["chunks_run"] == 0 and info["shrink_per_group"] == campaign.SHRINK


def test_a_response_in_contact_shrinks_only_to_responses_in_contact() -> None:
    touching = CASE_ADAPTER.validate_python({
        "id": "r", "description": "d", "kind": "sphere_response", "dim": 2,
        "a": {"center": [0.0, 0.0], "radius": 1.0, "mass": 1.0, "velocity": [1.0, 0.0]},
        "b": {"center": [2.0, 0.0], "radius": 1.0, "mass": 1.0, "velocity": [0.0, 0.0]}})
    assert in_contact(touching)
    apart = numbers(touching) | {("b", "center", 0): 1e9}
    assert build(touching, apart) is None  # moved apart: another question
    closer = numbers(touching) | {("b", "center", 0): 1.5}
    assert build(touching, closer) is not None
