"""``crosscheck engines``, and choosing engines by name for every command that runs them.

Engines are the built-in table's and the plug-ins' (the ``crosscheck.adapters``
entry-point group, see :mod:`adapters`).  ``crosscheck engines`` lists every one, built-in
or plug-in, then a line per plug-in naming its distribution and version; one that cannot
be used (its module fails to import, its class is not an Adapter, its name clashes, it
raises) is listed with the reason, never a traceback.  Asking for it by name (``--engine``) is
refused with that reason; running every engine skips it with a note.

``crosscheck engines --claims`` lists every variant's published accuracy claims (bound, regime,
source: :mod:`crosscheck.core.claims`); ``--claims RUN_DIR`` checks them on a stored run
(:func:`crosscheck.report.claims.evaluate`): the claims the run recorded, and those of the
variants it did not run (untested), each with the measured columns and its verdict.
"""

from __future__ import annotations

import argparse
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rich.padding import Padding
from rich.table import Table
from rich.text import Text

import adapters
from crosscheck.cli.console import fail, fit, stderr, stdout

if TYPE_CHECKING:
    from crosscheck.core.claims import Claim
    from crosscheck.core.contract import Adapter

UnknownEngine = adapters.UnknownEngine


def names() -> list[str]:
    """Every engine name: the built-ins in registry order, then the plug-ins."""
    return adapters.all_names()


def _note(message: str) -> None:
    stderr.print(Text(f"note: {message}", style="yellow"))


def _warn_shadowed(chosen: Sequence[str]) -> None:
    """Say so when a chosen built-in's name is also a (refused) plug-in's."""
    for entry in adapters.plugins():
        if entry.name in chosen and entry.name in adapters.REGISTRY:
            _note(f"{entry.describe()} is refused ({entry.clash}); the built-in runs")


def _usable(entry: adapters.Entry) -> Adapter | str:
    """The entry's adapter if it can run here, else the reason it cannot."""
    problem = entry.problem()
    if problem:
        return problem
    try:
        adapter = entry.load()()
        unavailable = adapter.available()
    except Exception as exc:  # a plug-in's fault is a reason, not a traceback
        return f"{type(exc).__name__}: {exc}"
    return unavailable or adapter


def engine_name(text: str) -> str:
    """An argparse type: a known engine name, or ``NAME@VERSION`` (the variant with that
    version of its package, for ``run``).  The version is checked here; the environment is
    built later, before any case runs."""
    from crosscheck.run import envs, pinned

    base, version = pinned.split(text)
    known = names()
    if base not in known:
        raise argparse.ArgumentTypeError(f"invalid choice: {base!r} (choose from "
                                         f"{', '.join(map(repr, known))}; NAME@VERSION for a "
                                         "version)")
    problem = envs.check_version(version) if version is not None else None
    if problem:
        raise argparse.ArgumentTypeError(problem)
    return text


def _made(name: str) -> Adapter:
    """The adapter called ``name`` (``NAME@VERSION``: that variant in the cached environment
    of its package's version, built first if need be); RefusedEngine, with the reason, if it
    cannot be made."""
    from crosscheck.run import envs, pinned

    base, version = pinned.split(name)
    entry = adapters.find(base)
    cls = entry.load()
    if version is not None:
        try:
            env = envs.ensure(cls.package or base, version,
                              lambda line: stderr.print(Text(line), soft_wrap=True))
            cls = pinned.pin(cls, env)
        except envs.EnvError as exc:
            raise adapters.RefusedEngine(f"{name}: {exc}") from None
    try:
        return cls()
    except Exception as exc:  # a plug-in's fault is a reason, not a traceback
        raise adapters.RefusedEngine(f"{entry.describe()} {entry.verdict}: it fails: "
                                     f"{type(exc).__name__}: {exc}") from None


def select(names: Sequence[str] | None) -> list[Adapter]:
    """The named engines, or every available one (with a note for each that cannot be
    used); raises UnknownEngine (or its RefusedEngine) for a bad name."""
    from crosscheck.core.contract import Adapter

    if names:
        _warn_shadowed(names)
        return [_made(name) for name in names]
    chosen = []
    for entry in adapters.entries():
        usable = _usable(entry)
        if isinstance(usable, Adapter):
            chosen.append(usable)
        elif not entry.builtin or entry.problem():  # a built-in not installed: as ever
            _note(f"skipping {entry.describe()}: {usable}")
    return chosen


