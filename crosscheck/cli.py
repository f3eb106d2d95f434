"""The ``crosscheck`` command line: run, report, validate, new-case, engines, schema."""

from __future__ import annotations

import argparse
import os
import re
import shlex
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pandas as pd
from rich.console import Console
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

import adapters
from adapters.base import Adapter, engine_info
from crosscheck import bench, compare, environment, fuzz, report, stability
from crosscheck.cases import LoadResult, load_paths
from crosscheck.execute import RunOptions
from crosscheck.model import PAIR_KINDS, Kind
from crosscheck.newcase import case_block
from crosscheck.runner import run
from crosscheck.schema import CASE_ADAPTER, ID_PATTERN, AnyCase, json_schema_text
from crosscheck.store import (
    ResultsStore,
    StoreError,
    read_cases,
    read_results,
    read_run_info,
)

out = Console(soft_wrap=True)
err = Console(stderr=True, soft_wrap=True)


def fail(message: str) -> None:
    """Print an error line; the message is shown literally (no rich markup)."""
    err.print(f"[red]error:[/red] {escape(message)}", highlight=False)


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def _run_dir(base: Path) -> Path:
    stamp = datetime.now(UTC).strftime("%Y%m%d-%H%M%S")
    path, n = base / stamp, 1
    while path.exists():
        path, n = base / f"{stamp}-{n}", n + 1
    return path


def _report_errors(loaded: LoadResult) -> None:
    for problem in loaded.errors:
        err.print(f"[red]invalid:[/red] {escape(problem.message)}", highlight=False)


def _select_engines(names: Sequence[str] | None) -> list[Adapter]:
    if names:
        return [adapters.get(name) for name in names]
    chosen = [adapters.get(name) for name in adapters.names()]
    return [a for a in chosen if a.available() is None]


def cmd_run(args: argparse.Namespace) -> int:
    if args.resume:
        return _resume(args.resume)
    loaded = load_paths(args.paths or [Path("cases")])
    _report_errors(loaded)
    engines = _select_engines(args.engine)
    directory = args.out or _run_dir(Path("reports"))
    try:
        store = ResultsStore(directory)
    except StoreError as exc:
        fail(str(exc))
        return 2
    options = RunOptions(quick=args.quick, min_sample_s=args.min_sample, timeout_s=args.timeout,
                         time_per_group=args.time_per_group,
                         isolate=not args.no_isolation, jobs=args.jobs or os.cpu_count() or 1,
                         scheduler=args.scheduler)
    info = {"run_id": directory.name, "started": _now(), "finished": None,
            "command": shlex.join(["crosscheck", *sys.argv[1:]]),
            "options": asdict(options),
            "machine": environment.machine(), "engines": [engine_info(a) for a in engines],
            "case_files": [str(p) for p in loaded.files], "cases_run": len(loaded.cases),
            "case_errors": [e.message for e in loaded.errors]}
    code = _finish(store, loaded.cases, engines, options, info)
    return code or (1 if loaded.errors else 0)


def _resume(directory: Path) -> int:
    try:
        info = read_run_info(directory)
        store = ResultsStore(directory, resume=True)
    except (OSError, StoreError) as exc:
        fail(f"cannot resume {directory}: {exc}")
        return 2
    cases = [CASE_ADAPTER.validate_python(case) for case in read_cases(directory).values()]
    engines = [adapters.get(engine["name"]) for engine in info["engines"]]
    out.print(f"resuming {directory}: {len(store.done)} case x engine pairs already done")
    info["resumed"] = [*info.get("resumed", []), _now()]
    return _finish(store, cases, engines, RunOptions(**info["options"]), info)


def _finish(store: ResultsStore, cases: list[AnyCase], engines: list[Adapter],
            options: RunOptions, info: dict[str, Any]) -> int:
    """Run what is left, then write run.json, the CSV files and the report."""
    store.write_run_info(info)
    try:
        _run_with_progress(cases, engines, store, options)
    except KeyboardInterrupt:
        store.close()
        err.print(escape(f"interrupted; finished rows are kept. Resume with: "
                         f"crosscheck run --resume {store.directory}"))
        return 130
    store.write_run_info({**info, "finished": _now()})
    store.close()
    paths = report.render(store.directory)
    _print_summary(store.directory)
    out.print(f"report: {paths['report']}")
    return 0


