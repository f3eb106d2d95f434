"""``crosscheck bench``: the command of the harness bench (:mod:`crosscheck.studies.bench`)."""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

from rich.table import Table

from crosscheck.cli.console import out, say
from crosscheck.studies.bench import ROOT, measure, write


def cmd_bench(args: argparse.Namespace) -> int:
    figures = measure(args.quick, progress=say)
    table = Table(title="crosscheck bench" + (" --quick" if args.quick else ""))
    for column in ("figure", "measured", "target", "met", "note"):
        table.add_column(column)
    for f in figures:
        value = f"{f.value:.3g} {f.unit}" if math.isfinite(f.value) else "-"
        table.add_row(f.name, value, f.target, "yes" if f.ok else "NO", f.note)
    out.print(table)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    path = write(figures, args.out or ROOT / "reports" / f"bench-{stamp}", args.quick)
    say(f"wrote {path}")
    return 0


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``bench``."""
    p = sub.add_parser("bench", help="measure the harness's own performance against targets")
    p.add_argument("--out", type=Path, help="output folder (default: reports/bench-<time>/)")
    p.add_argument("--quick", action="store_true", help="smaller sizes, no full-suite run")
    p.set_defaults(func=cmd_bench)
