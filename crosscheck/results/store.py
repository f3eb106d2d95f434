"""The results store of one run: a directory joined to the report by versioned files.

``reports/<run-id>/`` holds:

- ``results.jsonl``: one Record per line, appended and flushed as each
  case finishes, so a killed run keeps everything it finished;
- ``cases.jsonl``: the validated inputs of every case of the run, in suite
  order (the report shows them; ``--resume`` runs exactly these);
- ``run.json``: a :class:`~crosscheck.results.runinfo.RunInfo` (format
  version, machine, versions, engines and their conventions, options, start
  and end times);
- ``results.csv``: the tidy table, written from ``results.jsonl`` (with the timing
  phase's medians and the repeat check's second answers, :mod:`crosscheck.results.repeats`);
- ``timings.jsonl`` and ``counts.jsonl``: the timing phase's wall-clock samples
  (:mod:`crosscheck.results.timings`) and the instruction timer's raw counts
  (:mod:`crosscheck.results.counts`), joined to the results' timing columns when read;
- ``series.jsonl``: each recorded scene's relative energy against time, per engine and for
  the exact reference (:mod:`crosscheck.results.series`), appended with the case's rows;
- ``scene_facts.jsonl``: what each scene case's exact run showed that the report needs (its
  impacts on a step boundary; :mod:`crosscheck.results.scene_facts`), appended with the
  case's rows;
- ``repro/``: a standalone script per breaking case x engine (:func:`repro_name`), only
  once ``crosscheck repro RUN --all`` wrote them (:mod:`crosscheck.studies.repro`; a run
  writes none: every script is printed on demand); :func:`written_repros` says which are
  there.

Running writes these; reading them back is :mod:`crosscheck.results.run` (a
:class:`~crosscheck.results.run.Run`: the folder as an object, for the report and for the
phases after the verdicts).
Every row of ``results.jsonl`` is written as :mod:`crosscheck.results.rows` defines it.

A write that fails (a full disk: ENOSPC, a quota) raises :class:`StoreError`
saying so; the rows written before it stay loadable (a half-written last line
is skipped by every reader and dropped by ``--resume``), and the run can be
resumed once there is space.  ``cases.jsonl`` is written before ``run.json``,
so a folder with a run.json always has the cases to resume.

"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
from collections.abc import Iterable
from pathlib import Path
from typing import IO

import pandas as pd

from crosscheck.core.model import Kind, Record, quantities_of
from crosscheck.core.schema import AnyCase
from crosscheck.results import counts, jsonlines, repeats, scene_facts, series
from crosscheck.results.rows import line
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.timings import FILE as TIMINGS
from crosscheck.results.timings import TimingRecord, read_timings

LOCK = ".lock"
"""The file a run holds locked while it writes the folder; removed when the run closes."""


class StoreError(RuntimeError):
    """The results directory cannot be used."""


def open_append(path: Path) -> IO[str]:
    """The results file, opened to append (the one place the store opens it: tests can
    replace it with a writer that fails, as a full disk does)."""
    return path.open("a", encoding="utf-8")


class ResultsStore:
    """Append-only writer for one run directory.

    A new run refuses a directory that already holds results; ``resume=True``
    keeps the rows of every finished case x engine (all its quantities
    present), drops the rest (a half-written line, a pair cut short) and
    appends after them.  ``done`` is the set of finished (case id, engine); ``repeated``
    those the repeat check has asked again.
    """

    def __init__(self, directory: Path, *, resume: bool = False) -> None:
        self.directory = directory
        _check_writable(directory)
        self._lock = _lock(directory)
        results = directory / "results.jsonl"
        if not resume and results.exists() and results.stat().st_size:
            self._lock.close()
            raise StoreError(f"{directory} already holds results: resume it with "
                             f"'crosscheck run --resume {directory}' or choose another --out")
        self.done: set[tuple[str, str]] = _keep_finished(results) if resume else set()
        self._results: IO[str] = open_append(results)
        if resume:  # drop a half-written last line, so that appends start on a line of their own
            _replace_if_exists(directory / TIMINGS)
            _replace_if_exists(directory / repeats.FILE)
            _replace_if_exists(directory / counts.FILE)
            _replace_if_exists(directory / series.FILE)
            _replace_if_exists(directory / scene_facts.FILE)
        self.repeated: set[tuple[str, str]] = set(repeats.read_repeats(directory) if resume else ())
        timings = read_timings(directory) if resume else None
        self.timed: set[tuple[str, str]] = (
            set(zip(timings["case_id"], timings["engine"], strict=True))
            if timings is not None else set())
        """The (case id, engine) pairs the timing phase has already measured."""
        self.counted = counts.counted_pairs(directory) if resume else set()
        """The (case id, engine) pairs the instruction timer has already counted."""

    def add_cases(self, cases: Iterable[AnyCase]) -> None:
        """Record the inputs of every case of the run, in suite order (replacing any): once
        per run, before ``run.json`` (:func:`crosscheck.run.launch.launch`)."""
        lines = [json.dumps(case.model_dump() | {"source": case.source}) for case in cases]
        _replace(self.directory / "cases.jsonl", lines)

    def append(self, records: Iterable[Record]) -> None:
        """Append finished records in one write and flush them to disk.

        Raises :class:`StoreError` if the write fails (a full disk); what was
        written before stays readable, and ``--resume`` drops any half-written line.
        """
        self.append_lines("".join(map(line, records)))

    def append_lines(self, text: str) -> None:
        """Append finished rows already written as JSON lines (each ending in a newline, as
        :mod:`crosscheck.results.rows` writes them: columnar scoring makes them from columns)
        and flush."""
        try:
            self._results.write(text)
            self._results.flush()
        except OSError as exc:
            raise StoreError(f"cannot write results to {self.directory / 'results.jsonl'}: "
                             f"{exc.strerror or exc}") from exc

    def append_timing(self, record: TimingRecord) -> None:
        """Append one case x engine's timing samples to ``timings.jsonl`` and flush."""
        with (self.directory / TIMINGS).open("a", encoding="utf-8") as handle:
            handle.write(record.to_json() + "\n")
        self.timed.add((record.case_id, record.engine))

    def append_count(self, record: counts.CountRecord) -> None:
        """Append one case x engine's instruction counts to ``counts.jsonl`` and flush."""
        with (self.directory / counts.FILE).open("a", encoding="utf-8") as handle:
            handle.write(record.to_json() + "\n")
        self.counted.add((record.case_id, record.engine))

    def append_series(self, records: Iterable[series.SeriesRecord]) -> None:
        """Append scene energy series to ``series.jsonl``."""
        self._append_records(series.FILE, (record.to_json() for record in records))

    def append_scene_facts(self, records: Iterable[scene_facts.SceneFacts]) -> None:
        """Append scene cases' facts to ``scene_facts.jsonl``."""
        self._append_records(scene_facts.FILE, (record.to_json() for record in records))

    def _append_records(self, name: str, lines: Iterable[str]) -> None:
        """Append JSON lines to the file ``name`` of the run folder in one write and flush
        (nothing to write: the file is not touched)."""
        text = "".join(line + "\n" for line in lines)
        if not text:
            return
        try:
            with (self.directory / name).open("a", encoding="utf-8") as handle:
                handle.write(text)
        except OSError as exc:
            raise StoreError(f"cannot write {self.directory / name}: "
                             f"{exc.strerror or exc}") from exc

    def append_repeat(self, record: repeats.RepeatRecord) -> None:
        """Append one pair's second answer to ``repeats.jsonl`` and flush."""
        with (self.directory / repeats.FILE).open("a", encoding="utf-8") as handle:
            handle.write(record.to_json() + "\n")
        self.repeated.add((record.case_id, record.engine))

    def write_run_info(self, info: RunInfo) -> None:
        """Write ``run.json`` (replacing any previous one)."""
        _replace(self.directory / "run.json", [json.dumps(info.to_json(), indent=2)])

    def close(self) -> None:
        """Close the results file and release the folder (also after a failed write)."""
        try:
            self._results.close()
        except OSError:
            pass  # the write that failed has raised already; its rows were never on disk
        finally:
            _release(self.directory, self._lock)