def _run_with_progress(cases: list[AnyCase], engines: list[Adapter], store: ResultsStore,
                       options: RunOptions) -> None:
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn(), TimeRemainingColumn())
    with Progress(*columns, console=err, transient=True) as bar:
        total = sum((c.id, a.name) not in store.done for c in cases for a in engines)
        task = bar.add_task("case x engine", total=total)
        run(cases, engines, store, options, progress=lambda n: bar.update(task, advance=n))


def _print_summary(directory: Path) -> None:
    """Print the engine x kind counts from the run's summary.csv (written by the report)."""
    table = pd.read_csv(directory / "summary.csv", keep_default_na=False)
    rich_table = Table(title=f"summary of {directory}")
    columns = ("engine", "kind", *report.STATUSES)
    for column in columns:
        rich_table.add_column(column, no_wrap=column in ("engine", "kind"))
    for row in table.itertuples(index=False):
        rich_table.add_row(*(str(getattr(row, c)) for c in columns))
    out.print(rich_table)


def cmd_report(args: argparse.Namespace) -> int:
    try:
        paths = report.render(args.directory)
    except (OSError, StoreError) as exc:
        fail(f"cannot render {args.directory}: {exc}")
        return 2
    if args.markdown:
        print(report.markdown_summary(read_results(args.directory)))
    out.print(f"report: {paths['report']}")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    target = args.out or Path("reports") / f"compare-{args.a.name}-vs-{args.b.name}"
    try:
        result = compare.compare(args.a, args.b, target)
    except (OSError, StoreError) as exc:
        fail(f"cannot compare: {exc}")
        return 2
    out.print(f"{result['verdict_changes']} verdict changes, {result['timing_changes']} timing "
              f"changes beyond the noise; see {target / 'compare.html'}")
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    loaded = load_paths(args.paths or [Path("cases")])
    _report_errors(loaded)
    if not loaded.files:
        err.print("[red]invalid:[/red] no case files found")
        return 1
    status = "[red]FAILED[/red]" if loaded.errors else "[green]ok[/green]"
    out.print(f"{status}: {loaded.blocks} curated cases in {len(loaded.files)} files, "
              f"{len(loaded.cases)} after sweep expansion and A/B swaps, "
              f"{len(loaded.errors)} errors")
    return 1 if loaded.errors else 0


def _floats(text: str) -> list[float]:
    return [float(x) for x in text.split(",")]


def _body_options(args: argparse.Namespace, side: str) -> dict[str, Any]:
    body: dict[str, Any] = {}
    for key in ("center", "half", "radius", "mass", "velocity"):
        value = getattr(args, f"{side}_{key}")
        if value is not None:
            body[key] = value[0] if key in ("radius", "mass") else value
    return body


def cmd_new_case(args: argparse.Namespace) -> int:
    if not re.fullmatch(ID_PATTERN, args.id):
        fail(f"id {args.id!r} must match {ID_PATTERN}")
        return 2
    existing = load_paths([p for p in (Path("cases"), args.file) if p.exists()])
    if any(case.id == args.id for case in existing.cases):
        fail(f"id {args.id!r} is already used")
        return 2
    text = case_block(Kind(args.kind), args.dim, args.id, description=args.description,
                      tags=args.tag, a=_body_options(args, "a"), b=_body_options(args, "b"),
                      restitution=args.restitution)
    problems = _block_problems(text)
    if problems:
        for problem in problems:
            fail(f"the new case would be invalid: {problem}")
        return 2
    args.file.parent.mkdir(parents=True, exist_ok=True)
    prefix = "\n" if args.file.exists() else "#:schema ./schema.json\n\n"
    with args.file.open("a", encoding="utf-8") as handle:
        handle.write(prefix + text)
    out.print(escape(f"appended case {args.id!r} to {args.file}; check: crosscheck validate"))
    return 0


def _block_problems(text: str) -> list[str]:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "new.toml"
        path.write_text(text)
        return [e.message.replace(f"{path}: ", "") for e in load_paths([path]).errors]


def cmd_engines(args: argparse.Namespace) -> int:
    table = Table(title="engines")
    columns = ["name", "version", "available", "capabilities"]
    for column in [*columns, "settings"] if args.settings else columns:
        table.add_column(column, no_wrap=column in ("name", "version"))
    for name in adapters.names():
        info = engine_info(adapters.get(name))
        caps = info["capabilities"]
        assert isinstance(caps, list)
        row = [str(info["name"]), str(info["version"]), str(info["available"]), ", ".join(caps)]
        table.add_row(*row, *([str(info["settings"])] if args.settings else []))
    out.print(table)
    return 0