def _row(entry: adapters.Entry, settings: bool) -> tuple[list[Text], str | None]:
    """One row of the listing (name, built-in or plug-in, version, availability,
    capabilities[, settings]) and why the entry cannot be used (None: it can)."""
    from crosscheck.core.contract import engine_info

    problem = entry.problem()
    info: dict[str, object] = {}
    if problem is None:
        try:
            info = engine_info(entry.load()())
        except Exception as exc:  # a plug-in's fault is a reason, not a traceback
            problem = f"it fails: {type(exc).__name__}: {exc}"
    origin = "built-in" if entry.builtin else "plug-in"
    if problem is not None:
        cells = [entry.name, origin, "-", entry.verdict.split()[-1], "", ""]  # reason below
    else:
        caps = info["capabilities"]
        assert isinstance(caps, list)
        cells = [str(info["name"]), origin, str(info["version"]), str(info["available"]),
                 ", ".join(caps), str(info["settings"])]
    texts = [Text(cell, style="red" if problem and i == 3 else "") for i, cell in enumerate(cells)]
    return (texts if settings else texts[:-1]), problem


def cmd_engines(args: argparse.Namespace) -> int:
    table = Table(title="engines")
    longest = max((len(entry.name) for entry in adapters.entries()), default=4)
    for column in ("name", "from", "version", "available", "kinds"):  # kinds: capabilities
        table.add_column(column, no_wrap=column in ("name", "from"),
                         min_width=longest if column == "name" else None)
    lines, settings = [], []
    for entry in adapters.entries():
        row, problem = _row(entry, True)
        table.add_row(*row[:-1])
        if problem:
            lines.append(Text(f"{entry.describe()} {entry.verdict}: {problem}", style="red"))
        elif not entry.builtin:
            lines.append(Text(entry.describe()))
        if problem is None:
            settings.append((row[0].plain, row[-1].plain))
    stdout.print(fit(table))
    if args.settings:  # a list, not a column: settings are sentences, too long for a cell
        stdout.print(Text("settings of each variant:", style="bold"))
        for name, text in settings:
            stdout.print(Text(name, style="bold"))
            stdout.print(Padding(Text(text), (0, 0, 0, 4), expand=False), soft_wrap=False)
    stdout.print(Text(f"Built-ins are the lines of adapters.REGISTRY; plug-ins are the entry "
                   f"points of installed distributions in the {adapters.ENTRY_POINT_GROUP!r} "
                   f"group."), soft_wrap=False)
    for line in lines:
        stdout.print(line, soft_wrap=False)
    return 0


VERDICT_STYLES = {"holds": "green", "fails": "red", "untested": "yellow"}
"""Each claim verdict's colour in the table."""


def declared_claims() -> dict[str, tuple[Claim, ...]]:
    """Every usable variant's declared claims, by name in listing order (variants that
    declare none, or cannot be loaded, left out)."""
    found: dict[str, tuple[Claim, ...]] = {}
    for entry in adapters.entries():
        if entry.problem() is not None:
            continue
        try:
            claims = tuple(entry.load().claims)
        except Exception:
            continue
        if claims:
            found[entry.name] = claims
    return found


def run_problem(directory: Path) -> str | None:
    """Why ``directory`` is not a stored run folder (None: it is)."""
    if not directory.is_dir():
        return f"RUN_DIR: no such run folder: {directory}"
    if not (directory / "run.json").is_file():
        return (f"RUN_DIR: {directory} has no run.json: not a run folder (give the folder "
                "crosscheck run wrote)")
    return None


def cmd_claims(args: argparse.Namespace) -> int:
    """``engines --claims [RUN_DIR]``: the declared claims, or their checks on a run."""
    from crosscheck.report.claims import cells, evaluate
    from crosscheck.results.run import read_run
    from crosscheck.results.runinfo import FormatError
    from crosscheck.results.store import StoreError

    if not args.claims:
        return _list_claims(declared_claims())
    directory = Path(args.claims)
    problem = run_problem(directory)
    if problem:
        fail(problem)
        return 2
    try:
        run = read_run(directory)
        recorded = run.info.claims
        declared = {**recorded, **{name: claims for name, claims in declared_claims().items()
                                   if name not in recorded}}
        checks = evaluate(run, declared)
    except (OSError, StoreError, FormatError, ValueError, KeyError) as exc:
        fail(f"RUN_DIR: cannot read {directory}: {exc}")
        return 2
    table = Table(title=f"published claims against {directory}")
    for column in ("engine", "claim", "inside the regime", "outside", "verdict"):
        table.add_column(column)
    for check in checks:
        c = cells(check)
        verdict = Text(c["verdict"], style=VERDICT_STYLES[check.verdict])
        if c["why"]:
            verdict.append(f": {c['why']}", style="")
        inside = _rows_words(c["inside"], c["worst_inside"], c["worst_inside_case"])
        if c["unanswered"]:
            inside += f"; unanswered: {c['unanswered']}"
        outside = _rows_words(c["outside"], c["worst_outside"], c["worst_outside_case"])
        table.add_row(c["engine"], _claim_words(check.claim), inside, outside, verdict)
    stdout.print(fit(table))
    if not any(recorded.values()):
        stdout.print(Text(f"{directory} records no claim (a run before claims were recorded): "
                          "the claims above are the variants' declared ones, their engines "
                          "not in the run"), soft_wrap=False)
    stdout.print(Text("inside: measured rows (agree, disagree) in the claim's regime; "
                      "unanswered: rows inside without an error, by status (never read as "
                      "0); outside: measured rows of the same kinds outside the regime; "
                      "errors in the quantity's unit (m, rad; a verdict 0 or 1)."),
                 soft_wrap=False)
    return 0