def _lock(directory: Path) -> IO[str]:
    """Hold ``directory/.lock`` for this run; a second run into the directory is refused.

    A run that finishes removes the file while it still holds it (:func:`_release`), so a
    lock taken on a file that is no longer at that path is taken again on the new one.
    """
    path = directory / LOCK
    while True:
        handle = path.open("a+", encoding="utf-8")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            holder = handle.read().strip() or "another process"
            handle.close()
            raise StoreError(f"another crosscheck run ({holder}) is writing to {directory}; "
                             "wait for it or choose another --out") from None
        if _same_file(handle, path):
            break
        handle.close()  # the run that held it finished and removed it: lock the new one
    handle.truncate(0)
    handle.write(f"pid {os.getpid()}")
    handle.flush()
    return handle


def _same_file(handle: IO[str], path: Path) -> bool:
    try:
        return os.fstat(handle.fileno()).st_ino == path.stat().st_ino
    except FileNotFoundError:
        return False


def _release(directory: Path, handle: IO[str]) -> None:
    """Remove ``directory/.lock`` while holding it, then release it: a closed run leaves no
    lock file behind."""
    try:
        (directory / LOCK).unlink(missing_ok=True)
    except OSError:
        pass  # a read-only or vanished folder: the lock is released all the same
    finally:
        handle.close()


