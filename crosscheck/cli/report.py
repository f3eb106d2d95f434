"""``crosscheck report`` and ``crosscheck compare``: stored runs to CSV and HTML."""

from __future__ import annotations

import argparse
from pathlib import Path

from crosscheck.cli.console import err, fail, say
from crosscheck.cli.folders import OUT_RULE, chosen


def cmd_report(args: argparse.Namespace) -> int:
    from crosscheck.report.render import markdown_summary, render
    from crosscheck.results.store import StoreError, read_results

    try:
        paths = render(args.directory)
    except (OSError, StoreError) as exc:
        fail(f"cannot render {args.directory}: {exc}")
        return 2
    if args.markdown:
        print(markdown_summary(read_results(args.directory)))
    say(f"report: {paths['report']}")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from crosscheck.report.compare import compare
    from crosscheck.report.compare_timing import ALPHA, MIN_EFFECT
    from crosscheck.results.store import StoreError

    target = chosen(args.out) or Path("reports") / f"compare-{args.a.name}-vs-{args.b.name}"
    try:
        result = compare(args.a, args.b, target)
    except (OSError, StoreError) as exc:
        fail(f"cannot compare: {exc}")
        return 2
    for difference in result.differences:
        say(f"warning: {difference}", err)
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
    return 0


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``report`` and ``compare``."""
    p = sub.add_parser("report", help="re-render CSV and HTML from a stored run")
    p.add_argument("directory", type=Path, help="a stored run folder (reports/<run-id>)")
    p.add_argument("--markdown", action="store_true", help="also print the summary as Markdown")
    p.set_defaults(func=cmd_report)
    p = sub.add_parser("compare", help="verdict and timing changes between two stored runs")
    p.add_argument("a", type=Path, help="the earlier run directory")
    p.add_argument("b", type=Path, help="the later run directory")
    p.add_argument("--out", metavar="DIR",
                   help=f"output folder (default: reports/compare-A-vs-B/; {OUT_RULE})")
    p.set_defaults(func=cmd_compare)