def cmd_schema(args: argparse.Namespace) -> int:
    text = json_schema_text()
    if args.check:
        current = args.output.read_text() if args.output.exists() else ""
        if current != text:
            err.print(f"{args.output} is out of date; run: crosscheck schema")
            return 1
        return 0
    args.output.write_text(text)
    out.print(f"wrote {args.output}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="crosscheck", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("run", help="run cases on engines and write a report")
    p.add_argument("paths", nargs="*", type=Path, help="case files or folders (default: cases/)")
    p.add_argument("--engine", action="append", help="engine to run (repeatable; default: all)")
    p.add_argument("--out", type=Path, help="output folder (default: reports/<run-id>/)")
    p.add_argument("--quick", action="store_true", help="skip timing")
    p.add_argument("--min-sample", type=float, default=0.01, help="seconds per timing sample")
    p.add_argument("--time-per-group", type=int, default=3, metavar="K",
                   help="time the first K cases of each case file x kind x dim (0: all)")
    p.add_argument("--timeout", type=float, default=3.0,
                   help="seconds allowed per case x engine before it is marked timeout")
    p.add_argument("--jobs", type=int, default=0,
                   help="cases run at once, each lane with its own workers (default: cores)")
    p.add_argument("--resume", type=Path, metavar="DIR",
                   help="finish a stopped run in DIR without redoing what is done")
    p.add_argument("--no-isolation", action="store_true",
                   help="run engines in this process (faster start, no crash or hang safety)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run cases on this Dask scheduler (e.g. tcp://host:8786)")
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("report", help="re-render CSV and HTML from a stored run")
    p.add_argument("directory", type=Path)
    p.add_argument("--markdown", action="store_true", help="also print the summary as Markdown")
    p.set_defaults(func=cmd_report)
    p = sub.add_parser("compare", help="verdict and timing changes between two stored runs")
    p.add_argument("a", type=Path, help="the earlier run directory")
    p.add_argument("b", type=Path, help="the later run directory")
    p.add_argument("--out", type=Path, help="output folder (default: reports/compare-A-vs-B/)")
    p.set_defaults(func=cmd_compare)
    fuzz.register(sub)
    bench.register(sub)
    stability.register(sub)
    p = sub.add_parser("validate", help="check case files")
    p.add_argument("paths", nargs="*", type=Path)
    p.set_defaults(func=cmd_validate)
    p = sub.add_parser("new-case", help="append a valid template case to a file")
    p.add_argument("--kind", required=True, choices=PAIR_KINDS)
    p.add_argument("--dim", required=True, type=int, choices=[2, 3])
    p.add_argument("--id", required=True)
    p.add_argument("--file", type=Path, default=Path("cases/user.toml"))
    p.add_argument("--description", help="what the case probes")
    p.add_argument("--tag", action="append", help="a tag (repeatable)")
    p.add_argument("--restitution", type=float, help="sphere_response only (default 1)")
    for side in ("a", "b"):
        for key, help_text in (("center", "x,y[,z]"), ("half", "half-widths hx,hy[,hz]"),
                               ("velocity", "vx,vy[,vz]")):
            p.add_argument(f"--{side}-{key}", type=_floats, metavar=help_text.split()[-1],
                           help=f"body {side.upper()}: {help_text}")
        for key in ("radius", "mass"):
            p.add_argument(f"--{side}-{key}", type=_floats, metavar="X",
                           help=f"body {side.upper()}: {key}")
    p.set_defaults(func=cmd_new_case)
    p = sub.add_parser("engines", help="list adapters, versions, capabilities, availability")
    p.add_argument("--settings", action="store_true", help="also show each variant's settings")
    p.set_defaults(func=cmd_engines)
    p = sub.add_parser("schema", help="write the case-file JSON Schema")
    p.add_argument("--output", type=Path, default=Path("cases/schema.json"))
    p.add_argument("--check", action="store_true", help="fail if the file is out of date")
    p.set_defaults(func=cmd_schema)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    code: int = args.func(args)
    return code


if __name__ == "__main__":
    sys.exit(main())
