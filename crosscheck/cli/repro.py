"""``crosscheck repro``: standalone scripts that reproduce a case on an engine, bit for bit.

The command of :mod:`crosscheck.studies.repro`: one script goes to stdout (or ``--out
FILE``); several (no ``--engine``, several engines to show) go to one file each, named
``FILE-<engine>.py`` with ``--out FILE``, else ``<repro_name>.py`` in the current folder.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from crosscheck.cli.console import fail, say

if TYPE_CHECKING:
    from crosscheck.studies.repro import Script


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``repro``."""
    p = sub.add_parser("repro", help="a standalone script reproducing a case on an engine")
    p.add_argument("run_dir", type=Path, metavar="RUN_DIR", help="a run folder")
    p.add_argument("case_id", metavar="CASE_ID", help="a case of that run")
    p.add_argument("--engine", help="engine (default: every engine with a non-agree row for "
                                    "the case, else every engine that ran it)")
    p.add_argument("--out", type=Path, metavar="FILE",
                   help="write the script here (default: stdout; FILE-<engine>.py each "
                        "when there are several)")
    p.set_defaults(func=cmd_repro)


SHADOWING = frozenset({"fcl", "pybullet", "pymunk", "numpy", "json", "math", "sys"})
"""File stems a script may not have: Python would import the script itself for that module."""


def targets(made: Sequence[Script], out: Path | None) -> list[Path]:
    """Where each of several scripts (or one with ``--out``) is written."""
    if out is not None and len(made) == 1:
        return [out]
    if out is not None:
        suffix = out.suffix or ".py"
        return [out.with_name(f"{out.stem}-{s.engine}{suffix}") for s in made]
    return [Path(f"{s.name}.py") for s in made]


def cmd_repro(args: argparse.Namespace) -> int:
    from crosscheck.results.store import StoreError, read_run
    from crosscheck.studies.repro import ReproError, scripts

    try:
        made = scripts(read_run(args.run_dir), args.case_id, args.engine)
    except (StoreError, ReproError) as exc:
        fail(str(exc))
        return 2
    if len(made) == 1 and args.out is None:
        sys.stdout.write(made[0].text)
        return 0
    paths = targets(made, args.out)
    shadowing = [p for p in paths if p.stem in SHADOWING]
    if shadowing:
        fail(f"{shadowing[0]}: a script named after a module it imports would import itself; "
             "choose another name")
        return 2
    for script, path in zip(made, paths, strict=True):
        try:
            path.write_text(script.text, encoding="utf-8")
        except OSError as exc:
            fail(f"cannot write {path}: {exc}")
            return 2
        say(f"{script.engine}: {path}  (run it: python {path})")
    return 0
