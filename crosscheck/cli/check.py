"""``crosscheck baseline`` and ``crosscheck check``: a run's rows kept as a baseline, and a
later run checked against it, failing both ways, for an engine's CI.

The judging is :func:`crosscheck.results.baseline.judge` (its table of rules); the JUnit XML
and the Markdown summary are :mod:`crosscheck.compare.ci`.  ``crosscheck run --junit
--markdown --baseline`` writes the same outputs after its report (:func:`add_run_options`,
:func:`after_run`).  Everything a command is given is checked before any work: a bad
option, a missing run folder, a malformed baseline exit 2 (the baseline is read as the
command line is parsed, so a run never starts with a baseline it cannot use).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from rich import box
from rich.console import Console
from rich.table import Table

from crosscheck.cli.console import fail, fit, say, stderr, stdout
from crosscheck.results.baseline import (
    DEFAULT_MARGIN,
    DEFAULT_STALE_FACTOR,
    Baseline,
    BaselineError,
    Finding,
    Verdict,
    read_baseline,
)

if TYPE_CHECKING:
    import pandas as pd

    from crosscheck.results.run import Run

EXIT_CODES = """\
exit codes:
  0  every row as expected (skipped rows too); --update: the baseline rewritten
  1  any regression, stale entry, missing or new row
  2  a usage or input error: a bad option, a missing run folder or one without
     results, an unreadable or malformed baseline (the message names its file,
     its line and the reason), a run with engines the baseline has no row of and
     no --engine to scope the check (the message names the baseline's engines)
"""
SUITE = "crosscheck"
"""The name of the JUnit XML's test suites."""
SHOWN = 30
"""The failing findings printed on the terminal (the rest are counted)."""


class BaselineFile(NamedTuple):
    """A baseline read from a file given on the command line."""

    path: Path
    baseline: Baseline


def baseline_file(text: str) -> BaselineFile:
    """argparse type of ``--baseline``: the file read and checked as the line is parsed."""
    path = Path(text)
    try:
        return BaselineFile(path, read_baseline(path))
    except BaselineError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _at_least(low: float) -> Callable[[str], float]:
    """argparse type: a finite number >= ``low``."""
    def check(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value >= low):
            raise argparse.ArgumentTypeError(f"must be a finite number >= {low:g}, not {text!r}")
        return value
    return check


def _output(text: str) -> str:
    """argparse type of an output file (``-``: stdout): not a folder."""
    if text != "-" and Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a folder: give a file")
    return text


def _run_problem(run: Path) -> str | None:
    """Why ``run`` is not a run folder with results to judge (None: it is)."""
    if not run.is_dir():
        return f"no such run folder: {run}"
    if not (run / "run.json").is_file():
        return f"{run} has no run.json: not a run folder, or a run killed before it started"
    results = run / "results.jsonl"
    if not results.is_file() or not results.stat().st_size:
        return f"{run} has no results (results.jsonl is missing or empty)"
    return None


def _read(run: Path, engines: Sequence[str] | None,
          baseline: Baseline | None) -> tuple[pd.DataFrame, bool] | None:
    """The run's results and whether it finished, after every check (None: refused, said)."""
    from crosscheck.results.run import read_results, read_run_info
    from crosscheck.results.store import StoreError

    problem = _run_problem(run)
    try:
        finished = problem is None and read_run_info(run).finished is not None
        frame = None if problem else read_results(run)
    except (OSError, StoreError, ValueError) as exc:
        problem = f"cannot read {run}: {exc}"
    if problem or frame is None:
        fail(problem or f"cannot read {run}")
        return None
    known = set(frame["engine"]) | (baseline.engines if baseline else set())
    unknown = sorted(set(engines or ()) - known)
    if unknown:
        fail(f"no rows of {', '.join(unknown)} in {run}" + (" or the baseline" if baseline else "")
             + f"; its engines: {', '.join(sorted(known))}")
        return None
    return frame, finished


def cmd_baseline(args: argparse.Namespace) -> int:
    from crosscheck.results.baseline import from_rows, write_baseline

    read = _read(args.run, args.engine, None)
    if read is None:
        return 2
    frame, finished = read
    if not finished:
        fail(f"{args.run} is an unfinished run (its run.json has no end time), and a baseline "
             f"must hold every row: finish it with 'crosscheck run --resume {args.run}', "
             "then make the baseline")
        return 2
    if args.engine:
        frame = frame[frame["engine"].isin(args.engine)]
    baseline = from_rows(frame, args.margin, args.stale_factor, source=str(args.run))
    try:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        write_baseline(baseline, args.out)
    except OSError as exc:
        fail(f"cannot write {args.out}: {exc}")
        return 2
    say(f"baseline: {len(baseline.entries)} rows of {', '.join(sorted(baseline.engines))} from "
        f"{args.run} (margin {baseline.margin:g}, stale factor {baseline.stale_factor:g}) -> "
        f"{args.out}")
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    from crosscheck.results.baseline import judge, updated, write_baseline

    given: BaselineFile | None = args.baseline
    if args.update and given is None:
        fail("--update rewrites the file given by --baseline: give one")
        return 2
    baseline = given.baseline if given else None
    read = _read(args.run, args.engine, baseline)
    if read is None:
        return 2
    frame, finished = read
    if given and not args.engine and not args.update and beyond_baseline(
            frame, given, args.run, "Check only the baseline's engines with"):
        return 2
    console = stderr if args.markdown == "-" else stdout
    if not finished:
        say(f"warning: {args.run} is unfinished: the rows it has not reached are missing", stderr)
    findings = judge(frame, baseline, args.engine, args.margin, args.stale_factor)
    margin = args.margin if args.margin is not None else baseline.margin if baseline else None
    factor = (args.stale_factor if args.stale_factor is not None
              else baseline.stale_factor if baseline else None)
    show(findings, args.run, given, margin, factor, args.engine, console)
    if not write_outputs(findings, args.run, args.junit, args.markdown, given, margin, factor,
                         args.engine):
        return 2
    if args.update:
        assert given is not None
        new = updated(baseline, frame, args.engine, args.margin, args.stale_factor,
                      source=str(args.run))
        try:
            write_baseline(new, given.path)
        except OSError as exc:
            fail(f"cannot write {given.path}: {exc}")
            return 2
        show_changes(findings, given.path, args.run, new, console)
        return 0
    return 1 if any(f.verdict.fails for f in findings) else 0


def beyond_baseline(frame: pd.DataFrame, given: BaselineFile, run: Path, scope: str) -> bool:
    """Whether ``run`` has engines ``given`` holds no row of, said before any row is judged
    (each of their rows would be "new"): the message names the baseline's engines and how
    to scope the check to them (``scope``, followed by ``--engine NAME`` for each)."""
    from crosscheck.results.baseline import engines_beyond

    beyond = engines_beyond(frame, given.baseline)
    if not beyond:
        return False
    known = sorted(given.baseline.engines)
    others = ", ".join(sorted(beyond)[:5]) + (f" and {len(beyond) - 5} more" if len(beyond) > 5
                                              else "")
    fail(f"{given.path} holds rows of {', '.join(known)} only, and {run} also has "
         f"{len(beyond)} engine{'s' if len(beyond) > 1 else ''} it has no row of ({others}): "
         f"each of their {sum(beyond.values()):,} rows would be new. {scope} "
         f"{' '.join(f'--engine {e}' for e in known)}, or add the others to the baseline "
         f"with crosscheck check {run} --baseline {given.path} --update")
    return True


def show(findings: Sequence[Finding], run: Path, given: BaselineFile | None,
         margin: float | None, factor: float | None, engines: Sequence[str] | None,
         console: Console) -> None:
    """The check on the terminal: what was judged, a line per verdict, the failing findings
    (at most :data:`SHOWN`), the outcome."""
    from crosscheck.compare.ci import counts, outcome, scope

    against = (f"against {given.path} (margin {margin:g}, stale factor {factor:g})"
               if given and margin is not None and factor is not None
               else "with no baseline: every disagreement fails")
    say(f"check of {run} {against}; {scope(engines)}", console)
    counted = counts(findings)
    for verdict in Verdict:
        say(f"  {verdict:<11} {counted[verdict]:>7}", console)
    failing = [f for f in findings if f.verdict.fails]
    if failing:
        table = Table(box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False,
                      collapse_padding=True)
        for column in ("verdict", "engine", "case", "quantity", "reason"):
            table.add_column(column)
        for f in failing[:SHOWN]:
            table.add_row(str(f.verdict), f.engine, f.case, f.quantity, f.reason)
        console.print(fit(table), markup=False, highlight=False)
        if len(failing) > SHOWN:
            say(f"and {len(failing) - SHOWN} more (all of them: --junit or --markdown)", console)
    result = outcome(findings)
    say(result, console, style="green" if result == "passed" else "red")


def show_changes(findings: Sequence[Finding], path: Path, run: Path, new: Baseline,
                 console: Console) -> None:
    """What ``--update`` changed in the baseline: counted, then the first rows."""
    from crosscheck.compare.ci import side

    changed = [f for f in findings if not _unchanged(f)]
    added = sum(f.expected is None for f in changed)
    removed = sum(f.got is None for f in changed)
    say(f"updated {path} from {run}: {len(new.entries)} rows (margin {new.margin:g}, stale "
        f"factor {new.stale_factor:g}); {added} added, {removed} removed, "
        f"{len(changed) - added - removed} changed", console)
    for f in changed[:SHOWN]:
        say(f"  {f.engine} {f.case} {f.quantity}: {side(f.expected)} -> {side(f.got)}", console)
    if len(changed) > SHOWN:
        say(f"  and {len(changed) - SHOWN} more (git diff {path})", console)


def _unchanged(finding: Finding) -> bool:
    """Whether the baseline and the run say the same of this row (NaN errors alike)."""
    was, now = finding.expected, finding.got
    if was is None or now is None or (was.status, was.category) != (now.status, now.category):
        return False
    return was.error == now.error or (math.isnan(was.error) and math.isnan(now.error))


def write_outputs(findings: Sequence[Finding], run: Path, junit: str | None,
                  markdown: str | None, given: BaselineFile | None, margin: float | None,
                  factor: float | None, engines: Sequence[str] | None) -> bool:
    """Write the JUnit XML and the Markdown summary asked for; False (said) if one failed."""
    from crosscheck.compare.ci import markdown_summary, write_junit

    try:
        if junit:
            write_junit(findings, SUITE, run, Path(junit))
        if markdown:
            text = markdown_summary(findings, run, baseline=given.path if given else None,
                                    margin=margin, stale_factor=factor, engines=engines)
            if markdown == "-":
                print(text, end="")
            else:
                Path(markdown).parent.mkdir(parents=True, exist_ok=True)
                Path(markdown).write_text(text, encoding="utf-8")
    except OSError as exc:
        fail(f"cannot write the check's output: {exc}")
        return False
    return True


def after_run(run: Run, args: argparse.Namespace) -> int | None:
    """After ``crosscheck run`` rendered its report: the outputs of ``--junit``, ``--markdown``
    and ``--baseline`` for ``run`` (the object the run built, not read again); the check's
    exit code with ``--baseline`` (else None: the run's own)."""
    junit, markdown = getattr(args, "junit", None), getattr(args, "markdown", None)
    given: BaselineFile | None = getattr(args, "baseline", None)
    if junit is None and markdown is None and given is None:
        return None
    from crosscheck.results.baseline import judge

    directory = run.directory
    baseline = given.baseline if given else None
    if given and beyond_baseline(run.results, given, directory,
                                 "Run only the baseline's engines with crosscheck run"):
        return 2
    findings = judge(run.results, baseline)
    margin, factor = (baseline.margin, baseline.stale_factor) if baseline else (None, None)
    show(findings, directory, given, margin, factor, None, stderr if markdown == "-" else stdout)
    if not write_outputs(findings, directory, junit, markdown, given, margin, factor, None):
        return 2
    if given is None:
        return None
    return 1 if any(f.verdict.fails for f in findings) else 0


def _add_outputs(p: argparse.ArgumentParser) -> None:
    p.add_argument("--junit", type=_output, metavar="FILE",
                   help="also write the findings as JUnit XML (a test suite per engine)")
    p.add_argument("--markdown", type=_output, metavar="FILE",
                   help="also write a Markdown summary, e.g. to $GITHUB_STEP_SUMMARY (-: stdout, "
                        "the terminal summary then goes to stderr)")


def add_run_options(p: argparse.ArgumentParser) -> None:
    """``crosscheck run``'s ``--junit``, ``--markdown`` and ``--baseline``: a check after the
    run (:func:`after_run`)."""
    _add_outputs(p)
    p.add_argument("--baseline", type=baseline_file, metavar="FILE",
                   help="check the run against this baseline after its report, as crosscheck "
                        "check does; the run's exit code is then the check's")


def _add_judging(p: argparse.ArgumentParser, margin: float | None,
                 factor: float | None) -> None:
    kept = "default: the baseline's"
    p.add_argument("--margin", type=_at_least(0), default=margin, metavar="M",
                   help="a disagreeing row's error fails above its baseline's times 1+M ("
                        + (f"default {margin:g}" if margin is not None else kept) + ")")
    p.add_argument("--stale-factor", type=_at_least(1), default=factor, metavar="F",
                   help="an error below its baseline's divided by F makes the entry stale ("
                        + (f"default {factor:g}" if factor is not None else kept) + ")")
    p.add_argument("--engine", action="append", metavar="NAME",
                   help="only this engine's rows (repeatable; default: every engine)")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``baseline`` and ``check``."""
    p = sub.add_parser(
        "baseline", help="keep a finished run's rows as the baseline a check compares with",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Write every row of a finished run (status, category, error) to a "
                    "baseline file,\none JSON line per row, sorted: review it and commit it.",
        epilog="exit codes: 0 written; 2 a bad option, a missing, empty or unfinished run")
    p.add_argument("run", type=Path, metavar="RUN", help="a finished run folder")
    p.add_argument("--out", type=Path, metavar="FILE", required=True,
                   help="the baseline file to write (replaced if it exists)")
    _add_judging(p, DEFAULT_MARGIN, DEFAULT_STALE_FACTOR)
    p.set_defaults(func=cmd_baseline)

    p = sub.add_parser(
        "check", help="check a run against a baseline: regressions, stale, missing, new",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Judge every row of RUN against the baseline, failing both ways: a row "
                    "that got\nworse is a regression, one better than the baseline is stale "
                    "(update the\nbaseline), a row only one side has is missing or new.",
        epilog=EXIT_CODES)
    p.add_argument("run", type=Path, metavar="RUN", help="a run folder")
    p.add_argument("--baseline", type=baseline_file, metavar="FILE",
                   help="the baseline (default: none: every disagree, error, crash and "
                        "timeout fails)")
    _add_judging(p, None, None)
    _add_outputs(p)
    p.add_argument("--update", action="store_true",
                   help="rewrite the baseline from RUN (keeping its margin and factor unless "
                        "given), say what changed, exit 0")
    p.set_defaults(func=cmd_check)
