"""docs/generated/cli.md is what crosscheck's argument parser says now, at a fixed width."""

from __future__ import annotations

from pathlib import Path

import pytest

from crosscheck.cli import build_parser
from tools import cli_page


def test_the_committed_cli_page_is_what_the_parser_says() -> None:
    committed = cli_page.PAGE.read_text(encoding="utf-8")
    assert committed == cli_page.render(), "docs/generated/cli.md is out of date: run make cli-page"


def test_every_command_and_option_of_the_parser_is_on_the_page() -> None:
    parser = build_parser()
    page = cli_page.render(build_parser())
    for name, sub, _help in cli_page.commands(parser):
        assert f"### `crosscheck {name}`" in page
        for action in sub._actions:
            if action.help is None or "-h" in action.option_strings:
                continue
            flags = ", ".join(action.option_strings) or str(action.metavar or action.dest)
            assert f"| `{flags}` |" in page, (name, flags)


def test_a_new_option_changes_the_page_with_its_help_and_default() -> None:
    parser = build_parser()
    run = dict((name, sub) for name, sub, _help in cli_page.commands(parser))["run"]
    run.add_argument("--brand-new", type=int, default=7, help="an option nobody documented")
    page = cli_page.render(parser)
    assert page != cli_page.render()
    assert "| `--brand-new` | `7` |  | an option nobody documented |" in page
    assert "--brand-new BRAND_NEW" in page


def test_the_page_does_not_depend_on_the_terminal_width(monkeypatch: pytest.MonkeyPatch) -> None:
    wide = cli_page.render()
    monkeypatch.setenv("COLUMNS", "40")
    assert cli_page.render() == wide
    run_help = wide.split("### `crosscheck run`")[1].split("```text")[1].split("```")[0]
    assert max(len(line) for line in run_help.splitlines()) <= cli_page.WIDTH


def test_the_check_mode_fails_on_a_stale_page(tmp_path: Path) -> None:
    page = tmp_path / "cli.md"
    assert cli_page.main(["--output", str(page)]) == 0
    assert cli_page.main(["--check", "--output", str(page)]) == 0
    page.write_text(page.read_text() + "edited by hand\n")
    assert cli_page.main(["--check", "--output", str(page)]) == 1
