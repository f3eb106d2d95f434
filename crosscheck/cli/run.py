"""``crosscheck run``: run cases on engines into a folder, then render its report."""

from __future__ import annotations

import argparse
import math
import os
import shlex
import sys
import time
from collections.abc import Callable, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING

from crosscheck.cli import check
from crosscheck.cli import engines as engine_choice
from crosscheck.cli.console import (
    fail,
    phase_bars,
    print_summary,
    report_case_errors,
    say,
    stderr,
)
from crosscheck.cli.folders import OUT_RULE, chosen
from crosscheck.core.options import RunOptions

if TYPE_CHECKING:  # the library loads per command, not for --help (tests/cli/test_startup)
    from crosscheck.core.contract import Adapter
    from crosscheck.core.schema import AnyCase
    from crosscheck.results.run import Run
    from crosscheck.results.runinfo import RunInfo
    from crosscheck.results.store import ResultsStore


def run_dir(base: Path, prefix: str = "") -> Path:
    """A new folder under ``base`` named by the time (``-1``, ``-2`` ... if taken)."""
    stamp = prefix + datetime.now(UTC).strftime("%Y%m%d-%H%M%S")
    path, n = base / stamp, 1
    while path.exists():
        path, n = base / f"{stamp}-{n}", n + 1
    return path


def finish(store: ResultsStore, cases: Sequence[AnyCase], engines: Sequence[Adapter],
           options: RunOptions, info: RunInfo,
           after: Callable[[Run], int | None] = lambda run: None) -> int:
    """Run what is left with a progress bar, then render and summarise; the exit code
    (``after``'s, given the run, when it returns one: the baseline check)."""
    from crosscheck.results.store import StoreError
    from crosscheck.run.distributed import ClusterLost
    from crosscheck.run.launch import launch

    started = time.monotonic()
    say(f"running {len(cases)} cases x {len(engines)} engines "
        f"({', '.join(a.name for a in engines)}) -> {store.directory}")
    hint = f"crosscheck run --resume {store.directory}"
    try:
        with phase_bars() as phases:
            run = launch(store, cases, engines, options, info, phases=phases)
            _say_repeat_check(run.info)
            rendered = _render(run, phases)
    except KeyboardInterrupt:  # in the run, or after its last row (a resume then renders)
        stderr.print(f"interrupted; finished rows are kept. Resume with: {hint}",
                  markup=False, highlight=False)
        return 130
    except (StoreError, ClusterLost, OSError) as exc:  # a full disk, a lost Dask scheduler
        fail(f"the run stopped: {exc}. Finished rows are kept; resume with: {hint}")
        return 1
    if not rendered:
        return 1
    print_summary(run)
    say(f"finished in {time.monotonic() - started:.0f} s")
    return after(run) or 0


def _say_repeat_check(info: RunInfo) -> None:
    """One line on the repeat check, when the run made it."""
    check = info.repeat_check
    if check is not None:
        say(f"repeat check: {check['pairs']} pairs asked again in {check['seconds']:.0f} s; "
            f"{check['nondeterministic']} answered differently (nondeterministic)")


def _render(run: Run, phases: Callable[[str, int], Callable[[int], None]]) -> bool:
    """Render the run's report (its progress a phase of ``phases``); on failure say so (the
    results are kept) and how to retry."""
    from crosscheck.report.render import STEPS, render

    directory = run.directory
    try:
        paths = render(run, phases("report", STEPS))
    except Exception as exc:  # any fault of the report must not cost the run's results
        fail(f"the results are complete in {directory}, but its report failed to render "
             f"({type(exc).__name__}: {exc}); retry with: crosscheck report {directory}")
        return False
    say(f"report: {paths['report']}")
    return True


CHANGES_THE_RUN = ("paths", "deep", "engine", "out", "quick", "timing_cases", "timing_seed",
                   "samples", "min_sample", "scene_repeats", "no_pin", "timeout", "jobs",
                   "no_isolation",
                   "scheduler", "worker_memory", "repeat_check", "timer",
                   "junit", "markdown", "baseline")  # outputs: check a resumed run with check
"""The options of ``run`` that ``--resume`` refuses: a resumed run keeps those it started with."""

_PARSER_DEFAULTS: dict[str, object] = {}
"""The parser's default of each option in CHANGES_THE_RUN (filled by :func:`register`)."""


def cmd_run(args: argparse.Namespace) -> int:
    if args.resume:
        given = [f"--{name.replace('_', '-')}" if name != "paths" else "case paths"
                 for name in CHANGES_THE_RUN
                 if getattr(args, name) not in (_PARSER_DEFAULTS.get(name), None, [])]
        if given:
            fail(f"--resume runs {args.resume} with the cases, engines and options it started "
                 f"with; it takes no other option, but was given {', '.join(given)} "
                 "(drop them, or start a new run with --out)")
            return 2
        return resume(args.resume)
    return start(args)


