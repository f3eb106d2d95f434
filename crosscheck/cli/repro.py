"""``crosscheck repro``: standalone scripts that reproduce a case on an engine, bit for bit.

The command of :mod:`crosscheck.studies.repro`.  Everything goes to stdout unless ``--out``
is given: one script (or, with ``--issue``, one Markdown bug report around it), or, without
``--engine``, one per engine that disagrees on the case, printed one after another, each
headed by a comment line naming its engine (which engines it chose is said on stderr).
With ``--out FILE`` one goes to FILE and several to ``FILE-<engine>.py`` (``.md``) each.

A run writes no scripts: ``--all`` (without a CASE_ID) writes the script of every breaking
case x engine pair of the run into ``RUN_DIR/repro/`` (or ``--out DIR``), the folder the
report links them from once it is rendered again.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from crosscheck.cli.console import fail, say, stderr

if TYPE_CHECKING:
    from crosscheck.results.run import Run
    from crosscheck.studies.repro import Script

DESCRIPTION = """\
Print a standalone Python script that reproduces CASE_ID on an engine bit for bit, with
the engine's own API only (no crosscheck): it prints the engine's answer as results.csv
records it, the exact answer with each verdict against its float64 bound, and the
conventions the verdict consulted.  Every engine variant and every kind has one, scenes
included.  Without --engine: one script per engine that disagrees on the case (a row
neither agree nor skip; if none does, every engine that ran it), printed one after
another, each headed by a comment line naming its engine; save them with --out.  --issue
prints a Markdown bug report instead: engine and version, platform, the script (and for
MuJoCo its MJCF), expected and got, the error against the float64 bound, the verdict and
the conventions it consulted, and the case file block.  A run writes no script files:
--all, without a CASE_ID, writes the script of every case x engine pair with a disagree,
error, crash or timeout row into RUN_DIR/repro/ (or --out DIR), one <case>_<engine>.py each
(engines without a script writer, plug-ins, are left out), to archive or attach; the report
links those in RUN_DIR/repro/ once rendered again (crosscheck report RUN_DIR)."""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``repro``."""
    p = sub.add_parser("repro", help="a standalone script reproducing a case on an engine",
                       description=DESCRIPTION)
    p.add_argument("run_dir", type=Path, metavar="RUN_DIR", help="a run folder")
    p.add_argument("case_id", metavar="CASE_ID", nargs="?",
                   help="a case of that run (required, except with --all)")
    p.add_argument("--engine", help="engine (default: every engine that disagrees on the "
                                    "case, else every engine that ran it)")
    p.add_argument("--issue", action="store_true",
                   help="print a Markdown bug report around the script instead")
    p.add_argument("--all", action="store_true",
                   help="write the script of every breaking case x engine pair of the run "
                        "into RUN_DIR/repro/ (or --out DIR); takes no CASE_ID, --engine or "
                        "--issue")
    p.add_argument("--out", type=Path, metavar="PATH",
                   help="write it to the file PATH instead of stdout (several: "
                        "PATH-<engine>.py, or .md with --issue, one each); with --all, the "
                        "folder the scripts go to")
    p.set_defaults(func=cmd_repro)


SHADOWING = frozenset({"fcl", "pybullet", "pymunk", "numpy", "json", "math", "sys", "mujoco",
                       "coal", "Box2D", "rapier3d", "collections"})
"""File stems a script may not have: Python would import the script itself for that module."""


def targets(made: Sequence[Script], out: Path, suffix: str) -> list[Path]:
    """Where each script (or report) is written with ``--out``."""
    if len(made) == 1:
        return [out]
    return [out.with_name(f"{out.stem}-{s.engine}{out.suffix or suffix}") for s in made]


