"""``crosscheck bench``: the command of the harness bench (:mod:`crosscheck.studies.bench`)."""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from rich.table import Table

from crosscheck.cli.console import fit, say, stdout
from crosscheck.cli.folders import OUT_RULE, chosen

if TYPE_CHECKING:
    from crosscheck.studies.bench import Comparison, Figure


def cmd_bench(args: argparse.Namespace) -> int:
    from crosscheck.studies.bench import ROOT, BenchFileError, compare, load, measure, write

    try:
        previous = load(args.compare) if args.compare else None
    except BenchFileError as exc:
        say(str(exc))
        return 2
    figures = measure(args.quick, progress=say, full_runs=args.full_runs,
                      campaign=args.campaign, deep=args.deep)
    stdout.print(_table(figures, args.quick))
    stamp = time.strftime("%Y%m%d-%H%M%S")
    path = write(figures, chosen(args.out) or ROOT / "reports" / f"bench-{stamp}", args.quick)
    say(f"wrote {path}")
    if previous is not None:
        _print_comparison(compare(json.loads(path.read_text()), previous), args.compare)
    return 0


def _table(figures: list[Figure], quick: bool) -> Table:
    table = Table(title="crosscheck bench" + (" --quick" if quick else ""))
    for column in ("figure", "measured", "target", "met", "note"):
        table.add_column(column)
    for f in figures:
        value = f"{f.value:.3g} {f.unit}" if math.isfinite(f.value) else "-"
        met = "recorded" if not f.gating else "yes" if f.ok else "NO"
        table.add_row(f.name, value, f.target, met, f.note)
    return fit(table)


def _print_comparison(result: Comparison, old: Path) -> None:
    if result.machine:
        say(f"the machines differ from {old}; compare with care: "
            + "; ".join(result.machine))
    table = Table(title=f"against {old}")
    for column in ("figure", "before", "now", "now / before", "met before", "met now"):
        table.add_column(column)
    for r in result.rows:
        def shown(x: float, unit: str = r.unit) -> str:
            return f"{x:.3g} {unit}" if math.isfinite(x) else "-"
        met = {True: "yes", False: "NO", None: "-"}
        table.add_row(r.name, shown(r.old), shown(r.new),
                      f"{r.ratio:.2f}" if math.isfinite(r.ratio) else "-",
                      met[r.ok_old], met[r.ok_new] if r.gating else "recorded")
    stdout.print(fit(table))


def _at_least(low: int) -> Callable[[str], int]:
    """An argparse type: a whole number >= ``low``."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"{value} is under {low:,}")
        return value
    return parse


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``bench``."""
    p = sub.add_parser("bench", help="measure the harness's own performance against targets")
    p.add_argument("--out", metavar="DIR",
                   help=f"output folder (default: reports/bench-<time>/; {OUT_RULE})")
    p.add_argument("--quick", action="store_true", help="smaller sizes, no full-suite run")
    p.add_argument("--full-runs", type=_at_least(1), default=3, metavar="N",
                   help="times the full make run is timed; its figure is their median "
                        "(default 3)")
    p.add_argument("--deep", action="store_true",
                   help="also time make run-deep once (recorded, not judged) and its report")
    p.add_argument("--campaign", type=_at_least(1_000), metavar="CASES",
                   help="fuzz campaign cases (default 1,000,000; 2,000 with --quick); under a "
                        "million the figure is extrapolated and only recorded")
    p.add_argument("--compare", type=Path, metavar="BENCH_JSON",
                   help="a previous bench.json: print each figure beside it, machines first")
    p.set_defaults(func=cmd_bench)