def start(args: argparse.Namespace) -> int:
    """A new run: every option checked before any folder is made or any case runs."""
    from crosscheck.cases.load import load_paths
    from crosscheck.results.store import ResultsStore, StoreError
    from crosscheck.run.launch import new_info

    problem = (_deep_problem(args) or _pinned_problem(args) or _path_problem(args)
               or _timer_problem(args))
    if problem:
        fail(problem)
        return 2
    loaded = load_paths(_paths(args))
    report_case_errors(loaded)
    if not loaded.cases:
        fail("no valid case in the case files (see the errors above): nothing to run")
        return 2
    try:  # a listed engine that cannot be used (a broken plug-in) is refused, with its reason
        engines = engine_choice.select(args.engine)
    except engine_choice.UnknownEngine as exc:
        fail(str(exc))
        return 2
    directory = chosen(args.out) or run_dir(Path("reports"))
    options = _options(args)
    info = new_info(directory, shlex.join(["crosscheck", *sys.argv[1:]]), options, engines,
                    loaded.cases, loaded.files, [e.message for e in loaded.errors])
    try:
        store = ResultsStore(directory)
    except StoreError as exc:
        fail(str(exc))
        return 2
    code = finish(store, loaded.cases, engines, options, info,
                  lambda run: check.after_run(run, args))
    return code or (1 if loaded.errors else 0)


def _paths(args: argparse.Namespace) -> list[Path]:
    """The case paths of the run: those given, else the tier's folders."""
    from crosscheck.cases.tiers import tier_paths

    return list(args.paths) or tier_paths(args.deep)


def _deep_problem(args: argparse.Namespace) -> str | None:
    """Why ``--deep`` cannot go with these options, or None."""
    if args.deep and args.paths:
        return ("--deep runs the deep tier's folders (cases/ and cases-deep/); with case "
                f"paths given ({', '.join(map(str, args.paths))}) name cases-deep/ among "
                "them instead")
    return None


def _pinned_problem(args: argparse.Namespace) -> str | None:
    """Why a pinned ``--engine NAME@VERSION`` cannot run with these options, or None."""
    if not any("@" in name for name in args.engine or ()):
        return None
    other = "--no-isolation" if args.no_isolation else "--scheduler" if args.scheduler else ""
    return (f"--engine NAME@VERSION runs in a worker with that version's interpreter: it "
            f"cannot be combined with {other}") if other else None


def _path_problem(args: argparse.Namespace) -> str | None:
    """Why the run's case paths (none given: the tier's folders) hold no case file, or None."""
    from crosscheck.cases.load import case_files

    missing = [str(p) for p in args.paths if not p.exists()]
    if missing:
        return f"no such case file or folder: {', '.join(missing)}"
    searched = _paths(args)
    if not case_files(p for p in searched if p.exists()):
        where = ", ".join(f"{p}/" if p.is_dir() or not args.paths else str(p)
                          for p in searched)
        return f"no case files found under {where}: run from the project root or pass a path"
    return None


def _options(args: argparse.Namespace) -> RunOptions:
    """The run's options from the command line."""
    return RunOptions(quick=args.quick, min_sample_s=args.min_sample, samples=args.samples,
                      timeout_s=args.timeout, timing_cases=args.timing_cases,
                      timing_seed=args.timing_seed, scene_repeats=args.scene_repeats,
                      pin=not args.no_pin, isolate=not args.no_isolation,
                      jobs=args.jobs or os.cpu_count() or 1, scheduler=args.scheduler,
                      worker_memory_mb=args.worker_memory, repeat_check=args.repeat_check,
                      timer=args.timer)


def _timer_problem(args: argparse.Namespace) -> str | None:
    """Why ``--timer instructions`` cannot be honoured (None: it can, or it was not asked)."""
    if args.timer != "instructions":
        return None
    if args.quick or args.timing_cases == 0:
        given = "--quick" if args.quick else "--timing-cases 0"
        return (f"--timer instructions counts the timing sample, and {given} has none: drop "
                f"one of them")
    from crosscheck.run.callgrind import missing

    return missing()


def resume(directory: Path) -> int:
    """Finish a stopped run in ``directory`` with its own cases, engines and options."""
    from crosscheck.results.run import read_run
    from crosscheck.results.store import ResultsStore, StoreError

    problem = _unresumable(directory)
    if problem:
        fail(f"cannot resume {directory}: {problem}")
        return 2
    try:
        stored = read_run(directory)
        engines = engine_choice.select(stored.info.engine_names)
        store = ResultsStore(directory, resume=True)
    except (OSError, StoreError, engine_choice.UnknownEngine) as exc:
        fail(f"cannot resume {directory}: {exc}")
        return 2
    say(f"resuming {directory}: {len(store.done)} case x engine pairs already done")
    return finish(store, list(stored.cases.values()), engines, stored.info.options,
                  stored.info.resume())


