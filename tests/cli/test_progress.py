"""Plain progress (a log or a pipe) never goes silent: a line each tenth of the way and at
least every ten seconds while a phase advances, each with the time taken and the time left
at the rate so far (the clock injected, so nothing here is timed)."""

from __future__ import annotations

import pytest

from crosscheck.cli.console import QUIET_S, PlainProgress


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def lines(capsys: pytest.CaptureFixture[str]) -> list[str]:
    return capsys.readouterr().err.splitlines()


def test_each_tenth_is_said_with_the_time_left_at_the_rate_so_far(
        capsys: pytest.CaptureFixture[str]) -> None:
    clock = Clock()
    progress = PlainProgress("case x engine", 200, clock)
    clock.now += 4.0
    progress(20)
    assert lines(capsys) == ["case x engine: 200 to go",
                             "case x engine: 20/200 (10%, 4 s, about 36 s left)"]
    clock.now += 1.0
    progress(9)  # short of the next tenth, and not quiet for long: nothing said
    assert lines(capsys) == []


def test_a_phase_that_stalls_is_said_again_after_ten_quiet_seconds(
        capsys: pytest.CaptureFixture[str]) -> None:
    clock = Clock()
    progress = PlainProgress("repeat check", 1000, clock)
    progress(1)
    clock.now += QUIET_S - 0.5
    progress.beat()
    assert lines(capsys) == ["repeat check: 1000 to go"]
    clock.now += 0.5
    progress.beat()  # nothing finished, but ten seconds have passed since the last line
    assert lines(capsys) == ["repeat check: 1/1000 (0%, 10 s, about 9990 s left)"]
    progress(999)
    clock.now += 60.0
    progress.beat()  # done: nothing more to say
    assert lines(capsys) == ["repeat check: 1000/1000 (100%, 10 s)"]
