"""``crosscheck fuzz``: the command of the fuzz study (:mod:`crosscheck.studies.fuzz`).

``crosscheck fuzz --kind K --n N --seed S`` starts a campaign; ``crosscheck fuzz --resume
DIR`` finishes a killed one with the plan stored in it (only ``--jobs`` and ``--scheduler``,
which say where chunks run, may be given with it: every other option would change the
campaign, so it is refused by name).  ``--shrink N`` (default 1) shrinks the first N
representatives of each group written; ``--no-shrink`` none.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rich import box
from rich.table import Table

from crosscheck.cli import engines as engine_choice
from crosscheck.cli.console import fail, fit, progress_bar, say, stdout
from crosscheck.cli.folders import OUT_RULE, chosen, out_folder
from crosscheck.core.model import NEW_CASE_KINDS, Kind
from crosscheck.core.options import RunOptions

if TYPE_CHECKING:
    from crosscheck.studies.fuzz import Group


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``fuzz``."""
    p = sub.add_parser("fuzz", help="random cases near failure boundaries; grouped findings")
    p.add_argument("--kind", choices=NEW_CASE_KINDS,
                   help="kind of case (required unless --resume): every two-body kind")
    p.add_argument("--n", type=int, help="number of cases to generate (required unless --resume)")
    p.add_argument("--seed", type=int, help="seed >= 0; same seed, same cases (required unless "
                                           "--resume)")
    p.add_argument("--resume", type=Path, metavar="DIR",
                   help="finish the killed campaign in DIR with its own options (only --jobs "
                        "and --scheduler may be given)")
    p.add_argument("--engine", action="append", choices=engine_choice.names(), metavar="NAME",
                   help=f"engine to run (repeatable; default: every available one): "
                        f"{', '.join(engine_choice.names())}")
    p.add_argument("--out", metavar="DIR",
                   help=f"output folder (default: reports/fuzz-K-sS-nN/; {OUT_RULE})")
    p.add_argument("--per-group", type=int, help="cases written per group (5)")
    p.add_argument("--shrink", type=int, metavar="N",
                   help="shrink the first N representatives of each group written (largest "
                        "errors first) to a minimal case that fails the same way, written "
                        "just before its original (default 1; at most 300 engine calls each)")
    p.add_argument("--no-shrink", action="store_true", default=None,
                   help="shrink nothing (same as --shrink 0)")
    p.add_argument("--bias", type=Path, metavar="DIR",
                   help="a stored run or fuzz campaign: half the configuration-space cases "
                        "start from the cells where an engine erred, crashed or hung there")
    p.add_argument("--jobs", type=int, help="chunks run at once (default: cores)")
    p.add_argument("--timeout", type=float, help="seconds per case x engine (5)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run chunks on this Dask scheduler (e.g. tcp://host:8786)")
    p.set_defaults(func=cmd_fuzz)


def _command(args: argparse.Namespace) -> str:
    engines = "".join(f" --engine {name}" for name in args.engine or [])
    shrink = "" if args.shrink is None else f" --shrink {args.shrink}"
    shrink += " --no-shrink" if args.no_shrink else ""
    shrink += f" --bias {args.bias}" if args.bias is not None else ""
    return (f"crosscheck fuzz --kind {args.kind} --n {args.n} --seed {args.seed}{engines}"
            f"{shrink}")


CAMPAIGN_OPTIONS = ("kind", "n", "seed", "engine", "out", "per_group", "timeout", "shrink",
                    "no_shrink", "bias")


def _problem(args: argparse.Namespace) -> str | None:
    """What is wrong with the command line, naming the option, or None."""
    if args.jobs is not None and args.jobs < 1:
        return f"--jobs must be >= 1 (got {args.jobs})"
    if args.resume is not None:
        given = [f"--{o.replace('_', '-')}" for o in CAMPAIGN_OPTIONS
                 if getattr(args, o) is not None]
        return (f"--resume continues the campaign with its stored options; "
                f"{', '.join(given)} would change it (only --jobs and --scheduler may "
                f"be given)") if given else None
    missing = [f"--{o}" for o in ("kind", "n", "seed") if getattr(args, o) is None]
    if missing:
        return f"{', '.join(missing)} required (or --resume DIR)"
    checks = [(args.n >= 1, f"--n must be >= 1 (got {args.n})"),
              (args.seed >= 0, f"--seed must be >= 0 (got {args.seed})"),
              (args.per_group is None or args.per_group >= 1,
               f"--per-group must be >= 1 (got {args.per_group})"),
              (args.shrink is None or args.shrink >= 0,
               f"--shrink must be >= 0 (got {args.shrink})"),
              (args.shrink is None or not args.no_shrink,
               f"--shrink {args.shrink} and --no-shrink contradict each other"),
              (args.timeout is None or args.timeout > 0,
               f"--timeout must be > 0 seconds (got {args.timeout})"),
              (args.bias is None or (args.bias / "run.json").is_file()
               or (args.bias / "campaign.json").is_file(),
               f"--bias {args.bias}: not a stored run (run.json) nor a fuzz campaign "
               "(campaign.json)")]
    return next((message for ok, message in checks if not ok), None)


