"""``crosscheck coverage``: which cells of the configuration space a run or a fuzz campaign
asked, and each engine's worst status and largest error in each (crosscheck.report.coverage).

RUN is a run folder (``run.json``) or a fuzz campaign's folder (``campaign.json``).  A
campaign stores only its findings, so its cases are regenerated from its seed and bias
(:mod:`crosscheck.studies.fuzz`), each finding checked against the case the seed makes, and
handed to the report layer with the finding rows: a case without a finding agrees.  Writes
``coverage.csv`` and ``coverage.html`` (the report's coverage section as a page of its own: a
campaign has no report) into RUN (or ``--out DIR``) and prints, per kind and dimension, the
cells covered and those left empty.
"""

from __future__ import annotations

import argparse
import math
import shlex
import tempfile
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from crosscheck.cli.console import fail, progress_bar, say, stderr
from crosscheck.cli.folders import OUT_RULE, chosen

if TYPE_CHECKING:
    import pandas as pd

    from crosscheck.core.schema import AnyCase
    from crosscheck.report.coverage import CoverageMap

LIMIT = 12
"""Empty cells listed per dimension pair (or triple) unless ``--limit`` says otherwise."""

DESCRIPTION = """\
Place every case of RUN (bad-input cases left out) in its cells of its kind's
configuration space, measured from its geometry (docs/coverage.md): every pair of
levels of two dimensions, and every triple of direction x gap x size ratio. Writes
coverage.csv (one row per cell x engine: the cell's cases, the engine's worst status
and, for a disagree, its worst category over their rows, the case it comes from and the
largest error in units of the float64 bound) and coverage.html (the report's coverage
heat maps as a page of their own) into RUN or --out DIR, and prints per kind and
dimension the cells covered and those no case asks. RUN may be a fuzz campaign's
folder: its cases are regenerated from its seed (and bias) and each one without a
finding counts as agree. Exit code 0 once written, 2 for bad input."""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``coverage``."""
    p = sub.add_parser("coverage", help="the cells of the configuration space a run or a fuzz "
                                        "campaign covers, and each engine's worst status there",
                       description=DESCRIPTION)
    p.add_argument("run", type=Path, metavar="RUN",
                   help="a run folder (reports/<run-id>) or a fuzz campaign's folder")
    p.add_argument("--out", metavar="DIR",
                   help=f"where coverage.csv and coverage.html go (default: RUN; {OUT_RULE})")
    p.add_argument("--limit", type=int, default=LIMIT, metavar="N",
                   help=f"empty cells listed per dimension pair or triple (default {LIMIT}; "
                        "0: every one; coverage.csv has them all)")
    p.set_defaults(func=cmd_coverage)


def folder_kind(folder: Path) -> str | None:
    """``"campaign"``, ``"run"`` or None (neither: no campaign.json nor run.json)."""
    if (folder / "campaign.json").is_file():
        return "campaign"
    if (folder / "run.json").is_file():
        return "run"
    return None


def unwritable(folder: Path) -> str | None:
    """Why ``coverage.csv`` cannot be written into ``folder`` (made if missing), or None."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        return f"cannot write into {folder}: {exc.strerror or exc}"
    return None


@dataclass(frozen=True)
class Mapped:
    """A folder's coverage map, its engines, and the title and first line of its page."""

    found: CoverageMap
    engines: list[str]
    title: str
    about: str
    source: str


def cmd_coverage(args: argparse.Namespace) -> int:
    from crosscheck.report.coverage import write
    from crosscheck.report.coverage_page import write_page
    from crosscheck.results.store import StoreError
    from crosscheck.studies.fuzz import CampaignError

    source = folder_kind(args.run)
    if source is None:
        fail(f"{args.run} is neither a run folder (no run.json) nor a fuzz campaign's folder "
             "(no campaign.json)")
        return 2
    if args.limit < 0:
        fail(f"--limit must be 0 (every cell) or more, got {args.limit}")
        return 2
    target = chosen(args.out) or args.run
    problem = unwritable(target)
    if problem:
        fail(problem)
        return 2
    try:
        mapped = run_coverage(args.run) if source == "run" else campaign_coverage(args.run)
    except (StoreError, CampaignError, OSError, KeyError, ValueError) as exc:
        fail(f"cannot map the coverage of {args.run}: {exc}")
        return 2
    path = write(mapped.found, target)
    page = write_page(mapped.found, mapped.engines, target,
                      command=shlex.join(["crosscheck", "coverage", str(args.run)]),
                      title=mapped.title, about=mapped.about, source=mapped.source)
    print_coverage(mapped.found, args.limit)
    say(f"coverage: {path} (one row per cell x engine; an empty cell has cases 0)")
    say(f"coverage page: {page} (heat maps per kind and pair of dimensions)")
    return 0


def run_coverage(folder: Path) -> Mapped:
    """The coverage map of the run in ``folder``."""
    from crosscheck.report.coverage import run_map
    from crosscheck.results.run import read_run

    stored = read_run(folder)
    engines = stored.info.engine_names
    about = (f"Run {stored.info.run_id}: {len(stored.cases):,} cases on {len(engines)} "
             f"engines ({', '.join(engines)}); {stored.directory / 'report.html'} holds the "
             "same section.")
    return Mapped(run_map(stored.cases, stored.results, engines), list(engines),
                  f"coverage of run {stored.info.run_id}", about, "run")


