"""A run folder as an object: its info, its typed cases, its rows as columns, its repro scripts.

:class:`Run` is what every reader of a run folder gets: the report, ``compare``, ``advise``,
``stability``, the repro scripts, ``--resume``, and, in the process that wrote the folder,
every phase after the verdicts (:func:`crosscheck.run.launch.launch` builds one and hands the
same object to the repeat check, the timing and cost phases, the report, the CLI's summary
and the baseline check).  :func:`read_run` builds it from disk, migrating older formats
(:mod:`crosscheck.results.runinfo`, :mod:`crosscheck.results.legacy`).

Its rows are read once: ``results.jsonl`` is parsed (by the one reader,
:func:`crosscheck.results.jsonlines.read_lines`) the first time :attr:`Run.results` is
asked for, never before (``--resume`` needs only the info and the cases), and not at all when
the run's ``results.parquet`` is up to date with it and the side files
(:mod:`crosscheck.results.stored`): the table is then read from those columns.  The rows of
``results.jsonl`` are final once the verdict pass has written them; what a later phase
appends goes to the small side files (``repeats.jsonl``, ``timings.jsonl``,
``counts.jsonl``) and :meth:`Run.refresh` reads ``run.json`` and joins them again, without
parsing the rows again.
The ``value`` and ``truth`` columns hold the JSON text ``results.csv`` holds; their values,
decoded once per distinct text, are :attr:`Run.decoded`.
"""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.core.model import COLUMNS, Kind, quantities_of
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from crosscheck.core.values import decode, upgrade
from crosscheck.results import counts, jsonlines, legacy, repeats, stored
from crosscheck.results.runinfo import FORMAT_VERSION, FormatError, RunInfo
from crosscheck.results.store import StoreError, written_repros
from crosscheck.results.timings import read_timings

DECODED = {"value": "value_decoded", "truth": "truth_decoded"}
"""The columns of JSON text (``results.csv`` keeps them as text) and the columns of their
values (None, a bool, a float or a list) in :func:`decoded`."""


def decoded(frame: pd.DataFrame) -> pd.DataFrame:
    """The values of ``frame``'s ``value`` and ``truth`` texts (those it has) as the columns
    :data:`DECODED` names, in ``frame``'s index; each distinct text decoded once (the one
    place a results value is decoded: the report's modules read these columns).

    >>> decoded(pd.DataFrame({"value": ['[1.0, "NaN"]', "true"], "truth": ["null", "2.5"]}))
      value_decoded truth_decoded
    0    [1.0, nan]          None
    1          True           2.5
    """
    return pd.DataFrame({name: _decoded(frame[text]) for text, name in DECODED.items()
                         if text in frame}, index=frame.index)


def _decoded(texts: pd.Series) -> pd.Series:
    """Each text's value, an object column (None stays None: no value is not NaN)."""
    codes, distinct = pd.factorize(texts, use_na_sentinel=False)
    values = [decode(text) for text in distinct]
    return pd.Series([values[code] for code in codes], index=texts.index, dtype=object)


@dataclass(eq=False)
class Run:
    """A run folder: its info (``run.json``, migrated to the current format), its typed cases
    (by id, in suite order), its results table (:attr:`results`), the format version its
    run.json was written in, and the repro scripts it holds."""

    directory: Path
    info: RunInfo
    cases: dict[str, AnyCase]
    format_version: int = FORMAT_VERSION
    """The format of ``run.json`` as written (:mod:`crosscheck.results.runinfo`'s history)."""

    @functools.cached_property
    def rows(self) -> pd.DataFrame:
        """The rows of ``results.jsonl`` in :data:`~crosscheck.core.model.COLUMNS`, values in
        the current format, in suite, engine and quantity order; parsed once per object."""
        return _rows(self.directory, list(self.cases), self.info.engine_names)

    @functools.cached_property
    def results(self) -> pd.DataFrame:
        """The results table (``results.csv``): :attr:`rows` with the timing phase's medians,
        the instruction counts and the repeat check's columns joined; read from the stored
        columns (:func:`crosscheck.results.stored.read_results`) when they are up to date and
        the rows were not parsed already."""
        if "rows" not in self.__dict__:
            kept = stored.read_results(self.directory)
            if kept is not None:
                self.__dict__["_from_stored"] = True
                return kept
        return _joined(self.rows.copy(), self.directory)

    @property
    def from_stored(self) -> bool:
        """Whether :attr:`results` came from the up-to-date stored columns (the files written
        from them need no rewrite)."""
        return bool(self.__dict__.get("_from_stored", False))

    @functools.cached_property
    def decoded(self) -> pd.DataFrame:
        """The values of the ``value`` and ``truth`` columns (:func:`decoded`), in the results'
        order and index, decoded once per run."""
        return decoded(self.results)

    @property
    def repros(self) -> set[str]:
        """The file names of the repro scripts in the run folder
        (:func:`~crosscheck.results.store.written_repros`)."""
        return written_repros(self.directory)

    def refresh(self) -> None:
        """After a phase appended to the side files and wrote run.json: read run.json again and
        join the side files again (the rows, written before, are not parsed again)."""
        data = _run_json(self.directory)
        self.info, self.format_version = _info(self.directory, data), int(data["format_version"])
        self.__dict__.pop("results", None)  # its value and truth texts, so decoded, stay
        self.__dict__.pop("_from_stored", None)

    def with_results(self, results: pd.DataFrame, values: pd.DataFrame | None = None) -> Run:
        """This run with another results table (some of its rows, other columns: a what-if;
        or the same rows in other dtypes), with ``values`` as its decoded values when given
        (:attr:`decoded` of the same rows, in their index)."""
        run = replace(self)
        run.__dict__["results"] = results
        if values is not None:
            run.__dict__["decoded"] = values
        return run


