"""The ``crosscheck`` command line: a thin face over the library, one module per command family.

Each family module (``run``, ``report`` with ``compare``, ``coverage``, ``check`` with ``baseline``,
``cases`` with ``validate``, ``new-case`` and ``schema``, ``engines``, ``fuzz``, ``bench``,
``stability``) parses its options, calls the library and prints; everything
it does is callable from Python without rich.

Building the parser must stay cheap (``crosscheck --help`` in about 0.15 s instead of 3 s):
a family module imports at its top only what ``register`` needs (argparse, rich, the
engine names, the option defaults); each ``cmd_*`` function imports the library it runs
(pandas, the loader, launch, the report).  ``tests/cli/test_startup.py`` checks that no
``--help`` imports pandas, numpy, pydantic, plotly, jinja2, Dask or an engine, and
``tests/test_architecture.py`` allows those function-level imports in this package only.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from importlib import metadata

from crosscheck.cli import (
    advise,
    bench,
    cases,
    check,
    coverage,
    engines,
    fuzz,
    report,
    repro,
    run,
    stability,
)
from crosscheck.results.runinfo import FORMAT_VERSION

FAMILIES = (run, report, coverage, check, cases, fuzz, repro, bench, stability, advise,
            engines)
"""The command families, in the order ``crosscheck --help`` lists them."""


EXAMPLES = """examples:
  crosscheck run                          the whole suite on every engine
  crosscheck run --quick --engine fcl     verdicts only, one engine
  crosscheck run cases/sphere.toml --engine pybullet --engine pymunk
  crosscheck report reports/<run>         re-render a stored run
  crosscheck compare reports/<a> reports/<b>
  crosscheck coverage reports/<run>       which cells of the space its cases ask
  crosscheck baseline reports/<run> --out baseline.jsonl
  crosscheck check reports/<run> --baseline baseline.jsonl --junit junit.xml
  crosscheck advise reports/<run> --dim 2 --kind sphere --tolerance 1e-6
  crosscheck repro reports/<run> sphere-2d-gap-1e-3 --engine fcl
  crosscheck validate cases/mine.toml
  crosscheck engines --settings
"""


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command."""
    parser = argparse.ArgumentParser(
        prog="crosscheck", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Collision Crosscheck: collision engines scored against an exact oracle.",
        epilog=EXAMPLES)
    parser.add_argument("--version", action="version", version=version_line())
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                title="commands")
    for family in FAMILIES:
        family.register(sub)
    return parser


def version_line() -> str:
    """``crosscheck --version``: the harness, its results format and the engines it pins."""
    try:
        own = metadata.version("collision-crosscheck")
    except metadata.PackageNotFoundError:
        own = "(not installed)"
    return f"crosscheck {own} (results format {FORMAT_VERSION})"


def main(argv: Sequence[str] | None = None) -> int:
    """Run one ``crosscheck`` command; its exit code."""
    args = build_parser().parse_args(argv)
    try:
        code: int = args.func(args)
    except KeyboardInterrupt:  # a command without its own message: the shell's code for Ctrl-C
        print("interrupted", file=sys.stderr)
        return 130
    return code


if __name__ == "__main__":
    sys.exit(main())
