"""``crosscheck report`` and ``crosscheck compare``: stored runs to CSV, HTML and Markdown."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from crosscheck.cli.console import fail, phase_bars, say, stderr
from crosscheck.cli.folders import OUT_RULE, chosen

if TYPE_CHECKING:
    from crosscheck.results.changes import Changes

COMPARE_DESCRIPTION = """\
Two runs (A B): what differs between them (cases, engines, options, versions,
machines), the verdict changes, cost and timing changes (compare.html), then,
for every engine of both (or --from ENGINE --to ENGINE), what changed by
failure mode (changes.md, changes.csv).

One run (A --from X --to Y): what changed from engine X to engine Y of that
run, such as two versions run side by side (crosscheck run --engine
pymunk@6.11.1 --engine pymunk).

A row of Y judged against X's by the baseline rules (crosscheck check): a new
disagreement, an error larger beyond the margin or smaller beyond the stale
factor, a new failure, a row newly (or no longer) answered. Each failure mode
lists examples with the repro command of both sides. Exit code 0 once written
(a report, not a check: crosscheck check fails), 2 for bad input."""


def cmd_report(args: argparse.Namespace) -> int:
    from crosscheck.report.render import STEPS, markdown_summary, render
    from crosscheck.results.run import read_run
    from crosscheck.results.store import StoreError

    try:
        run = read_run(args.directory)
        with phase_bars() as phases:
            paths = render(run, phases("report", STEPS))
    except (OSError, StoreError) as exc:
        fail(f"cannot render {args.directory}: {exc}")
        return 2
    if args.markdown:
        print(markdown_summary(run.results))
    say(f"report: {paths['report']}")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from crosscheck.results.changes import side, what_changed, write
    from crosscheck.results.store import StoreError

    if (args.from_engine is None) != (args.to_engine is None):
        fail("--from and --to go together: the engine before and the engine after")
        return 2
    if args.b is None and args.from_engine is None:
        fail("compare of one run needs --from ENGINE --to ENGINE (two engines of that run, "
             "such as --from pymunk@6.11.1 --to pymunk); or give two runs")
        return 2
    one = args.b is None
    a, b = args.a, args.a if one else args.b
    default = (f"changes-{a.name}-{args.from_engine}-vs-{args.to_engine}" if one
               else f"compare-{a.name}-vs-{b.name}")
    target = chosen(args.out) or Path("reports") / default
    try:
        if not one:
            _compared(a, b, target)
        if args.from_engine is not None:
            pairs = [(side(a, args.from_engine), side(b, args.to_engine))]
        else:
            pairs = [(side(a, e), side(b, e)) for e in _shared_engines(a, b)]
        found = [what_changed(x, y) for x, y in pairs]
        paths = write(found, target)
    except KeyError as exc:
        fail(f"cannot compare: {exc.args[0]}")
        return 2
    except (OSError, StoreError) as exc:
        fail(f"cannot compare: {exc}")
        return 2
    _say_changes(found, paths["markdown"])
    return 0


def _shared_engines(a: Path, b: Path) -> list[str]:
    from crosscheck.results.run import read_run_info

    theirs = set(read_run_info(b).engine_names)
    return [e for e in read_run_info(a).engine_names if e in theirs]


def _say_changes(found: Sequence[Changes], markdown: Path) -> None:
    """One line per engine pair that changed, with its largest failure modes."""
    quiet = [c for c in found if not c.changed]
    for changes in found:
        if not changes.changed:
            continue
        counts = ", ".join(f"{n} {v}" for v, n in sorted(changes.counts().items()))
        say(f"what changed, {changes.before.label} -> {changes.after.label}: "
            f"{changes.changed} of {changes.compared} rows ({counts}) in "
            f"{len(changes.modes)} failure modes; the largest:")
        for mode, rows in list(changes.modes.items())[:5]:
            say(f"  {len(rows):>6}  {mode}")
    for changes in quiet:
        say(f"no row changed from {changes.before.label} to {changes.after.label} "
            f"({changes.compared} rows; {changes.answered_differently} answer differently "
            "within the margin and factor)")
    say(f"what changed, by failure mode, with repro commands: {markdown}")


def _compared(a: Path, b: Path, target: Path) -> None:
    """The two-run comparison (verdicts, cost, timing) written into ``target``, and said."""
    from crosscheck.compare.runs import compare
    from crosscheck.compare.timing import ALPHA, MIN_EFFECT

    result = compare(a, b, target)
    for difference in result.differences:
        say(f"warning: {difference}", stderr)
    counts = result.timing_counts
    yardstick = "after the yardstick" if result.normalised else "not normalised"
    if result.cost_counts is not None:
        cost = result.cost_counts
        say(f"cost (counted instructions, both runs): {cost['more']} more work, {cost['less']} "
            f"less work, {cost['unknown']} unknown of {result.cost_pairs} pairs (beyond "
            f"{result.cost_threshold * 100:g}% of instructions per query)")
    else:
        say(f"cost: not compared (timers: A {result.timers[0]}, B {result.timers[1]}; counts "
            "only against counts)")
    say(f"{result.verdict_changes} verdict changes among the {result.shared_rows} shared rows "
        f"({len(result.added_cases)} added, {len(result.removed_cases)} removed); timing: "
        f"{counts['slower']} slower, {counts['faster']} faster, {counts['unknown']} unknown "
        f"of {result.timing_pairs} pairs (p < {ALPHA:g} and beyond x{MIN_EFFECT:g}, "
        f"{yardstick}); see {target / 'compare.html'}")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``report`` and ``compare``."""
    p = sub.add_parser("report", help="re-render CSV and HTML from a stored run")
    p.add_argument("directory", type=Path, help="a stored run folder (reports/<run-id>)")
    p.add_argument("--markdown", action="store_true", help="also print the summary as Markdown")
    p.set_defaults(func=cmd_report)
    p = sub.add_parser("compare", help="what changed between two stored runs, or between two "
                                       "engine versions in one run",
                       description=COMPARE_DESCRIPTION,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("a", type=Path, help="the earlier run directory")
    p.add_argument("b", type=Path, nargs="?",
                   help="the later run directory (none: compare two engines of A)")
    p.add_argument("--from", dest="from_engine", metavar="ENGINE",
                   help="the engine before (e.g. pymunk@6.11.1), in A")
    p.add_argument("--to", dest="to_engine", metavar="ENGINE",
                   help="the engine after (e.g. pymunk), in B (or in A if there is no B)")
    p.add_argument("--out", metavar="DIR",
                   help=f"output folder (default: reports/compare-A-vs-B/; {OUT_RULE})")
    p.set_defaults(func=cmd_compare)
