"""``crosscheck fuzz``: the command of the fuzz study (:mod:`crosscheck.studies.fuzz`)."""

from __future__ import annotations

import argparse
import os
from collections.abc import Sequence
from pathlib import Path

from rich.table import Table

from crosscheck.cli import engines as engine_choice
from crosscheck.cli.console import fail, out, progress_bar, say
from crosscheck.core.model import PAIR_KINDS, Kind
from crosscheck.core.options import RunOptions
from crosscheck.results.store import StoreError
from crosscheck.studies.findings import Group
from crosscheck.studies.fuzz import fuzz


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``fuzz``."""
    p = sub.add_parser("fuzz", help="random cases near failure boundaries; grouped findings")
    p.add_argument("--kind", required=True, choices=PAIR_KINDS)
    p.add_argument("--n", type=int, required=True, help="number of cases to generate")
    p.add_argument("--seed", type=int, required=True, help="seed >= 0; same seed, same cases")
    p.add_argument("--engine", action="append", choices=engine_choice.names(), metavar="NAME",
                   help=f"engine to run (repeatable; default: every available one): "
                        f"{', '.join(engine_choice.names())}")
    p.add_argument("--out", type=Path, help="output folder (default: reports/fuzz-K-sS-nN/)")
    p.add_argument("--per-group", type=int, default=5, help="cases written per group (5)")
    p.add_argument("--jobs", type=int, default=0, help="cases run at once (default: cores)")
    p.add_argument("--timeout", type=float, default=5.0, help="seconds per case x engine")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run cases on this Dask scheduler (e.g. tcp://host:8786)")
    p.set_defaults(func=cmd_fuzz)


def _command(args: argparse.Namespace) -> str:
    engines = "".join(f" --engine {name}" for name in args.engine or [])
    return f"crosscheck fuzz --kind {args.kind} --n {args.n} --seed {args.seed}{engines}"


def cmd_fuzz(args: argparse.Namespace) -> int:
    if args.n < 1 or args.seed < 0 or args.per_group < 1:
        fail("need --n >= 1, --seed >= 0 and --per-group >= 1")
        return 2
    try:
        engines = engine_choice.select(args.engine)
    except engine_choice.UnknownEngine as exc:
        fail(str(exc.args[0]))
        return 2
    stem = f"fuzz-{args.kind.replace('_', '-')}-s{args.seed}-n{args.n}"
    directory = args.out or Path("reports") / stem
    options = RunOptions(quick=True, jobs=args.jobs or os.cpu_count() or 1,
                         timeout_s=args.timeout, scheduler=args.scheduler)
    try:
        with progress_bar(args.n * len(engines), "fuzz case x engine") as advance:
            groups = fuzz(Kind(args.kind), args.n, args.seed, directory, engines, options,
                          args.per_group, _command(args), advance)
    except (FileExistsError, StoreError) as exc:
        fail(str(exc))
        return 2
    print_groups(groups)
    say(f"output: {directory}  (check: crosscheck validate {directory}; "
        f"inspect: crosscheck report {directory / 'run'})")
    return 0


def print_groups(groups: Sequence[Group], limit: int = 30) -> None:
    """The groups, largest first, as a table (``limit`` rows)."""
    title = f"{sum(len(g.rows) for g in groups)} findings in {len(groups)} groups"
    table = Table(title=title)
    for column in ("engine", "quantity", "status", "category", "family", "driver", "decade",
                   "findings", "written"):
        table.add_column(column, justify="right" if column in ("findings", "written")
                         else "left", no_wrap=column == "engine")
    ranked = sorted(groups, key=lambda g: (-len(g.rows), g.slug))
    for g in ranked[:limit]:
        table.add_row(g.engine, g.quantity, g.status, g.category, g.family, g.driver,
                      g.decade, str(len(g.rows)), str(len(g.chosen)))
    if len(ranked) > limit:
        table.caption = f"... and {len(ranked) - limit} smaller groups: see findings.csv"
    out.print(table)