def _check_writable(directory: Path) -> None:
    try:
        directory.mkdir(parents=True, exist_ok=True)
        probe = directory / ".write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise StoreError(f"cannot write results to {directory}: {exc}") from exc


def _replace(path: Path, lines: list[str]) -> None:
    """Write ``lines`` to ``path`` atomically (a reader never sees half a file)."""
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text("".join(line + "\n" for line in lines), encoding="utf-8")
    os.replace(tmp, path)


def _replace_if_exists(path: Path) -> None:
    if path.exists():
        _replace(path, [text for text, _ in jsonlines.read_lines(path)])


def _keep_finished(path: Path) -> set[tuple[str, str]]:
    """Keep only the rows of finished case x engine pairs, as they were written; return
    those pairs."""
    lines = jsonlines.read_lines(path)
    seen: dict[tuple[str, str], set[str]] = {}
    for _, row in lines:
        seen.setdefault((row["case_id"], row["engine"]), set()).add(row["quantity"])
    kinds = {(row["case_id"], row["engine"]): row["kind"] for _, row in lines}
    done = {pair for pair, qs in seen.items() if qs == set(quantities_of(Kind(kinds[pair])))}
    _replace(path, [text for text, row in lines if (row["case_id"], row["engine"]) in done])
    return done


REPRO_DIR = "repro"
"""The folder of a run's repro scripts, beside report.html."""


def repro_path(directory: Path, case_id: str, engine: str) -> Path:
    """Where the repro script of ``case_id`` on ``engine`` goes in a run folder."""
    return directory / REPRO_DIR / f"{repro_name(case_id, engine)}.py"


def written_repros(directory: Path) -> set[str]:
    """The file names of the repro scripts in a run folder (``repro/*.py``)."""
    folder = directory / REPRO_DIR
    return {p.name for p in folder.glob("*.py")} if folder.is_dir() else set()


def repro_name(case_id: str, engine: str) -> str:
    """The file name (without ``.py``) of the repro script of ``case_id`` on ``engine``.

    Safe on every file system and in a URL path: lowercase letters, digits, '.',
    '-', '~' and the one '_' that joins the case and the engine.  Any other
    character (of the case id, e.g. a sweep's '=', ',', '+' or '_', or of the engine)
    becomes '~' and its UTF-8 bytes in hex, so different pairs never share a name.
    A name over 200 characters is cut to 182 and ends in '__' and a hash of the pair
    (two '_' more: it cannot be the name of a shorter pair).

    >>> repro_name("sphere-gap.gap=0.001,offset=1e+15", "pybullet-default")
    'sphere-gap.gap~3d0.001~2coffset~3d1e~2b15_pybullet-default'
    """
    safe = frozenset("abcdefghijklmnopqrstuvwxyz0123456789.-")

    def escaped(text: str) -> str:
        return "".join(c if c in safe else "".join(f"~{b:02x}" for b in c.encode())
                       for c in text)

    name = f"{escaped(case_id)}_{escaped(engine)}"
    if len(name) > 200:
        digest = hashlib.sha256(f"{case_id}\n{engine}".encode()).hexdigest()[:16]
        name = f"{name[:182]}__{digest}"
    return name


def write_csv(frame: pd.DataFrame, directory: Path) -> Path:
    """Write ``results.csv`` from a results DataFrame."""
    path = directory / "results.csv"
    frame.to_csv(path, index=False)
    return path