def texts(stored: Run, made: Sequence[Script], issue: bool) -> list[str]:
    """Each script's text, or with ``issue`` its bug report."""
    if not issue:
        return [s.text for s in made]
    from crosscheck.studies.repro import issue_report
    from crosscheck.studies.repro.script import RunRows

    runs = RunRows(stored)
    info = stored.info
    return [issue_report(s, stored.cases[s.case_id], runs.rows(s.case_id, s.engine),
                         runs.engine_info(s.engine), info.machine, info.run_id,
                         str(info.machine.get("git_commit", ""))) for s in made]


def headed(made: Sequence[Script], bodies: Sequence[str], issue: bool) -> str:
    """Several texts one after another, each headed by a comment line naming its engine."""
    if len(made) == 1:
        return bodies[0]
    out = []
    for i, (script, body) in enumerate(zip(made, bodies, strict=True), start=1):
        title = f"repro {i} of {len(made)}: case {script.case_id} on engine {script.engine}"
        out.append((f"<!-- {title} -->" if issue else f"# ===== {title} =====") + "\n" + body)
    return "\n".join(out)


def _arguments_problem(args: argparse.Namespace) -> str | None:
    """Why these arguments ask for nothing this command does, or None."""
    if not args.all:
        return None if args.case_id is not None else (
            "give a CASE_ID of the run, or --all for every breaking pair's script")
    given = [f"CASE_ID {args.case_id!r}" if args.case_id is not None else "",
             "--engine" if args.engine is not None else "", "--issue" if args.issue else ""]
    given = [g for g in given if g]
    if given:
        return (f"--all writes every breaking pair's script; it takes no {', '.join(given)} "
                f"(drop --all for one case's scripts)")
    return None


def write_all(run_dir: Path, out: Path | None) -> int:
    """``--all``: every breaking pair's script into ``out`` (default: the run's ``repro/``)."""
    from crosscheck.results.store import REPRO_DIR, StoreError
    from crosscheck.studies.repro import write_run_scripts

    folder = run_dir / REPRO_DIR if out is None else out
    try:
        written = write_run_scripts(run_dir, out)
    except (StoreError, OSError) as exc:
        fail(f"cannot write the scripts of {run_dir} into {folder}: {exc}")
        return 2
    say(f"{len(written)} script(s) written into {folder} (one per breaking case x engine "
        "with a script writer)")
    if written and folder.resolve() == (run_dir / REPRO_DIR).resolve():
        say(f"the report links them once rendered again: crosscheck report {run_dir}")
    return 0


def cmd_repro(args: argparse.Namespace) -> int:
    from crosscheck.results.run import read_run
    from crosscheck.results.store import StoreError
    from crosscheck.studies.repro import ReproError, engines_for, scripts
    from crosscheck.studies.repro.script import RunRows

    problem = _arguments_problem(args)
    if problem:
        fail(problem)
        return 2
    if args.all:
        return write_all(args.run_dir, args.out)
    try:
        stored = read_run(args.run_dir)
        made = scripts(stored, args.case_id, args.engine)
    except (StoreError, ReproError) as exc:
        fail(str(exc))
        return 2
    if args.engine is None:
        _, disagree = engines_for(RunRows(stored), args.case_id)
        why = "disagree on it" if disagree else "ran it (none disagrees)"
        say(f"{args.case_id}: {len(made)} engine(s) {why}: "
            f"{', '.join(s.engine for s in made)}", stderr)
    bodies = texts(stored, made, args.issue)
    if args.out is None:
        sys.stdout.write(headed(made, bodies, args.issue))
        return 0
    paths = targets(made, args.out, ".md" if args.issue else ".py")
    shadowing = [p for p in paths if p.stem in SHADOWING and p.suffix == ".py"]
    if shadowing:
        fail(f"{shadowing[0]}: a script named after a module it imports would import itself; "
             "choose another name")
        return 2
    for script, body, path in zip(made, bodies, paths, strict=True):
        try:
            path.write_text(body, encoding="utf-8")
        except OSError as exc:
            fail(f"cannot write {path}: {exc}")
            return 2
        run = f"  (run it: python {path})" if path.suffix == ".py" else ""
        say(f"{script.engine}: {path}{run}")
    return 0
