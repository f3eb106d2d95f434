"""README.md is a front page: at most 150 lines, ``make run`` and ``make test`` first, and its
generated blocks exactly the files ``make docs-figures`` wrote."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tools import docs_figures
from tools.stated_numbers import without_fences

README = docs_figures.README
FENCED = re.compile(r"^\s*(`{3,}|~{3,})[^\n]*\n(.*?)^\s*\1", re.S | re.M)


def commands(text: str) -> list[str]:
    """The command lines of the fenced blocks of ``text``, in order (no comments, no prompts)."""
    lines = []
    for block in FENCED.finditer(text):
        for line in block.group(2).splitlines():
            line = line.strip().removeprefix("$ ")
            if line and not line.startswith("#"):
                lines.append(line)
    return lines


def test_readme_is_at_most_150_lines() -> None:
    lines = README.read_text(encoding="utf-8").count("\n")
    assert lines <= 150, f"README.md has {lines} lines; the docs pages say the rest"


def test_the_first_two_commands_are_make_run_and_make_test() -> None:
    first = commands(README.read_text(encoding="utf-8"))[:2]
    assert [line.split()[:2] for line in first] == [["make", "run"], ["make", "test"]], first


def test_the_command_reader_finds_commands_in_order() -> None:
    text = "intro `make lint`\n```sh\n$ make run   # all\n# a comment\nmake test\n```\n"
    assert commands(text) == ["make run   # all", "make test"]


def test_every_generated_block_of_the_readme_equals_its_file() -> None:
    text = README.read_text(encoding="utf-8")
    blocks = docs_figures.readme_blocks(text)
    assert set(blocks) >= {"headline.md", "setup.md"}, "README lacks its generated blocks"
    for name, body in blocks.items():
        path = docs_figures.GENERATED / name
        assert path.is_file(), f"README's block names {name}, which is not generated"
        assert body == path.read_text(encoding="utf-8"), f"{name}: run make docs-figures"


def test_rewriting_the_blocks_fills_them_from_the_files(tmp_path: Path) -> None:
    (tmp_path / "headline.md").write_text("<!-- generated -->\n\n| a | b |\n")
    text = "# X\n<!-- generated: headline.md -->\nstale 70 s\n<!-- end generated -->\nend\n"
    filled = docs_figures.with_blocks(text, tmp_path)
    assert filled == ("# X\n<!-- generated: headline.md -->\n<!-- generated -->\n\n| a | b |\n"
                      "<!-- end generated -->\nend\n")
    body = "<!-- generated -->\n\n| a | b |\n"
    assert docs_figures.readme_blocks(filled) == {"headline.md": body}
    assert docs_figures.with_blocks(filled, tmp_path) == filled
    with pytest.raises(SystemExit, match=r"missing\.md"):
        docs_figures.with_blocks("<!-- generated: missing.md -->\n<!-- end generated -->", tmp_path)


def test_the_readme_markers_are_outside_code_blocks() -> None:
    text = README.read_text(encoding="utf-8")
    assert without_fences(text).count("<!-- end generated -->") == text.count(
        "<!-- end generated -->")