def read_run(directory: Path) -> Run:
    """Everything a report, compare, stability study or resume needs from a run folder."""
    data = _run_json(directory)
    info = _info(directory, data)
    return Run(directory, info, read_cases(directory),
               int(data["format_version"]))  # an int: else RunInfo refused it


def read_results(directory: Path) -> pd.DataFrame:
    """The results table of a run folder (:attr:`Run.results`) without validating its cases:
    for the readers that need no more (``check``, ``compare``'s changes); from the stored
    columns when they are up to date."""
    kept = stored.read_results(directory)
    if kept is not None:
        return kept
    case_ids = [str(case["id"]) for case in jsonlines.parse_lines(directory / "cases.jsonl")]
    engines = ([e["name"] for e in _run_json(directory).get("engines", [])]
               if (directory / "run.json").exists() else [])
    return _joined(_rows(directory, case_ids, engines), directory)


def read_cases(directory: Path) -> dict[str, AnyCase]:
    """The stored cases of a run, typed as when they ran, by id, in suite order."""
    return {str(case["id"]): CASE_ADAPTER.validate_python(legacy.case_fields(case))
            for case in jsonlines.parse_lines(directory / "cases.jsonl")}


def read_run_info(directory: Path) -> RunInfo:
    """``run.json`` of a run, of any format version this harness has written."""
    return _info(directory, _run_json(directory))


def _rows(directory: Path, case_ids: list[str], engine_names: list[str]) -> pd.DataFrame:
    """``results.jsonl`` as a frame in COLUMNS order, sorted by case (in ``case_ids``' order),
    engine (``engine_names``') and quantity, so the order depends neither on ``--jobs`` nor
    on resuming."""
    rows = [legacy.record_fields(row)
            for row in jsonlines.parse_lines(directory / "results.jsonl")]
    frame = pd.DataFrame(jsonlines.by_column(rows, COLUMNS), columns=list(COLUMNS))
    if not rows:
        return frame
    frame = frame.astype({"dim": "int64", "loops": "int64"})
    for column in ("value", "truth"):  # formats 1-3 wrote "", undefined and bare NaN
        frame[column] = jsonlines.each_distinct(frame[column], upgrade)
    case_rank = {case_id: i for i, case_id in enumerate(case_ids)}
    engine_rank = {name: i for i, name in enumerate(engine_names)}
    keys = pd.DataFrame({
        "case": frame["case_id"].map(case_rank).fillna(len(case_rank)),
        "engine": frame["engine"].map(engine_rank).fillna(len(engine_rank)),
        "quantity": jsonlines.each_distinct(frame["kind"] + "\x00" + frame["quantity"],
                                            _rank).to_numpy(),
    })
    order = keys.sort_values(["case", "engine", "quantity"], kind="stable").index
    return frame.loc[order].reset_index(drop=True)


def _joined(frame: pd.DataFrame, directory: Path) -> pd.DataFrame:
    """The rows with the side files joined: timings, counts, then the repeat columns
    (:func:`~crosscheck.results.repeats.with_repeats`)."""
    if len(frame):
        frame = _with_timings(frame, read_timings(directory))
    return repeats.with_repeats(counts.with_counts(frame, directory), directory)


def _rank(kind_quantity: str) -> int:
    """The place of a quantity among its kind's (``kind NUL quantity``)."""
    kind, quantity = kind_quantity.split("\x00")
    return quantities_of(Kind(kind)).index(quantity)


def _with_timings(frame: pd.DataFrame, timings: pd.DataFrame) -> pd.DataFrame:
    """The rows' timing columns filled from the timing phase's samples, where it timed them."""
    if timings.empty:
        return frame
    timed = timings.set_index(["case_id", "engine"])
    keys = pd.MultiIndex.from_frame(frame[["case_id", "engine"]])
    found = keys.isin(timed.index)
    if not found.any():
        return frame
    rows = timed.reindex(keys[found])
    frame.loc[found, "query_s"] = rows["median_s"].to_numpy()
    frame.loc[found, "query_iqr_s"] = rows["iqr_s"].to_numpy()
    frame.loc[found, "loops"] = rows["loops"].to_numpy().astype("int64")
    frame.loc[found, "unstable"] = rows["unstable"].to_numpy().astype(bool)
    return frame


def _run_json(directory: Path) -> dict[str, Any]:
    """``run.json`` as written (the one place that parses it)."""
    path = directory / "run.json"
    try:
        data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise StoreError(f"{path} does not exist: not a run folder, or a run killed before "
                         "it started") from None
    except json.JSONDecodeError as exc:
        raise StoreError(f"{path}: {exc}") from exc
    return data


def _info(directory: Path, data: dict[str, Any]) -> RunInfo:
    try:
        return RunInfo.from_json(data)
    except (KeyError, TypeError, FormatError) as exc:
        raise StoreError(f"{directory / 'run.json'}: {exc}") from exc
