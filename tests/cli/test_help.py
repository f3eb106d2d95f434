"""Every command's help reads at 80 columns, and every option and positional says what it is
and, where it has one, its default."""

from __future__ import annotations

import argparse

import pytest

from crosscheck.cli import build_parser
from tools.cli_page import commands

COMMANDS = [name for name, _sub, _help in commands(build_parser())]


def _no_default(action: argparse.Action) -> bool:
    return action.default in (None, False, argparse.SUPPRESS) or action.default == []


@pytest.mark.parametrize("name", ["", *COMMANDS])
def test_help_fits_in_80_columns(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    parser = build_parser()
    found = {n: sub for n, sub, _help in commands(parser)}
    text = (found[name] if name else parser).format_help()
    assert [line for line in text.splitlines() if len(line) > 80] == []


@pytest.mark.parametrize("name", COMMANDS)
def test_every_option_has_help_and_states_its_default(name: str) -> None:
    (sub,) = [s for n, s, _help in commands(build_parser()) if n == name]
    for action in sub._actions:
        if action.help == argparse.SUPPRESS or "-h" in action.option_strings:
            continue
        what = action.option_strings or [action.dest]
        assert action.help, f"{name} {what}: no help"
        if not _no_default(action):
            assert "default" in action.help, f"{name} {what}: default {action.default!r} unsaid"


def test_the_checks_catch_a_silent_option() -> None:
    parser = argparse.ArgumentParser()
    silent = parser.add_argument("--speed", type=float, default=2.0, help="how fast")
    assert not _no_default(silent) and "default" not in (silent.help or "")
