"""``crosscheck run``: run cases on engines into a folder, then render its report."""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import time
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

from crosscheck.cases.load import load_paths
from crosscheck.cli import engines as engine_choice
from crosscheck.cli.console import (
    err,
    fail,
    out,
    phase_bars,
    print_summary,
    report_case_errors,
    say,
)
from crosscheck.core.contract import Adapter
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.report.render import render
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.store import ResultsStore, StoreError, read_run
from crosscheck.run.launch import launch, new_info
from crosscheck.studies.repro import write_run_scripts


def run_dir(base: Path, prefix: str = "") -> Path:
    """A new folder under ``base`` named by the time (``-1``, ``-2`` ... if taken)."""
    stamp = prefix + datetime.now(UTC).strftime("%Y%m%d-%H%M%S")
    path, n = base / stamp, 1
    while path.exists():
        path, n = base / f"{stamp}-{n}", n + 1
    return path


def finish(store: ResultsStore, cases: Sequence[AnyCase], engines: Sequence[Adapter],
           options: RunOptions, info: RunInfo) -> int:
    """Run what is left with a progress bar, then render and summarise; the exit code."""
    started = time.monotonic()
    say(f"running {len(cases)} cases x {len(engines)} engines "
        f"({', '.join(a.name for a in engines)}) -> {store.directory}")
    try:
        with phase_bars() as phases:
            launch(store, cases, engines, options, info, phases=phases)
    except KeyboardInterrupt:
        err.print(f"interrupted; finished rows are kept. Resume with: "
                  f"crosscheck run --resume {store.directory}", markup=False, highlight=False)
        return 130
    write_run_scripts(store.directory)  # repro/<case>_<engine>.py, linked from the report
    paths = render(store.directory)
    print_summary(store.directory)
    out.print(f"report: {paths['report']}", markup=False, highlight=False)
    say(f"finished in {time.monotonic() - started:.0f} s")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    if args.resume:
        return resume(args.resume)
    loaded = load_paths(args.paths or [Path("cases")])
    report_case_errors(loaded)
    try:  # a listed engine that cannot be used (a broken plug-in) is refused, with its reason
        engines = engine_choice.select(args.engine)
    except engine_choice.UnknownEngine as exc:
        fail(str(exc))
        return 2
    directory = args.out or run_dir(Path("reports"))
    try:
        store = ResultsStore(directory)
    except StoreError as exc:
        fail(str(exc))
        return 2
    options = RunOptions(quick=args.quick, min_sample_s=args.min_sample, samples=args.samples,
                         timeout_s=args.timeout, timing_cases=args.timing_cases,
                         timing_seed=args.timing_seed, scene_repeats=args.scene_repeats,
                         pin=not args.no_pin, isolate=not args.no_isolation,
                         jobs=args.jobs or os.cpu_count() or 1, scheduler=args.scheduler)
    info = new_info(directory, shlex.join(["crosscheck", *sys.argv[1:]]), options, engines,
                    loaded.cases, loaded.files, [e.message for e in loaded.errors])
    code = finish(store, loaded.cases, engines, options, info)
    return code or (1 if loaded.errors else 0)


def resume(directory: Path) -> int:
    """Finish a stopped run in ``directory`` with its own cases, engines and options."""
    try:
        stored = read_run(directory)
        engines = engine_choice.select(stored.info.engine_names)
        store = ResultsStore(directory, resume=True)
    except (OSError, StoreError, engine_choice.UnknownEngine) as exc:
        fail(f"cannot resume {directory}: {exc}")
        return 2
    out.print(f"resuming {directory}: {len(store.done)} case x engine pairs already done",
              markup=False, highlight=False)
    return finish(store, list(stored.cases.values()), engines, stored.info.options,
                  stored.info.resume())


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``run``."""
    defaults = RunOptions()
    p = sub.add_parser("run", help="run cases on engines and write a report")
    p.add_argument("paths", nargs="*", type=Path, help="case files or folders (default: cases/)")
    p.add_argument("--engine", action="append", choices=engine_choice.names(), metavar="NAME",
                   help=f"engine to run (repeatable; default: every available one): "
                        f"{', '.join(engine_choice.names())}")
    p.add_argument("--out", type=Path, help="output folder (default: reports/<run-id>/)")
    p.add_argument("--quick", action="store_true",
                   help="no timing phase; scenes over 1,000 steps skipped")
    p.add_argument("--timing-cases", type=int, default=defaults.timing_cases, metavar="N",
                   help="cases timed per engine x kind, drawn at random (0: no timing phase; "
                        f"default {defaults.timing_cases})")
    p.add_argument("--timing-seed", type=int, default=defaults.timing_seed,
                   help="seed of the timing sample")
    p.add_argument("--samples", type=int, default=defaults.samples,
                   help=f"timing samples kept per case (default {defaults.samples})")
    p.add_argument("--min-sample", type=float, default=defaults.min_sample_s,
                   help=f"seconds per timing sample (default {defaults.min_sample_s:g})")
    p.add_argument("--scene-repeats", type=int, default=defaults.scene_repeats,
                   help=f"runs of each timed scene (default {defaults.scene_repeats})")
    p.add_argument("--no-pin", action="store_true",
                   help="do not pin the timed engine and the harness to separate cores")
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