def _resume(args: argparse.Namespace) -> list[Group]:
    from crosscheck.studies.fuzz import resume, stored_plan

    plan = stored_plan(args.resume)
    with progress_bar(int(plan["n"]) * len(plan["engines"]), "fuzz case x engine") as advance:
        return resume(args.resume, engine_choice.select, args.jobs, advance, args.scheduler)


def _directory(args: argparse.Namespace) -> Path:
    """The campaign's folder: --resume's, --out, or reports/fuzz-K-sS-nN/."""
    stem = f"fuzz-{str(args.kind).replace('_', '-')}-s{args.seed}-n{args.n}"
    if args.resume is not None:
        return Path(args.resume)
    return out_folder(args.out) if args.out else Path("reports") / stem


def _start(args: argparse.Namespace) -> tuple[list[Group], Path]:
    from crosscheck.studies.fuzz import SHRINK, fuzz
    from crosscheck.studies.fuzz.bias import bias_from

    engines = engine_choice.select(args.engine)
    directory = chosen(args.out) or _directory(args)
    options = RunOptions(quick=True, jobs=args.jobs or os.cpu_count() or 1,
                         timeout_s=5.0 if args.timeout is None else args.timeout,
                         scheduler=args.scheduler)
    shrink = 0 if args.no_shrink else SHRINK if args.shrink is None else args.shrink
    bias = bias_from(args.bias) if args.bias is not None else ()
    with progress_bar(args.n * len(engines), "fuzz case x engine") as advance:
        return fuzz(Kind(args.kind), args.n, args.seed, directory, engines, options,
                    args.per_group or 5, _command(args), advance, shrink, bias), directory


def cmd_fuzz(args: argparse.Namespace) -> int:
    from crosscheck.studies.fuzz import CampaignError

    problem = _problem(args)
    if problem:
        fail(problem)
        return 2
    try:
        if args.resume is not None:
            groups, directory = _resume(args), args.resume
        else:
            groups, directory = _start(args)
    except (engine_choice.UnknownEngine, CampaignError) as exc:
        fail(str(exc.args[0]))
        return 2
    except KeyboardInterrupt:
        fail(f"interrupted: the finished chunks are kept; finish with "
             f"'crosscheck fuzz --resume {_directory(args)}'")
        return 130
    print_groups(groups, directory=directory)
    say(f"output: {directory}  (check: crosscheck validate {directory}; every finding: "
        f"{directory / 'findings.csv'}; counts and speed: {directory / 'fuzz.json'})")
    return 0


GROUP_COLUMNS = ("engine", "quantity", "status", "category", "family", "findings")
"""The columns of the groups table: about 70 characters with the longest names, so it reads
whole at 80 columns.  A family's driver (relative gap for near-touching, ...) is in
findings.csv; the cases each group wrote are listed below the table."""


def groups_table(ranked: Sequence[Group], limit: int = 30) -> Table:
    """The first ``limit`` groups in the order given, one row each, without borders."""
    table = Table(title=f"{sum(g.count for g in ranked)} findings in {len(ranked)} groups",
                  box=box.SIMPLE_HEAD, title_justify="left", show_edge=False, pad_edge=False,
                  collapse_padding=True)
    for column in GROUP_COLUMNS:
        table.add_column(column, justify="right" if column == "findings" else "left")
    for g in ranked[:limit]:
        table.add_row(g.engine, g.quantity, g.status, g.category, g.family, str(g.count))
    if len(ranked) > limit:
        table.caption = f"... and {len(ranked) - limit} more groups: see findings.csv"
        table.caption_justify = "left"
    return fit(table)


def print_groups(groups: Sequence[Group], limit: int = 30, directory: Path | None = None
                 ) -> None:
    """The groups, worst first (:func:`~crosscheck.studies.fuzz.by_severity`), as a table
    (``limit`` rows), then the case files written, by name."""
    from crosscheck.studies.fuzz import by_severity

    ranked = by_severity(groups)
    stdout.print(groups_table(ranked, limit))
    written = [g for g in ranked if g.chosen]
    where = f" in {directory}" if directory is not None else ""
    if written:
        say(f"{len(written)} case files written{where}, worst first:")
    elif ranked:
        say("no case file written: every group lies within its engine's declared tolerance "
            "(listed in findings.csv)")
    for g in written:
        shrunk = f" + {len(g.shrunk)} shrunk" if g.shrunk else ""
        say(f"  {g.slug}.toml  ({len(g.chosen)} cases{shrunk}; {g.status}"
            f"{' / ' + g.category if g.category else ''})")