def _rows_words(count: str, worst: str, case_id: str) -> str:
    """``12 rows, worst 3e-07 (case)``; ``0 rows``."""
    return f"{count} rows" + (f", worst {worst} ({case_id})" if worst else "")


def _claim_words(claim: Claim) -> str:
    """A claim in one cell: quantity on its pairs, its bound, its regime."""
    return (f"{claim.quantity} ({', '.join(claim.kinds)}) within {claim.bound_words()}; "
            f"{claim.regime_words()}")


def _list_claims(declared: dict[str, tuple[Claim, ...]]) -> int:
    """The declared claims as a table, then each in its source's words."""
    table = Table(title="published claims")
    for column in ("engine", "quantity", "pairs", "bound", "regime", "source"):
        table.add_column(column)
    for name, claims in declared.items():
        for claim in claims:
            table.add_row(name, claim.quantity, ", ".join(claim.kinds), claim.bound_words(),
                          claim.regime_words(), claim.source)
    stdout.print(fit(table))
    stdout.print(Text("each claim in its source's words:", style="bold"))
    for name, claims in declared.items():
        for claim in claims:
            stdout.print(Text(f"{name}, {claim.quantity} ({', '.join(claim.kinds)})",
                              style="bold"))
            stdout.print(Padding(Text(f"{claim.statement}\n{claim.source}"), (0, 0, 0, 4),
                                 expand=False), soft_wrap=False)
    stdout.print(Text("crosscheck engines --claims RUN_DIR checks them on a stored run."),
                 soft_wrap=False)
    return 0


def _engines_or_claims(args: argparse.Namespace) -> int:
    if args.envs or args.clear_envs:
        return cmd_envs(args)
    return cmd_claims(args) if args.claims is not None else cmd_engines(args)


def cmd_envs(args: argparse.Namespace) -> int:
    """List (or clear) the cached environments of pinned engine versions."""
    from crosscheck.run import envs

    root = envs.cache_root()
    found = envs.cached(root)
    if args.clear_envs:
        shutil.rmtree(root, ignore_errors=True)
        stdout.print(Text(f"removed {len(found)} cached environments and {root}"), soft_wrap=True)
        return 0
    stdout.print(Text(f"cached environments of pinned versions (--engine NAME@VERSION) in {root} "
                   "(set CROSSCHECK_ENVS to move it; --clear-envs or deleting a folder clears "
                   "it):"), soft_wrap=True)
    for env in found:
        stdout.print(Text(f"  {env.package} {env.version}  {env.path}"), soft_wrap=True)
    if not found:
        stdout.print(Text("  (none)"))
    return 0


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``engines``."""
    p = sub.add_parser("engines", help="list adapters (built-in and plug-ins), where each comes "
                                       "from, versions, capabilities, availability")
    p.add_argument("--settings", action="store_true", help="also show each variant's settings")
    p.add_argument("--envs", action="store_true",
                   help="list the cached environments of pinned engine versions "
                        "(run --engine NAME@VERSION) and where they are")
    p.add_argument("--clear-envs", action="store_true",
                   help="delete every cached environment (each is built again on next use)")
    p.add_argument("--claims", nargs="?", const="", default=None, metavar="RUN_DIR",
                   help="list each variant's published accuracy claims (bound, regime, "
                        "source); with a stored run folder, check them on its rows: the worst "
                        "error inside and outside each claim's regime and whether it holds")
    p.set_defaults(func=_engines_or_claims)
