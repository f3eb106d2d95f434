"""``run.json``: the typed metadata of one run, with its format history and migrations.

Format history (in the manner of pyperf's ``_JSON_VERSION`` list and asv's
``update_to_N`` steps); every version this harness has written can be read:

- **1** (up to the layered architecture): a free dict built by hand in three
  places; ``options`` held ``timed_ids`` (the timing sample, always ``null``
  when written), ``resumed`` was present only after a resume.
- **2**: the typed :class:`RunInfo`; ``options`` are :class:`RunOptions`
  without ``timed_ids`` (which cases are timed is the runner's per-case
  choice, not an option), and ``resumed`` is always a list.  Every results
  row and stored case carries ``origin``, ``coords`` and ``twin_of`` (format
  1 had them only inside the case id; :mod:`crosscheck.results.legacy` reads
  them back from there), and ``error_at_contact`` (NaN in format 1: responses
  were judged at the engine's contact instead, category ``timestep`` did not exist).
- **3**: a timing phase after the verdicts: every sample in ``timings.jsonl``,
  the results rows' timing columns filled from it, and ``timing`` here (the
  sampling method, pinning, the machine yardstick at the start and the end,
  each engine's binding overhead).  Options ``timing_cases``, ``timing_seed``,
  ``scene_repeats`` and ``pin`` replace ``time_per_group``.
- **4**: the ``value`` and ``truth`` columns are strict JSON
  (:mod:`crosscheck.core.values`): ``null`` for no value (formats 1-3: ``""``
  or the bare token ``undefined``), and a number that is not finite as the
  string ``"NaN"``, ``"Infinity"`` or ``"-Infinity"`` (formats 1-3: the bare
  tokens, which strict JSON rejects).  ``read_results`` upgrades older rows
  as it reads them; run.json itself is unchanged.
- **5**: the repeat check (``crosscheck run --repeat-check``): ``repeats.jsonl`` holds the
  second answer of every re-asked pair (:mod:`crosscheck.results.repeats`), the results
  gain the columns ``nondeterministic``, ``repeat_value`` and ``repeat_status`` (on a run of
  an earlier format: False, None and ``""``, "not asked again"), the options gain
  ``repeat_check`` (False), and ``repeat_check`` here sums the check up (None: not run).
- **6**: the timing phase in interleaved rounds: each line of ``timings.jsonl`` keeps
  its round's yardstick per sample (``yardstick``; lines without it read as not
  normalised) and ``timing`` here gains ``rounds`` (the round yardsticks and their drift);
  the instruction timer (``--timer instructions``): the options gain ``timer``
  (``"wall"``), ``counts.jsonl`` holds the raw counts (:mod:`crosscheck.results.counts`),
  the results gain ``query_instructions`` and ``engine_instructions`` (empty on a run of an
  earlier format), and ``timing`` here gains ``cost`` (how the counting went).  Nothing in
  run.json changes shape: the update only stamps the version.
- **7**: ``scene_facts.jsonl`` holds what each scene case's exact run showed that the report
  needs (its impacts on a step boundary, :mod:`crosscheck.results.scene_facts`), so a report
  no longer runs the exact reference; a run of an earlier format has no such file, and the
  report recomputes the facts of each scene case from its stored case (the same page).
  Nothing in run.json changes shape: the update only stamps the version.

Within format 7, each engine's entry gained ``claims``, its published accuracy claims
(:mod:`crosscheck.core.claims`): additive, so the version is unchanged, and an entry without
them (a run written before) reads as an engine that claims nothing (:func:`claims_of`).

A run.json of a later format (a newer crosscheck wrote it) is refused by
:func:`migrate` with its version and how to upgrade; ``tests/data/format3-run`` and
``tests/data/format4-run`` are stored runs of formats 3 and 4 that ``report``, ``compare``
and ``advise`` must keep reading.

>>> info = RunInfo(run_id="r", command="crosscheck run", options=RunOptions(quick=True),
...                machine={}, engines=(), started="2026-01-01T00:00:00+00:00")
>>> RunInfo.from_json(info.to_json()) == info
True
>>> RunInfo.from_json({"format_version": 1, "run_id": "old", "command": "c", "started": "s",
...     "finished": None, "options": {"quick": True, "timed_ids": None}, "machine": {},
...     "engines": [], "case_files": [], "cases_run": 0, "case_errors": []}).options.quick
True
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from typing import Any

from crosscheck.cases.tiers import tier_of
from crosscheck.core.claims import Claim
from crosscheck.core.options import RunOptions

FORMAT_VERSION = 7
"""The version of run.json (and of the files beside it) that this harness writes."""


class FormatError(ValueError):
    """run.json is of a format this harness cannot read."""


def now() -> str:
    """The current time as ISO 8601 UTC, to the second (run.json's time stamps)."""
    return datetime.now(UTC).isoformat(timespec="seconds")


@dataclass(frozen=True)
class RunInfo:
    """Everything a run records about itself, beside its results."""

    run_id: str
    command: str
    options: RunOptions
    machine: dict[str, Any]
    """CPU, cores, Python, package versions, git commit (see crosscheck.run.environment)."""
    engines: tuple[dict[str, Any], ...]
    """Per engine: name, engine, version, settings, capabilities, conventions, and ``claims``
    (its published accuracy claims as :meth:`~crosscheck.core.claims.Claim.to_json` wrote
    them; absent in a run written before claims were recorded: none)."""
    started: str
    finished: str | None = None
    case_files: tuple[str, ...] = ()
    cases_run: int = 0
    case_errors: tuple[str, ...] = ()
    resumed: tuple[str, ...] = field(default=())
    """When the run was resumed, oldest first."""
    timing: dict[str, Any] | None = None
    """The timing phase (format 3; None: no timing phase): ``method`` (in words), ``sampled``
    (pairs timed), ``pinned``, ``failed`` (pairs that crashed or hung), ``yardstick``
    (``start`` and ``end``: per workload, the median, quartiles and samples), ``rounds``
    (format 6: ``count`` of rounds, ``yardstick_s``, each round's yardstick in seconds, None
    where none was read, and ``drift``, the largest over the smallest of them, None: none),
    ``binding`` (per engine: the cheapest call into its binding, or why there is none), and
    ``cost`` (format 6, ``--timer instructions`` only: how the instructions were counted,
    :func:`crosscheck.run.cost.cost_phase`: ``timer``, ``method``, ``valgrind``, ``calls``,
    ``warmups``, ``sampled``, ``counted``, ``failed``, ``failures`` (the first, with their
    reasons), ``parallel`` and ``wall_s``; or ``timer`` and ``none``, why nothing was
    counted)."""
    repeat_check: dict[str, Any] | None = None
    """The repeat check (format 5; None: not run): ``pairs`` asked again, ``nondeterministic``
    (those whose answer changed), ``seconds`` it took (summed over a resumed run's parts),
    ``scenes`` (whether scene pairs were asked: the deep tier only; absent before)."""

    @property
    def tier(self) -> str:
        """The suite's tier the run holds (:func:`crosscheck.cases.tiers.tier_of`)."""
        return tier_of(self.case_files)

    @property
    def engine_names(self) -> list[str]:
        """The engines of the run, in run order."""
        return [str(e["name"]) for e in self.engines]

    @property
    def claims(self) -> dict[str, tuple[Claim, ...]]:
        """Each engine's recorded claims, by name in run order (none for an engine whose
        entry has no ``claims``: a run written before they were recorded)."""
        return {str(e["name"]): claims_of(e) for e in self.engines}

    def finish(self) -> RunInfo:
        """This info, finished now."""
        return replace(self, finished=now())

    def resume(self) -> RunInfo:
        """This info, resumed now (and not finished)."""
        return replace(self, finished=None, resumed=(*self.resumed, now()))

    def to_json(self) -> dict[str, Any]:
        """run.json's content, format version first."""
        return {"format_version": FORMAT_VERSION, "run_id": self.run_id, "command": self.command,
                "started": self.started, "finished": self.finished,
                "resumed": list(self.resumed), "options": self.options.to_json(),
                "machine": self.machine, "engines": list(self.engines),
                "case_files": list(self.case_files), "tier": self.tier,
                "cases_run": self.cases_run,
                "case_errors": list(self.case_errors), "timing": self.timing,
                "repeat_check": self.repeat_check}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RunInfo:
        """Read run.json's content of any known format version (older ones are migrated)."""
        data = migrate(data)
        return cls(run_id=data["run_id"], command=data["command"],
                   options=RunOptions.from_json(data["options"]), machine=data["machine"],
                   engines=tuple(data["engines"]), started=data["started"],
                   finished=data["finished"], case_files=tuple(data["case_files"]),
                   cases_run=int(data["cases_run"]), case_errors=tuple(data["case_errors"]),
                   resumed=tuple(data["resumed"]), timing=data.get("timing"),
                   repeat_check=data.get("repeat_check"))


def claims_of(engine: dict[str, Any]) -> tuple[Claim, ...]:
    """The claims an engine's entry in run.json records (none when it has no ``claims``).

    >>> claims_of({"name": "old"})
    ()
    """
    return tuple(Claim.from_json(c) for c in engine.get("claims") or ())


def _update_to_2(data: dict[str, Any]) -> dict[str, Any]:
    options = {k: v for k, v in data.get("options", {}).items() if k != "timed_ids"}
    return {**data, "options": options, "resumed": data.get("resumed", []),
            "format_version": 2}


def _update_to_3(data: dict[str, Any]) -> dict[str, Any]:
    return {**data, "timing": None, "format_version": 3}


def _update_to_4(data: dict[str, Any]) -> dict[str, Any]:
    return {**data, "format_version": 4}  # the results rows are upgraded as they are read


def _update_to_5(data: dict[str, Any]) -> dict[str, Any]:
    return {**data, "repeat_check": None, "format_version": 5}  # no repeats.jsonl: not asked


def _update_to_6(data: dict[str, Any]) -> dict[str, Any]:
    return {**data, "format_version": 6}  # no rounds, no counts: the readers' defaults


def _update_to_7(data: dict[str, Any]) -> dict[str, Any]:
    return {**data, "format_version": 7}  # no scene_facts.jsonl: the report recomputes them


_UPDATES: dict[int, Callable[[dict[str, Any]], dict[str, Any]]] = {
    1: _update_to_2, 2: _update_to_3, 3: _update_to_4, 4: _update_to_5, 5: _update_to_6,
    6: _update_to_7}
"""Version N -> a function that turns a version-N run.json into version N + 1."""


def migrate(data: dict[str, Any]) -> dict[str, Any]:
    """run.json's content brought to :data:`FORMAT_VERSION`, one step at a time."""
    version = data.get("format_version")
    while version != FORMAT_VERSION:
        readable = f"this harness reads formats {', '.join(map(str, [*_UPDATES, FORMAT_VERSION]))}"
        if isinstance(version, int) and version > FORMAT_VERSION:
            raise FormatError(f"run.json has format {version}; {readable}; a newer crosscheck "
                              "wrote it: upgrade crosscheck (git pull, then pip install -e .) "
                              "to read it")
        if not isinstance(version, int) or version not in _UPDATES:
            raise FormatError(f"run.json has format {version!r}; {readable}")
        data = _UPDATES[version](data)
        version = data["format_version"]
    return data
