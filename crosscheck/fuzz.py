"""``crosscheck fuzz``: generate cases near engine failure boundaries, run them, group findings.

Cases come from :mod:`crosscheck.fuzzgen` (same seed, same cases); they run
into a normal results store (``DIR/run``); findings (disagree, error, crash,
timeout) are grouped and written as ready-to-commit case files by
:mod:`crosscheck.casewriter`, with ``DIR/findings.csv`` listing every one.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from collections.abc import Sequence
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pandas as pd
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

import adapters
from adapters.base import Adapter, engine_info
from crosscheck import environment
from crosscheck.casewriter import Group, write_findings
from crosscheck.execute import RunOptions
from crosscheck.fuzzgen import Generated, generate
from crosscheck.model import PAIR_KINDS, Kind
from crosscheck.runner import run
from crosscheck.schema import json_schema_text
from crosscheck.store import ResultsStore, StoreError, read_results

# --- running --------------------------------------------------------------------------------

out = Console()
err = Console(stderr=True)


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def run_cases(gens: Sequence[Generated], engines: Sequence[Adapter], directory: Path,
              options: RunOptions, command: str) -> pd.DataFrame:
    """Run the cases into a normal results store at ``directory``; return its results."""
    store = ResultsStore(directory)
    cases = [gen.case for gen in gens]
    info: dict[str, Any] = {
        "run_id": directory.name, "started": _now(), "finished": None, "command": command,
        "options": asdict(options), "machine": environment.machine(),
        "engines": [engine_info(a) for a in engines], "case_files": [],
        "cases_run": len(cases), "case_errors": []}
    store.write_run_info(info)
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn())
    try:
        with Progress(*columns, console=err, transient=True) as bar:
            task = bar.add_task("fuzz case x engine", total=len(cases) * len(engines))
            run(cases, engines, store, options, progress=lambda n: bar.update(task, advance=n))
        store.write_run_info({**info, "finished": _now()})
    finally:
        store.close()
    return read_results(directory)


def fuzz(kind: Kind, n: int, seed: int, directory: Path, engines: Sequence[Adapter],
         options: RunOptions, per_group: int = 5, command: str = "") -> list[Group]:
    """Generate, run into ``directory/run``, write grouped findings into ``directory``."""
    if directory.exists() and any(directory.iterdir()):
        raise FileExistsError(f"{directory} is not empty; choose another --out or empty it")
    command = command or f"crosscheck fuzz --kind {kind.value} --n {n} --seed {seed}"
    start = time.perf_counter()
    gens = generate(kind, n, seed)
    generated = time.perf_counter()
    frame = run_cases(gens, engines, directory / "run", options, command)
    ran = time.perf_counter()
    groups = write_findings(directory, {g.case.id: g for g in gens}, frame, command, per_group)
    (directory / "schema.json").write_text(json_schema_text(), encoding="utf-8")
    info = {"command": command, "kind": kind.value, "n": n, "seed": seed,
            "engines": [a.name for a in engines], "per_group": per_group,
            "options": asdict(options), "finished": _now(), "generate_s": generated - start,
            "run_s": ran - generated, "write_s": time.perf_counter() - ran,
            "findings": sum(len(g.rows) for g in groups), "groups": len(groups),
            "files": sum(bool(g.chosen) for g in groups), "machine": environment.machine()}
    (directory / "fuzz.json").write_text(json.dumps(info, indent=2) + "\n", encoding="utf-8")
    return groups


# --- command line ---------------------------------------------------------------------------

def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``fuzz`` sub-command to the ``crosscheck`` parser."""
    p = sub.add_parser("fuzz", help="random cases near failure boundaries; grouped findings")
    p.add_argument("--kind", required=True, choices=PAIR_KINDS)
    p.add_argument("--n", type=int, required=True, help="number of cases to generate")
    p.add_argument("--seed", type=int, required=True, help="seed >= 0; same seed, same cases")
    p.add_argument("--engine", action="append", help="engine to run (repeatable; default: all)")
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
        err.print("[red]error:[/red] need --n >= 1, --seed >= 0 and --per-group >= 1")
        return 2
    try:
        engines = [adapters.get(name) for name in args.engine or adapters.names()]
    except adapters.UnknownEngine as exc:
        err.print(f"[red]error:[/red] {exc.args[0]}")
        return 2
    engines = engines if args.engine else [a for a in engines if a.available() is None]
    stem = f"fuzz-{args.kind.replace('_', '-')}-s{args.seed}-n{args.n}"
    directory = args.out or Path("reports") / stem
    options = RunOptions(quick=True, jobs=args.jobs or os.cpu_count() or 1,
                         timeout_s=args.timeout, scheduler=args.scheduler)
    try:
        groups = fuzz(Kind(args.kind), args.n, args.seed, directory, engines, options,
                      args.per_group, _command(args))
    except (FileExistsError, StoreError) as exc:
        err.print(f"[red]error:[/red] {exc}")
        return 2
    print_groups(groups)
    out.print(f"output: {directory}  (check: crosscheck validate {directory}; "
              f"inspect: crosscheck report {directory / 'run'})")
    return 0


def print_groups(groups: Sequence[Group], limit: int = 30) -> None:
    """The groups, largest first, as a table (``limit`` rows)."""
    title = f"{sum(len(g.rows) for g in groups)} findings in {len(groups)} groups"
    table = Table(title=title)
    for column in ("engine", "quantity", "status", "category", "family", "driver", "decade",
                   "findings", "written"):
        table.add_column(column, justify="right" if column in ("findings", "written")
                         else "left")
    ranked = sorted(groups, key=lambda g: (-len(g.rows), g.slug))
    for g in ranked[:limit]:
        table.add_row(g.engine, g.quantity, g.status, g.category, g.family, g.driver,
                      g.decade, str(len(g.rows)), str(len(g.chosen)))
    if len(ranked) > limit:
        table.caption = f"... and {len(ranked) - limit} smaller groups: see findings.csv"
    out.print(table)