def _unresumable(directory: Path) -> str | None:
    """Why ``directory`` holds no run to resume (a run killed before it wrote run.json), or None."""
    again = (f"start it again with the same command and --out {directory} "
             "(the folder is reused)")
    if not directory.is_dir():
        return (f"no such folder: {directory} does not exist; check the path (a run killed "
                f"before it made its folder left nothing to resume: {again})")
    if not (directory / "run.json").exists():
        return (f"it has no run.json: the run was killed before it started, so no result "
                f"was lost; {again}")
    return None


def _number(kind: type[int] | type[float], low: float, inclusive: bool
            ) -> Callable[[str], float]:
    """An argparse type: a finite ``kind`` above ``low`` (or equal, if ``inclusive``)."""
    bound = f">= {low:g}" if inclusive else f"> {low:g}"
    name = "an integer" if kind is int else "a number"

    def check(text: str) -> float:
        try:
            value = kind(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and (value >= low if inclusive else value > low)):
            raise argparse.ArgumentTypeError(f"must be {name} {bound}, not {text!r}")
        return value
    return check


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``run``."""
    defaults = RunOptions()
    p = sub.add_parser("run", help="run cases on engines and write a report")
    p.add_argument("paths", nargs="*", type=Path, help="case files or folders (default: cases/)")
    p.add_argument("--engine", action="append", type=engine_choice.engine_name,
                   metavar="NAME[@VERSION]",
                   help=f"engine to run (repeatable; default: every available one): "
                        f"{', '.join(engine_choice.names())}; NAME@VERSION runs that variant "
                        "with that version of its engine's package, from a cached environment "
                        "built with pip on first use (crosscheck engines --envs), e.g. "
                        "--engine pymunk@6.11.1 --engine pymunk")
    p.add_argument("--out", metavar="DIR",
                   help=f"output folder (default: reports/<run-id>/; {OUT_RULE})")
    p.add_argument("--deep", action="store_true",
                   help="run the deep tier: cases/ and cases-deep/ (finer time steps, "
                        "minute-long gases at 1/240 s, strength-3 covering designs; "
                        "docs/coverage.md)")
    p.add_argument("--quick", action="store_true",
                   help="no timing phase; scenes over 1,000 steps skipped")
    p.add_argument("--timing-cases", type=_number(int, 0, True), metavar="N",
                   default=defaults.timing_cases,
                   help="cases timed per engine x kind, drawn at random (0: no timing phase; "
                        f"default {defaults.timing_cases})")
    p.add_argument("--timing-seed", type=int, default=defaults.timing_seed,
                   help="seed of the timing sample")
    p.add_argument("--samples", type=_number(int, 1, True), default=defaults.samples,
                   help=f"timing samples kept per case (default {defaults.samples})")
    p.add_argument("--min-sample", type=_number(float, 0, False), default=defaults.min_sample_s,
                   help=f"seconds per timing sample (default {defaults.min_sample_s:g})")
    p.add_argument("--timer", choices=("wall", "instructions"), default=defaults.timer,
                   help="wall: time the sample on the wall clock; instructions: also count "
                        "each sampled pair's instructions per query under Valgrind's callgrind, "
                        "deterministic whatever the machine's load (needs valgrind; "
                        "default: %(default)s)")
    p.add_argument("--scene-repeats", type=_number(int, 1, True), default=defaults.scene_repeats,
                   help=f"runs of each timed scene (default {defaults.scene_repeats})")
    p.add_argument("--no-pin", action="store_true",
                   help="do not pin the timed engine and the harness to separate cores")
    p.add_argument("--timeout", type=_number(float, 0, False), default=3.0,
                   help="seconds allowed per case x engine before it is marked timeout "
                        "(default: %(default)s)")
    p.add_argument("--jobs", type=_number(int, 1, True), default=0,
                   help="cases run at once, each lane with its own workers (default: cores)")
    p.add_argument("--resume", type=Path, metavar="DIR",
                   help="finish a stopped run in DIR without redoing what is done")
    p.add_argument("--no-isolation", action="store_true",
                   help="run engines in this process (faster start, no crash or hang safety)")
    p.add_argument("--worker-memory", type=_number(float, 0, False), metavar="MB",
                   default=defaults.worker_memory_mb,
                   help="resident memory an engine's worker may reach: past it between cases "
                        "the worker is recycled, during a case that case is a crash "
                        f"(\"memory limit\"; default {defaults.worker_memory_mb:g})")
    p.add_argument("--repeat-check", action="store_true",
                   help="after the verdicts, ask every pair with a disagree, error or crash row "
                        "once more, each in a worker process started for it alone, and flag "
                        "the pairs whose answer changes as nondeterministic (off by default: "
                        "it costs a worker start and a query per such pair; on in make run)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run cases on this Dask scheduler (e.g. tcp://host:8786)")
    check.add_run_options(p)  # --junit, --markdown, --baseline: crosscheck check after the run
    p.set_defaults(func=cmd_run)
    _PARSER_DEFAULTS.update({name: p.get_default(name) for name in CHANGES_THE_RUN})
