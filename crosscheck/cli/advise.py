"""``crosscheck advise``: which engine for my scene, from a stored run.

The library is :mod:`crosscheck.report.advise`; this module parses options and prints.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

from rich.markup import escape
from rich.table import Table

from crosscheck.cli.console import fail, out, say
from crosscheck.core.model import Kind

if TYPE_CHECKING:
    from crosscheck.report.advise import Advice, EngineAdvice, Envelope
    from crosscheck.results.store import StoredRun


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``advise``."""
    p = sub.add_parser("advise", help="which engines pass every stored case inside a scene's "
                                      "envelope, cheapest first")
    p.add_argument("run_dir", type=Path, metavar="RUN_DIR", help="a stored run folder")
    p.add_argument("--dim", action="append", metavar="2|3",
                   help="dimension of the scene (repeatable; default: all)")
    p.add_argument("--kind", action="append", metavar="K",
                   help="kind of query (repeatable; default: every pair kind in the run)")
    p.add_argument("--scale", metavar="LO:HI", help="body sizes (radius, largest half-width)")
    p.add_argument("--offset", metavar="MAX", help="largest |coordinate| of any centre")
    p.add_argument("--speed", metavar="MAX", help="largest |velocity component| (responses)")
    p.add_argument("--mass-ratio", metavar="MAX", help="largest max(m)/min(m) (responses)")
    p.add_argument("--tolerance", metavar="T",
                   help="accuracy needed: a disagreement within T passes (never a wrong hit)")
    p.add_argument("--include-bad-input", action="store_true",
                   help="also judge cases tagged bad-input")
    p.add_argument("--json", action="store_true", help="print the advice as JSON")
    p.set_defaults(func=cmd_advise)


class OptionError(ValueError):
    """A command-line value that cannot be used; the message names the option."""


def _number(option: str, text: str | None) -> float | None:
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        raise OptionError(f"{option}: not a number: {text!r}") from None
    if math.isnan(value):
        raise OptionError(f"{option}: not a number: {text!r}")
    return value


def _scale(text: str | None) -> tuple[float, float] | None:
    if text is None:
        return None
    parts = text.split(":")
    if len(parts) != 2:
        raise OptionError(f"--scale: expected LO:HI, got {text!r}")
    lo, hi = (_number("--scale", part) for part in parts)
    assert lo is not None and hi is not None
    return lo, hi


def _dims(texts: list[str] | None) -> tuple[int, ...]:
    dims = tuple(text.strip() for text in texts or [])
    for text in dims:
        if text not in ("2", "3"):
            raise OptionError(f"--dim: must be 2 or 3, got {text!r}")
    return tuple(sorted({int(text) for text in dims}))


def _kinds(texts: list[str] | None) -> tuple[str, ...]:
    known = [str(k) for k in Kind]
    for text in texts or []:
        if text not in known:
            raise OptionError(f"--kind: unknown kind {text!r} (choose from {', '.join(known)})")
    return tuple(dict.fromkeys(texts or []))


def envelope_of(args: argparse.Namespace) -> Envelope:
    """The envelope the options state; OptionError or EnvelopeError naming a bad option."""
    from crosscheck.report.advise import Envelope

    envelope = Envelope(
        dims=_dims(args.dim), kinds=_kinds(args.kind), scale=_scale(args.scale),
        offset=_number("--offset", args.offset), speed=_number("--speed", args.speed),
        mass_ratio=_number("--mass-ratio", args.mass_ratio),
        tolerance=_number("--tolerance", args.tolerance),
        include_bad_input=args.include_bad_input)
    envelope.check()
    return envelope


def _stored(directory: Path) -> StoredRun:
    from crosscheck.results.store import read_run

    if not directory.is_dir():
        raise OptionError(f"RUN_DIR: {directory} is not a folder")
    run = read_run(directory)
    if run.results.empty:
        raise OptionError(f"RUN_DIR: {directory} holds no results")
    return run


def cmd_advise(args: argparse.Namespace) -> int:
    from crosscheck.report.advise import EnvelopeError, advise
    from crosscheck.results.store import StoreError

    try:
        envelope = envelope_of(args)
        run = _stored(args.run_dir)
        advice = advise(run, envelope)
    except (OptionError, EnvelopeError) as exc:
        fail(str(exc))
        return 2
    except StoreError as exc:
        fail(f"RUN_DIR: {exc}")
        return 2
    if args.json:
        say(json.dumps(advice.to_json(), indent=2))
        return 0 if advice.cases else 1
    if not advice.cases:
        fail("no case of the run lies inside this envelope: widen it")
        return 1
    print_advice(advice)
    return 0


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value * 1e6:.3g} µs"


def _why(engine: EngineAdvice) -> str:
    """One line per reason: unsupported kinds and dimensions, then the worst cases."""
    lines = [f"does not support {', '.join(engine.unsupported)}"] if engine.unsupported else []
    lines += [f"{c.case_id}  {c.quantity} {c.status}" + (f"/{c.category}" if c.category else "")
              + ("" if c.error is None else f" error {c.error:.3g}") for c in engine.culprits]
    if engine.failing_cases > len(engine.culprits):
        lines.append(f"... and {engine.failing_cases - len(engine.culprits)} more cases")
    return escape("\n".join(lines) or "answered no case here")


def print_advice(advice: Advice) -> None:
    """The engines that pass, cheapest first, then the others with the cases that rule them out."""
    tolerance = advice.envelope.tolerance
    title = (f"{advice.cases} cases inside the envelope ({', '.join(advice.kinds)}; "
             f"{', '.join(f'{d}-D' for d in advice.dims)}; tolerance "
             f"{'none: agree only' if tolerance is None else f'{tolerance:g}'})")
    table = Table(title=title)
    table.add_column("engine", no_wrap=True)
    table.add_column("verdict", no_wrap=True)
    table.add_column("cases", justify="right", no_wrap=True)
    table.add_column("median query", justify="right", no_wrap=True)
    table.add_column("failing", justify="right", no_wrap=True)
    table.add_column("ruled out by (worst first)", overflow="fold")
    for engine in advice.passing:
        table.add_row(engine.engine, "[green]passes[/green]", str(engine.cases),
                      _seconds(engine.median_query_s), "0", "")
    for engine in advice.failing:
        table.add_row(engine.engine, "[red]ruled out[/red]", str(engine.cases),
                      _seconds(engine.median_query_s), str(engine.failing_cases),
                      _why(engine))
    out.print(table)
    say(f"{len(advice.passing)} of {len(advice.passing) + len(advice.failing)} engines pass "
        "every case inside this envelope" + (", cheapest first" if advice.passing else ""))
