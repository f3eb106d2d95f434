"""A campaign's bias: the cells of the configuration space where an engine already failed.

``crosscheck fuzz --bias DIR`` reads a stored run or a finished (or partly finished) fuzz
campaign and takes the cell (:func:`crosscheck.cases.space.classify`) of every case on which
some engine answered with an unexplained error (category ``error``) or crashed or hung.  The
generator then starts half of its configuration-space cases from one of those cells, keeping
most of its levels (:data:`~crosscheck.studies.fuzz.generator.BIAS_SHARE`).  The bias is
stored in the campaign's plan, so a resumed campaign draws exactly the same cases.
"""

from __future__ import annotations

import gzip
import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from crosscheck.core.model import Status
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from crosscheck.results.run import read_run
from crosscheck.studies.fuzz.generator import Bias, failing_cells

FAILING = ("error",)
"""The categories of a failing row (besides every crash and timeout)."""


class BiasError(ValueError):
    """A ``--bias`` folder that is neither a stored run nor a fuzz campaign."""


def _failing(rows: Iterable[dict[str, Any]]) -> set[str]:
    return {str(r["case_id"]) for r in rows
            if r.get("category") in FAILING or r.get("status") in (Status.CRASH, Status.TIMEOUT)}


def bias_from(directory: Path) -> Bias:
    """The failing cells of the run or campaign in ``directory`` (:class:`BiasError`)."""
    if (directory / "campaign.json").is_file():
        cases, failing = _campaign(directory)
    elif (directory / "run.json").is_file():
        run = read_run(directory)
        cases = list(run.cases.values())
        frame = run.results
        failing = _failing({"case_id": c, "category": k, "status": s} for c, k, s in zip(
            frame["case_id"], frame["category"], frame["status"], strict=True))
    else:
        raise BiasError(f"--bias {directory}: neither a stored run (run.json) nor a fuzz "
                        "campaign (campaign.json)")
    return failing_cells(cases, failing)


def _campaign(directory: Path) -> tuple[list[AnyCase], set[str]]:
    """The cases with findings of a campaign's finished chunks, and those that failed."""
    cases: list[AnyCase] = []
    failing: set[str] = set()
    for path in sorted((directory / "chunks").glob("c??????.json.gz")):
        with gzip.open(path, "rt", encoding="utf-8") as handle:
            chunk = json.load(handle)
        columns = chunk["columns"]
        failing |= _failing(dict(zip(columns, row, strict=True)) for row in chunk["findings"])
        with gzip.open(path.with_name(path.name.replace(".json.gz", ".inputs.json.gz")), "rt",
                       encoding="utf-8") as handle:
            cases += [CASE_ADAPTER.validate_python(data) for data in json.load(handle).values()]
    return cases, failing
