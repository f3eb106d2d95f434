"""``crosscheck stability``: the command of the stability study (crosscheck.report.stability).

Without a run folder it first runs ``cases/sweeps.toml`` (``--quick``) on
every engine into ``reports/stability-<time>/``, through the same launch and
report as ``crosscheck run``; then it analyses the run and prints the verdicts.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import TYPE_CHECKING

from rich.markup import escape
from rich.table import Table

from crosscheck.cli import engines as engine_choice
from crosscheck.cli.console import fail, fit, report_case_errors, say, stdout
from crosscheck.cli.folders import OUT_RULE, chosen
from crosscheck.cli.run import finish, run_dir
from crosscheck.core.options import RunOptions

if TYPE_CHECKING:
    import pandas as pd

    from crosscheck.results.run import Run

SWEEPS = Path("cases/sweeps.toml")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``stability``."""
    p = sub.add_parser("stability", help="where each engine starts to disagree along the sweeps")
    p.add_argument("directory", nargs="?", type=Path, metavar="DIR",
                   help="a run to analyse (default: run cases/sweeps.toml first)")
    p.add_argument("--out", metavar="OUT",
                   help="without DIR: the run folder (default: reports/stability-<timestamp>/); "
                        f"with DIR: where the CSVs go (default: DIR); {OUT_RULE}")
    p.add_argument("--engine", action="append", choices=engine_choice.names(), metavar="NAME",
                   help=f"engine to run (repeatable; default: every available one): "
                        f"{', '.join(engine_choice.names())}")
    p.set_defaults(func=cmd_stability)


def run_sweeps(directory: Path, engine_names: list[str] | None) -> tuple[int, Run | None]:
    """Run the sweeps, quick, through the normal launch and report; the exit code and the
    run (None: it did not finish)."""
    from crosscheck.cases.load import load_paths
    from crosscheck.results.store import ResultsStore, StoreError
    from crosscheck.run.launch import new_info

    loaded = load_paths([SWEEPS])
    report_case_errors(loaded)
    if not loaded.cases:
        fail(f"no sweep cases in {SWEEPS} (run from the project folder)")
        return 2, None
    try:
        engines = engine_choice.select(engine_names)
        store = ResultsStore(directory)
    except (engine_choice.UnknownEngine, StoreError) as exc:
        fail(str(exc.args[0]))
        return 2, None
    options = RunOptions(quick=True, jobs=os.cpu_count() or 1)
    command = "".join(f" --engine {e}" for e in engine_names or [])
    info = new_info(directory, f"crosscheck stability{command} --out {directory}", options,
                    engines, loaded.cases, [SWEEPS], [e.message for e in loaded.errors])
    ran: list[Run] = []
    code = finish(store, loaded.cases, engines, options, info, lambda run: ran.append(run))
    return code, ran[0] if ran else None


def print_table(table: pd.DataFrame) -> None:
    """The headline verdicts as a rich table: a section per engine, a row per sweep walk."""
    rich = Table(title="stability: the first value that breaks, from easy to hard "
                 "(distance; v2 for responses)",
                 caption="breaks: disagree, error, crash or timeout; skip and undefined are "
                         "stepped over (they neither agree nor break)")
    for column in ("engine", "sweep (walk)", "verdict"):
        rich.add_column(column)
    style = {"none": "green", "breaks": "yellow", "already": "red", "unjudged": "dim"}
    for n, (engine, rows) in enumerate(table[table["headline"]].groupby("engine", sort=False)):
        if n:
            rich.add_section()
        for i, r in enumerate(rows.itertuples()):
            walk_name = f"{str(r.sweep).removeprefix('sweep-')} ({r.direction})"
            rich.add_row("" if i else escape(str(engine)), escape(walk_name),
                         f"[{style[str(r.state)]}]{escape(str(r.verdict))}[/]")
    stdout.print(fit(rich))


def cmd_stability(args: argparse.Namespace) -> int:
    from crosscheck.report.stability import analyse, save

    directory, out_dir = args.directory, chosen(args.out)
    if directory is None:
        directory = out_dir or run_dir(Path("reports"), "stability-")
        code, ran = run_sweeps(directory, args.engine)
        if code or ran is None:
            return code or 1
        points, table = analyse(ran)  # the run just made, not read again
    elif not (directory / "results.jsonl").is_file():
        fail(f"{directory} holds no results.jsonl")
        return 2
    else:
        points, table = analyse(directory)
    if table.empty:
        say(f"no sweep cases in {directory}: nothing to analyse")
    else:
        print_table(table)
    paths = save(points, table, out_dir if args.directory and out_dir else directory)
    say(f"thresholds: {paths['stability']}, points: {paths['stability_points']}")
    return 0
