"""``advise`` for stepped scenes: a family by its tags, the least simulated time, and the
settle offset judged in metres (absolute, or relative to the smallest radius)."""

from __future__ import annotations

import argparse

import pytest

from crosscheck.cli.advise import OptionError, envelope_of, register
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from crosscheck.report.advise.recommend import Envelope
from tests.conftest import sphere


def resting(duration: float, tags: list[str]) -> AnyCase:
    return CASE_ADAPTER.validate_python({
        "id": "rest", "description": "d", "kind": "sphere_scene", "dim": 3,
        "duration": duration, "dt": 0.01, "tags": tags, "gravity": [0, 0, -9.81],
        "walls": [{"normal": [0, 0, 1]}],
        "bodies": [{"center": [0, 0, 0.1], "radius": 0.1, "mass": 1, "velocity": [0, 0, 0]}]})


def test_a_tag_keeps_only_the_cases_that_carry_it() -> None:
    profile = Envelope(tags=("resting",))
    assert profile.holds(resting(10.0, ["dynamics", "resting"]))
    assert not profile.holds(resting(10.0, ["dynamics", "bounce"]))


def test_a_duration_keeps_scenes_at_least_that_long_and_leaves_other_kinds_alone() -> None:
    profile = Envelope(duration=10.0)
    assert profile.holds(resting(10.0, []))
    assert not profile.holds(resting(5.0, []))
    assert profile.holds(sphere(0.0, 2.0))  # a limit bounds the kinds that have it


def test_the_settle_offset_is_a_length_for_a_relative_tolerance() -> None:
    assert Envelope(tolerance=1e-3, rtol=0.1).allowed("settle", 0.1) == pytest.approx(0.01)
    assert Envelope(tolerance=1e-3, rtol=0.1).allowed("energy_drift", 0.1) == 0.0
    assert Envelope(fraction_tolerance=1e-3, rtol=0.1).allowed("energy_drift", 0.1) == 1e-3


def parsed(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    return parser.parse_args(["advise", "run", *argv])


def test_the_options_state_the_family_and_the_time() -> None:
    envelope = envelope_of(parsed("--kind", "sphere_scene", "--quantities", "settle",
                                  "--tolerance", "1e-3", "--tag", "resting",
                                  "--duration", "10"))
    assert (envelope.tags, envelope.duration, envelope.quantities) == (
        ("resting",), 10.0, ("settle",))
    with pytest.raises(OptionError, match="--duration"):
        envelope_of(parsed("--duration", "ten"))
    with pytest.raises(ValueError, match="--duration"):
        envelope_of(parsed("--duration", "-1"))


def test_a_time_step_and_an_interval_read_as_written() -> None:
    assert envelope_of(parsed("--kind", "sphere_scene", "--dt", "1/60")).dt == (0.0, 1 / 60)
    assert envelope_of(parsed("--kind", "sphere_scene", "--dt", "1/240:1/60")).dt == (
        1 / 240, 1 / 60)
    assert envelope_of(parsed("--kind", "sphere_toi", "--interval", "2")).interval == (0.0, 2.0)
    for bad in ("1/0", "a/60", "1:2:3"):
        with pytest.raises(OptionError, match="--dt"):
            envelope_of(parsed("--kind", "sphere_scene", "--dt", bad))
