"""The terminal reads at 80 columns: every command's help fits, every option and positional
says what it is and, where it has one, its default; ``engines --settings`` in a file keeps
every variant's settings whole."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import pytest

import adapters
from crosscheck.cli import build_parser
from crosscheck.core.contract import engine_info
from tests.conftest import ROOT
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


@pytest.mark.engine
def test_engines_settings_read_at_80_columns_in_a_file(tmp_path: Path) -> None:
    # piped to a file at 80 columns: no line over 80, and every variant's settings whole
    env = {**os.environ, "COLUMNS": "80", "PYTHONPATH": str(ROOT)}
    printed = subprocess.run([sys.executable, "-m", "crosscheck.cli", "engines", "--settings"],
                             env=env, capture_output=True, text=True, check=True).stdout
    assert [line for line in printed.splitlines() if len(line) > 80] == []
    assert "\u2026" not in printed  # no cell cut with an ellipsis
    flat = " ".join(printed.split())
    for entry in adapters.entries():
        if entry.problem() is None:
            settings = str(engine_info(entry.load()())["settings"])
            assert " ".join(settings.split()) in flat, entry.name
