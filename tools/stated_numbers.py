"""The stated-number rule: no page states a measured count, size or time in its own words.

Measured figures go stale (a README once said 277 curated cases when there were 297), so
they are written only by ``make docs-figures`` into ``docs/generated/`` and included from
there.  This check reads every page of ``docs/`` outside ``docs/generated/`` and README.md
outside its generated blocks (``<!-- generated: NAME.md -->`` ... ``<!-- end generated -->``),
and flags, in prose (not in fenced code blocks, inline ``code``, HTML comments or link
addresses), a number (digits, possibly with ``,`` ``.`` ``e`` or ``^``) followed by:

- a unit of time: ns, µs, us, ms, s, sec, seconds, min, minutes, h, hours;
- a unit of size: B, bytes, KB, kB, KiB, MB, MiB, GB, GiB;
- ``%`` (or "percent"), or an ``x`` / ``\u00d7`` speed ratio (``4.2x``, ``3 x faster``; not
  ``1400 x 1000`` or ``2 x jobs``);
- a count noun: cases, rows, pairs, tests, items, runs, samples, lines, engines, variants,
  modules, pages, chunks, findings, px (singular too, and after k, M or million).

A setting or a default is written as code (```--timeout 30```), a declared value too; units
such as m/s and version numbers (3.2.7) are not flagged.

>>> [f.match for f in findings("The suite took 130 s; the page is 2.8 MB and 43% agree.")]
['130 s', '2.8 MB', '43%']
>>> findings("Use `--timeout 30` with version 3.2.7 at 1 m/s.")
[]

    python -m tools.stated_numbers          # check README.md and docs/; exit 1 on a finding
"""

from __future__ import annotations

import re
import sys
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GENERATED = "docs/generated"

TIME = ("ns", "µs", "μs", "us", "ms", "s", "sec", "secs", "seconds?", "min", "mins", "minutes?",
        "h", "hrs?", "hours?")
SIZE = ("B", "bytes?", "KB", "kB", "KiB", "MB", "MiB", "GB", "GiB")
NOUNS = ("cases?", "rows?", "pairs?", "tests?", "items?", "runs?", "samples?", "lines?",
         "engines?", "variants?", "modules?", "pages?", "chunks?", "findings?", "px")
_SPACE = r"[ \u00a0\u202f]?"
_NUMBER = r"(?<![\w.,^/-])\d[\d,]*(?:\.\d+)?(?:[eE][-+]?\d+)?(?:\^-?\d+)?(?![.,]?\d)"
STATED = re.compile(
    _NUMBER + "(?:"
    + _SPACE + "(?:" + "|".join(TIME + SIZE) + r")(?![\w%])"
    + "|" + _SPACE + r"(?:%|percent\b)"
    + "|" + r"[x\u00d7](?!\w)(?!\s*\d)"
    + "|" + r"[ \u00a0\u202f][x\u00d7](?=\s*(?:$|[.,;:)\]|]|faster|slower|quicker|as\b))"
    + "|" + r"[ \u00a0\u202f](?:(?:k|K|M|thousand|million|billion) )?(?i:"
    + "|".join(NOUNS) + r")(?!\w)"
    + ")")
"""A number and the unit or count noun after it."""

_FENCE = re.compile(r"^\s*(`{3,}|~{3,})")
_COMMENT = re.compile(r"<!--.*?-->", re.S)
_CODE = re.compile(r"(`+)(?:(?!\n\s*\n).)+?\1", re.S)
_LINK_TARGET = re.compile(r"\]\([^)]*\)|<https?://[^>]*>|https?://\S+")
_SNIPPET = re.compile(r'^\s*-{1,2}8<-{1,2}\s.*$', re.M)
_BLOCK = re.compile(r"<!-- generated: (?P<name>[\w.-]+) -->\n(?P<body>.*?)<!-- end generated -->",
                    re.S)


@dataclass(frozen=True)
class Finding:
    """A stated measured number: where it is and what it says."""

    path: str
    line: int
    match: str
    text: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: states {self.match!r}: {self.text.strip()}"


def _blank(match: re.Match[str]) -> str:
    """The matched text as blanks, its line breaks kept (line numbers stay right)."""
    return re.sub(r"[^\n]", " ", match.group(0))


def without_fences(text: str) -> str:
    """``text`` with every fenced code block blanked (an unclosed fence runs to the end)."""
    out, fence = [], ""
    for line in text.split("\n"):
        opened = _FENCE.match(line)
        if fence:
            if opened and opened.group(1)[0] == fence[0] and len(opened.group(1)) >= len(fence):
                fence = ""
            out.append("")
        elif opened:
            fence = opened.group(1)
            out.append("")
        else:
            out.append(line)
    return "\n".join(out)


def without_generated_blocks(text: str) -> str:
    """README text with the body of every generated block blanked."""
    return _BLOCK.sub(_blank, text)


def prose(text: str) -> str:
    """The prose of Markdown ``text``: no fenced blocks, HTML comments, inline code, snippet
    includes or link addresses (blanked, so line numbers stay)."""
    text = without_fences(text)
    for pattern in (_COMMENT, _CODE, _SNIPPET, _LINK_TARGET):
        text = pattern.sub(_blank, text)
    return text


def findings(text: str, path: str = "<text>") -> list[Finding]:
    """Every stated measured number in the prose of ``text``.

    >>> [f.match for f in findings("934 cases, 1,654 items in 63 modules; 4.2x, 3 x faster")]
    ['934 cases', '1,654 items', '63 modules', '4.2x', '3 x']
    >>> findings("at most 2 x jobs cases in flight, 1e-12 x the size")
    []
    >>> findings("```\\ntook 130 s\\n```\\na 1400 x 1000 view, Python 3.11, 2-D cases")
    []
    """
    lines = text.split("\n")
    found = []
    for number, line in enumerate(prose(text).split("\n"), start=1):
        found += [Finding(path, number, m.group(0), lines[number - 1])
                  for m in STATED.finditer(line)]
    return found


def pages(root: Path = ROOT) -> list[Path]:
    """README.md and every Markdown page of docs/ outside docs/generated/."""
    docs = sorted(p for p in (root / "docs").rglob("*.md")
                  if not p.relative_to(root).as_posix().startswith(GENERATED + "/"))
    readme = root / "README.md"
    return ([readme] if readme.exists() else []) + docs


def check(paths: Iterable[Path], root: Path = ROOT) -> list[Finding]:
    """The findings of every page (README.md's generated blocks left out)."""
    found = []
    for path in paths:
        text = path.read_text(encoding="utf-8")
        if path.name == "README.md":
            text = without_generated_blocks(text)
        name = path.relative_to(root).as_posix() if path.is_relative_to(root) else str(path)
        found += findings(text, name)
    return found


def main(argv: Sequence[str] | None = None) -> int:
    """Print every finding of the given pages (default: README.md and docs/); exit 1 if any."""
    args = list(sys.argv[1:] if argv is None else argv)
    found = check([Path(a).resolve() for a in args] if args else pages())
    for finding in found:
        print(finding)
    if found:
        print(f"{len(found)} stated numbers: include them from docs/generated/ "
              "(make docs-figures) or write a setting as `code`", file=sys.stderr)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
