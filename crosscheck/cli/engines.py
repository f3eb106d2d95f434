"""``crosscheck engines``, and choosing engines by name for every command that runs them."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from rich.table import Table

import adapters
from crosscheck.cli.console import out
from crosscheck.core.contract import Adapter, engine_info

UnknownEngine = adapters.UnknownEngine


def names() -> list[str]:
    """Every engine name the registry knows, in registry order."""
    return adapters.names()


def select(names: Sequence[str] | None) -> list[Adapter]:
    """The named engines, or every available one; raises UnknownEngine for a bad name."""
    if names:
        return [adapters.get(name) for name in names]
    chosen = [adapters.get(name) for name in adapters.names()]
    return [a for a in chosen if a.available() is None]


def cmd_engines(args: argparse.Namespace) -> int:
    table = Table(title="engines")
    columns = ["name", "version", "available", "capabilities"]
    for column in [*columns, "settings"] if args.settings else columns:
        table.add_column(column, no_wrap=column in ("name", "version"))
    for name in adapters.names():
        info = engine_info(adapters.get(name))
        caps = info["capabilities"]
        assert isinstance(caps, list)
        row = [str(info["name"]), str(info["version"]), str(info["available"]), ", ".join(caps)]
        table.add_row(*row, *([str(info["settings"])] if args.settings else []))
    out.print(table)
    return 0


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``engines``."""
    p = sub.add_parser("engines", help="list adapters, versions, capabilities, availability")
    p.add_argument("--settings", action="store_true", help="also show each variant's settings")
    p.set_defaults(func=cmd_engines)
