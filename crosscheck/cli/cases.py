"""``crosscheck validate``, ``new-case`` and ``schema``: the case files' commands."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rich.table import Table

from crosscheck.cli.console import fail, report_case_errors, say, stderr, stdout
from crosscheck.core.model import NEW_CASE_KINDS

if TYPE_CHECKING:
    from crosscheck.cases.cover import Coverage


def cmd_validate(args: argparse.Namespace) -> int:
    from crosscheck.cases.cover import coverage
    from crosscheck.cases.load import load_paths

    loaded = load_paths(args.paths or [Path("cases")])
    report_case_errors(loaded)
    if not loaded.files:
        stderr.print("[red]invalid:[/red] no case files found")
        return 1
    say(f"{'FAILED' if loaded.errors else 'ok'}: {len(loaded.errors)} errors; "
        f"{loaded.blocks} curated cases in {len(loaded.files)} files, {len(loaded.cases)} "
        "after sweep expansion, [[cover]] designs and A/B swaps",
        style="red" if loaded.errors else "green")
    stdout.print(coverage_table(coverage(loaded.cases, 2), coverage(loaded.cases, 3)))
    return 1 if loaded.errors else 0


def coverage_table(two_way: Sequence[Coverage], three_way: Sequence[Coverage]) -> Table:
    """Per kind and dimension: the cases, and the configuration space's cells they cover two
    and three dimensions at a time (3-way: the space's strong dimensions)."""
    table = Table(title="coverage of the configuration space (docs/coverage.md)")
    for column in ("kind", "dim", "cases", "2-way cells", "3-way cells"):
        table.add_column(column, justify="left" if column == "kind" else "right")
    for two, three in zip(two_way, three_way, strict=True):
        table.add_row(two.kind.value, str(two.dim), str(two.cases),
                      f"{two.covered} / {two.cells} ({two.share:.0%})",
                      f"{three.covered} / {three.cells} ({three.share:.0%})" if three.cells
                      else "-")
    return table


def _floats(text: str) -> list[float]:
    """An argparse type: comma-separated numbers (a vector)."""
    try:
        return [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be numbers separated by commas, such as 1,0,0.5, not {text!r}") from None


def _float(text: str) -> float:
    """An argparse type: one number (``1,2`` is refused, not cut to 1)."""
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be one number, not {text!r}") from None


def _body(args: argparse.Namespace, side: str) -> dict[str, object]:
    body: dict[str, object] = {}
    for key in ("center", "half", "radius", "mass", "velocity"):
        value = getattr(args, f"{side}_{key}")
        if value is not None:
            body[key] = value
    return body


def cmd_new_case(args: argparse.Namespace) -> int:
    from crosscheck.cases.newcase import NewCaseError, append_case

    try:
        append_case(args.file, args.kind, args.dim, args.id, description=args.description,
                    tags=args.tag, a=_body(args, "a"), b=_body(args, "b"),
                    restitution=args.restitution, duration=args.duration)
    except NewCaseError as exc:
        for problem in exc.problems:
            fail(problem)
        return 2
    say(f"appended case {args.id!r} to {args.file.resolve()}; check: crosscheck validate "
        f"{args.file}")
    return 0


def cmd_schema(args: argparse.Namespace) -> int:
    from crosscheck.core.schema import json_schema_text

    text = json_schema_text()
    if args.check:
        current = args.output.read_text() if args.output.exists() else ""
        if current != text:
            stderr.print(f"{args.output} is out of date; run: crosscheck schema")
            return 1
        return 0
    args.output.write_text(text)
    say(f"wrote {args.output}")
    return 0


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``validate``, ``new-case`` and ``schema``."""
    p = sub.add_parser("validate", help="check case files")
    p.add_argument("paths", nargs="*", type=Path,
                   help="case files or folders (default: cases/)")
    p.set_defaults(func=cmd_validate)
    p = sub.add_parser("new-case", help="append a valid template case to a file")
    p.add_argument("--kind", required=True, choices=NEW_CASE_KINDS,
                   help="the kind of query")
    p.add_argument("--dim", required=True, type=int, choices=[2, 3], help="2 or 3 dimensions")
    p.add_argument("--id", required=True, help="the new case's id, unique in the suite")
    p.add_argument("--file", type=Path, default=Path("cases/user.toml"),
                   help="case file to append to, created if missing (default: cases/user.toml, "
                        "relative to the current folder)")
    p.add_argument("--description", help="what the case probes")
    p.add_argument("--tag", action="append", help="a tag (repeatable)")
    p.add_argument("--restitution", type=float, help="sphere_response only (default 1)")
    p.add_argument("--duration", type=float,
                   help="sphere_toi only: the interval [0, duration] in s (default 1)")
    for side in ("a", "b"):
        for key, help_text in (("center", "x,y[,z]"), ("half", "half-widths hx,hy[,hz]"),
                               ("velocity", "vx,vy[,vz]")):
            p.add_argument(f"--{side}-{key}", type=_floats, metavar=help_text.split()[-1],
                           help=f"body {side.upper()}: {help_text}")
        for key in ("radius", "mass"):
            p.add_argument(f"--{side}-{key}", type=_float, metavar="X",
                           help=f"body {side.upper()}: {key}")
    p.set_defaults(func=cmd_new_case)
    p = sub.add_parser("schema", help="write the case-file JSON Schema")
    p.add_argument("--output", type=Path, default=Path("cases/schema.json"),
                   help="where to write it (default: %(default)s)")
    p.add_argument("--check", action="store_true", help="fail if the file is out of date")
    p.set_defaults(func=cmd_schema)