def campaign_coverage(folder: Path) -> Mapped:
    """The coverage map of the fuzz campaign in ``folder``: its cases regenerated from its
    seed, its findings read from ``findings.csv``."""
    import pandas as pd

    from crosscheck.report.coverage import campaign_map
    from crosscheck.studies.fuzz import CampaignError, stored_plan

    plan = stored_plan(folder)
    path = folder / "findings.csv"
    if not path.is_file():
        raise CampaignError(f"{path} does not exist: the campaign did not finish (finish it "
                            f"with crosscheck fuzz --resume {folder})")
    findings = pd.read_csv(path, dtype={"case_id": str, "engine": str, "kind": str,
                                        "quantity": str, "status": str, "family": str})
    engines = [str(e) for e in plan["engines"]]
    with progress_bar(int(plan["n"]), "cases regenerated") as advance:
        found = campaign_map(campaign_cases(plan, findings, advance), findings, engines)
    bias = f", biased toward {len(plan['bias'])} failing cells" if plan.get("bias") else ""
    about = (f"Fuzz campaign {folder.name}: {int(plan['n']):,} {plan['kind']} cases from seed "
             f"{plan['seed']}{bias}, on {len(engines)} engines ({', '.join(engines)}). It "
             "keeps only its findings: a case without one counts as agree.")
    return Mapped(found, engines, f"coverage of fuzz campaign {folder.name}", about, "campaign")


def campaign_cases(plan: Mapping[str, Any], findings: pd.DataFrame,
                   advance: Any = None) -> Iterator[AnyCase]:
    """The campaign's cases, chunk by chunk from its seed (and its bias, the failing cells its
    configuration-space cases start from); each case with findings must be
    the one they were found on (same family, dimension and driving value), else the seed no
    longer makes the campaign's cases and :class:`CampaignError` says which."""
    from crosscheck.core.model import Kind
    from crosscheck.studies.fuzz import CampaignError, generate_chunk
    from crosscheck.studies.fuzz.campaign import stored_bias
    from crosscheck.studies.fuzz.generator import chunk_count

    kind, n, seed = Kind(plan["kind"]), int(plan["n"]), int(plan["seed"])
    bias = stored_bias(plan.get("bias", []))
    expected = {str(cid): (str(family), int(dim), float(value)) for cid, family, dim, value
                in zip(findings["case_id"], findings["family"], findings["dim"],
                       findings["driver_value"], strict=True)}
    for chunk in range(chunk_count(n)):
        made = generate_chunk(kind, seed, chunk, n, bias)
        for g in made:
            want = expected.pop(g.case.id, None)
            got = (g.family, g.case.dim, g.value)
            if want is not None and not _same(want, got):
                raise CampaignError(f"case {g.case.id} is not the one its findings were found "
                                    f"on (family, dim, driving value: found {want}, "
                                    f"regenerated {got}); this version of the generator "
                                    "does not make the campaign's cases")
            yield g.case
        if advance is not None:
            advance(len(made))
    if expected:
        raise CampaignError(f"{len(expected)} findings name cases the seed does not make "
                            f"(first: {next(iter(expected))})")


def _same(want: tuple[str, int, float], got: tuple[str, int, float]) -> bool:
    return want[:2] == got[:2] and (want[2] == got[2]
                                    or (math.isnan(want[2]) and math.isnan(got[2])))


def print_coverage(found: CoverageMap, limit: int) -> None:
    """Per kind and dimension: its cases and cells covered, then its empty cells grouped by
    dimension pair or triple (at most ``limit`` listed per group; 0: all)."""
    from crosscheck.report.coverage import covered, empty_cells

    if found.table.empty:
        say("no case of this folder has a cell (only bad-input cases or scenes)", stderr)
        return
    empty = empty_cells(found.table)
    for space in covered(found.table):
        kind, dim = space["kind"], space["dim"]
        cases = next(n for (k, d), n in found.cases.items() if k.value == kind and d == dim)
        three = (f"; 3-way cells {space['covered_3']} / {space['cells_3']}"
                 if space["cells_3"] else "")
        say(f"{kind} {dim}-D: {cases} cases; 2-way cells {space['covered_2']} / "
            f"{space['cells_2']} covered{three}")
        mine = empty[(empty["kind"] == kind) & (empty["dim"] == dim)]
        groups = mine[["dimension_1", "dimension_2", "dimension_3"]].drop_duplicates()
        for names in groups.itertuples(index=False):
            cells = mine[(mine[list(groups.columns)] == list(names)).all(axis=1)]
            levels = ["level_1", "level_2", "level_3"][:len([n for n in names if n])]
            tokens = ["/".join(map(str, row)) for row in cells[levels].itertuples(index=False)]
            shown = tokens[:limit] if limit else tokens
            more = f" and {len(tokens) - len(shown)} more" if len(shown) < len(tokens) else ""
            words = " x ".join(str(n) for n in names if n)
            say(f"  empty, {words} ({len(tokens)}): {', '.join(shown)}{more}")
