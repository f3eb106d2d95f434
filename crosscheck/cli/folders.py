"""Where a command writes its output folder: one rule for every ``--out`` that names a folder.

A bare name (no ``/``, such as ``--out full``) goes under ``reports/``, beside the default
folders and ignored by git like them; a path with a slash (``./full``, ``runs/full``) or
an absolute path is taken as given.
"""

from __future__ import annotations

import os
from pathlib import Path

from crosscheck.cli.console import say

REPORTS = Path("reports")
"""Where every command puts its folders unless told otherwise (relative to the current
folder)."""

OUT_RULE = "a bare name goes under reports/; a path with a slash is taken as given"
"""The rule in a few words, for each ``--out`` help."""


def is_bare(text: str) -> bool:
    """Whether ``text`` is a bare folder name (no folder part), which goes under reports/.

    >>> is_bare("full"), is_bare("./full"), is_bare("runs/full"), is_bare("/tmp/full")
    (True, False, False, False)
    >>> is_bare("."), is_bare("..")
    (False, False)
    """
    separators = [sep for sep in (os.sep, os.altsep) if sep]
    return text not in (".", "..") and not any(sep in text for sep in separators)


def out_folder(text: str) -> Path:
    """The folder ``--out text`` names: ``reports/text`` for a bare name, else ``text``.

    >>> str(out_folder("full")), str(out_folder("./full")), str(out_folder("/tmp/full"))
    ('reports/full', 'full', '/tmp/full')
    """
    return REPORTS / text if is_bare(text) else Path(text)


def chosen(text: str | None) -> Path | None:
    """The folder ``--out text`` names (None without ``--out``); where a bare name went is
    said on stdout first, so the output's first line names the folder it goes to."""
    if text is None:
        return None
    if is_bare(text):
        say(f"--out {text}: a bare name goes under reports/, so the output is in "
            f"{out_folder(text)}")
    return out_folder(text)
