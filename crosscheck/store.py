"""The results store of one run: a directory joined to the report by versioned files.

``reports/<run-id>/`` holds:

- ``results.jsonl``: one Record per line, appended and flushed as each
  case x engine finishes, so a killed run keeps everything it finished;
- ``cases.jsonl``: the validated inputs of every case run, for the report;
- ``run.json``: format version, machine, versions, engines and their
  conventions, options, and start and end times;
- ``results.csv``: the tidy table, written from ``results.jsonl``.

Running writes these; reporting only reads them.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import IO, Any

import pandas as pd

from crosscheck.model import COLUMNS, Record
from crosscheck.schema import AnyCase

FORMAT_VERSION = 1
"""Version of the results format; bump it when columns or files change meaning."""


class StoreError(RuntimeError):
    """The results directory cannot be used."""


class ResultsStore:
    """Append-only writer for one run directory."""

    def __init__(self, directory: Path) -> None:
        self.directory = directory
        try:
            directory.mkdir(parents=True, exist_ok=True)
            probe = directory / ".write-test"
            probe.write_text("")
            probe.unlink()
        except OSError as exc:
            raise StoreError(f"cannot write results to {directory}: {exc}") from exc
        self._results: IO[str] = (directory / "results.jsonl").open("a", encoding="utf-8")
        self._cases: IO[str] = (directory / "cases.jsonl").open("a", encoding="utf-8")

    def add_case(self, case: AnyCase) -> None:
        """Record the inputs of a case that is about to run."""
        self._cases.write(json.dumps(case.model_dump(mode="json") | {"source": case.source}))
        self._cases.write("\n")
        self._cases.flush()

    def append(self, records: Iterable[Record]) -> None:
        """Append finished records and flush them to disk."""
        for record in records:
            self._results.write(json.dumps(record.row()) + "\n")
        self._results.flush()

    def write_run_info(self, info: dict[str, Any]) -> None:
        """Write ``run.json`` (replacing any previous one)."""
        info = {"format_version": FORMAT_VERSION, **info}
        (self.directory / "run.json").write_text(json.dumps(info, indent=2) + "\n")

    def close(self) -> None:
        self._results.close()
        self._cases.close()


def read_results(directory: Path) -> pd.DataFrame:
    """The results of a run as a DataFrame, one row per record, in COLUMNS order."""
    path = directory / "results.jsonl"
    rows = []
    if path.exists():
        for line in path.read_text(encoding="utf-8").splitlines():
            try:
                rows.append(json.loads(line))
            except json.JSONDecodeError:
                continue  # a half-written last line of a killed run
    frame = pd.DataFrame(rows, columns=list(COLUMNS))
    return frame.astype({"dim": "int64", "loops": "int64"}) if rows else frame


def read_cases(directory: Path) -> dict[str, dict[str, Any]]:
    """The stored case inputs of a run, by id."""
    path = directory / "cases.jsonl"
    if not path.exists():
        return {}
    cases = (json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line)
    return {case["id"]: case for case in cases}


def read_run_info(directory: Path) -> dict[str, Any]:
    """``run.json`` of a run, checking its format version."""
    info: dict[str, Any] = json.loads((directory / "run.json").read_text())
    if info.get("format_version") != FORMAT_VERSION:
        raise StoreError(f"{directory}/run.json has format {info.get('format_version')}, "
                         f"this harness reads format {FORMAT_VERSION}")
    return info


def write_csv(frame: pd.DataFrame, directory: Path) -> Path:
    """Write ``results.csv`` from a results DataFrame."""
    path = directory / "results.csv"
    frame.to_csv(path, index=False)
    return path
