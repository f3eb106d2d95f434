"""Every link of README.md and of docs/ leads to a file of the repository or to an http(s)
address: no pointer outside the project (such as ``../shared``)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tools.stated_numbers import ROOT, without_fences

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)"
                  r"|^\s*\[[^\]]+\]:\s*<?(\S+?)>?(?:\s|$)"
                  r"|<(?:img|a|source)\b[^>]*?\b(?:src|href)=\"([^\"]+)\"", re.M)
CODE = re.compile(r"(`+)(?:(?!\n\s*\n).)+?\1", re.S)
ELSEWHERE = ("http://", "https://", "mailto:")


def targets(text: str) -> list[str]:
    """The link targets of Markdown ``text`` (not those shown as code)."""
    prose = CODE.sub("", without_fences(text))
    return [next(g for g in m.groups() if g) for m in LINK.finditer(prose)]


def outside(page: Path, target: str) -> str:
    """Why ``target`` of ``page`` leads outside the repository's files ('' when it does not)."""
    if target.startswith(ELSEWHERE) or target.startswith("#"):
        return ""
    if "://" in target or target.startswith("/"):
        return f"{target}: not an http(s) address nor a path in the repository"
    path = (page.parent / target.split("#")[0].split("?")[0]).resolve()
    if not path.is_relative_to(ROOT):
        return f"{target}: outside the repository"
    if not path.exists():
        return f"{target}: no such file in the repository"
    return ""


def test_the_link_reader_finds_every_form() -> None:
    text = ("[a](docs/x.md#y) ![b](images/c.png \"t\") <img src=\"d.png\">\n[ref]: ../e.md\n"
            "`[not](code.md)`\n```\n[no](fenced.md)\n```\n")
    assert targets(text) == ["docs/x.md#y", "images/c.png", "d.png", "../e.md"]


def test_a_pointer_outside_the_repository_is_refused() -> None:
    page = ROOT / "docs" / "index.md"
    assert outside(page, "../../shared/ARCHITECTURE.md").endswith("outside the repository")
    assert outside(page, "file:///etc/passwd") and outside(page, "missing-page.md")
    assert outside(page, "https://wp.freya.no/") == outside(page, "engines.md#pybullet") == ""


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_link_stays_in_the_repository(page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    problems = [why for t in targets(text) if (why := outside(page, t))]
    assert not problems, problems
    assert "../shared" not in text
