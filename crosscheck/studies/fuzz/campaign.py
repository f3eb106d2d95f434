"""The fuzz study: cases near engine failure boundaries, run in chunks, findings grouped.

A fuzz campaign of ``n`` cases is cut into chunks of
:data:`~crosscheck.studies.fuzz.generator.CHUNK` (chunk ``k`` generated from ``(seed, k)``
alone).  Lane processes (:mod:`crosscheck.studies.fuzz.lanes`) generate, run and
score whole chunks; each finished chunk is written at once, atomically, to
``DIR/chunks/cNNNNNN.json.gz``: its status counts per engine x quantity x status
x category, its finding rows (disagree, error, crash, timeout) and the inputs of
the cases that have findings.  Nothing else is kept: agreeing rows are counted,
not stored, so memory and disk stay flat in ``n``.

``DIR/campaign.json`` holds the plan (kind, n, seed, engines, options, command);
a killed campaign (even by SIGKILL) is finished by :func:`resume`, which skips
the chunks already on disk and regenerates exactly the others.  When every
chunk is in, the findings are grouped and written as ready-to-commit case files
by :mod:`crosscheck.studies.fuzz.findings` (``DIR/findings.csv`` lists every one), the
first ``shrink`` representatives of each group shrunk beside them
(:mod:`crosscheck.studies.fuzz.shrink`), and ``DIR/fuzz.json`` gives the counts, the
timings (cases per second overall and per engine), resident memory sampled along the way
and what the shrinking took.  ``crosscheck fuzz`` is its command;
:func:`campaign_throughput` is the bench's figure.
"""

from __future__ import annotations

import gzip
import json
import multiprocessing as mp
import os
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Kind
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, json_schema_text
from crosscheck.results.runinfo import now
from crosscheck.run import environment
from crosscheck.run.execute import Executor
from crosscheck.run.lanes import LocalLanes
from crosscheck.run.processes import resident_mb
from crosscheck.studies.fuzz import generator
from crosscheck.studies.fuzz.findings import (
    FINDING_COLUMNS,
    SHRUNK_SUFFIX,
    Group,
    Row,
    Shrinker,
    Signature,
    as_list,
    finding_text,
    from_list,
    write_stream,
)
from crosscheck.studies.fuzz.lanes import Block, Plan, run_chunks
from crosscheck.studies.fuzz.shrink import MAX_CALLS, Shrunk, shrink_case

Progress = Callable[[int], None]
PLAN = "campaign.json"
CHUNKS = "chunks"
MEMORY_SAMPLES = 200
"""fuzz.json keeps at most about this many resident-memory samples (every k-th chunk)."""
SHRINK = 1
"""Representatives shrunk per group by default: the first (the largest error)."""
SHRUNK_TAG = "shrunk"
"""The tag of a shrunk case (its id is its original's and ``-shrunk``)."""


class CampaignError(RuntimeError):
    """A campaign folder cannot be used (not empty, not a campaign, already finished)."""


def _chunk_path(directory: Path, chunk: int, part: str = "") -> Path:
    return directory / CHUNKS / f"c{chunk:06d}{part}.json.gz"


def _dump(path: Path, data: dict[str, Any]) -> None:
    tmp = path.with_suffix(".tmp")
    with gzip.open(tmp, "wt", encoding="utf-8", compresslevel=1) as handle:
        json.dump(data, handle, separators=(",", ":"))
    os.replace(tmp, path)


def _load(path: Path) -> dict[str, Any]:
    with gzip.open(path, "rt", encoding="utf-8") as handle:
        data: dict[str, Any] = json.load(handle)
    return data


def write_chunk(directory: Path, chunk: int, cases: int, blocks: Sequence[Block]) -> None:
    """One finished chunk, atomically: ``cNNNNNN.json.gz`` (counts, seconds per engine and
    the findings as lists in ``FINDING_COLUMNS`` order), written last, after
    ``cNNNNNN.inputs.json.gz`` (the inputs of the cases with findings)."""
    _dump(_chunk_path(directory, chunk, ".inputs"),
          {cid: case for b in blocks for cid, case in b.cases.items()})
    _dump(_chunk_path(directory, chunk),
          {"chunk": chunk, "cases": cases, "counts": dict(sum((b.counts for b in blocks),
                                                              Counter())),
           "seconds": {b.engine: b.seconds for b in blocks}, "columns": FINDING_COLUMNS,
           "findings": [as_list(row) for b in blocks for row in b.findings]})


def read_chunk(directory: Path, chunk: int) -> dict[str, Any]:
    """A finished chunk's data (see :func:`write_chunk`), findings as rows."""
    data = _load(_chunk_path(directory, chunk))
    data["findings"] = [from_list(values) for values in data["findings"]]
    return data


def finished_chunks(directory: Path) -> set[int]:
    """The chunks already on disk (a ``.tmp`` left by a kill is not one)."""
    return {int(p.name[1:7]) for p in (directory / CHUNKS).glob("c??????.json.gz")}


@dataclass
class Tally:
    """What the parent keeps while chunks come in: counts, seconds, memory samples."""

    counts: Counter[str] = field(default_factory=Counter)
    seconds: Counter[str] = field(default_factory=Counter)
    memory: list[dict[str, float]] = field(default_factory=list)
    stride: int = 1
    done: int = 0
    cases: int = 0

    def add(self, counts: dict[str, int], seconds: dict[str, float]) -> None:
        self.counts.update(counts)
        self.seconds.update(seconds)

    def sample(self, start: float) -> None:
        """Resident memory of this process and of its lanes, every ``stride``-th chunk."""
        self.done += 1
        if self.done % self.stride:
            return
        pids = [p.pid or 0 for p in mp.active_children()]
        self.memory.append({"chunks": self.done, "s": round(time.perf_counter() - start, 2),
                            "parent_mb": round(resident_mb([os.getpid()]), 1),
                            "lanes_mb": round(resident_mb(pids), 1)})
        if len(self.memory) >= MEMORY_SAMPLES:
            self.memory, self.stride = self.memory[::2], self.stride * 2


@dataclass(frozen=True)
class Writing:
    """How a campaign writes its findings: representatives per group, and how many of them
    to shrink (0: none)."""

    per_group: int = 5
    shrink: int = SHRINK


def _plan_json(plan: Plan, command: str, writing: Writing) -> dict[str, Any]:
    return {"kind": plan.kind.value, "n": plan.n, "seed": plan.seed,
            "engines": [cls().name for cls in plan.engines], "per_group": writing.per_group,
            "shrink": writing.shrink, "options": plan.options.to_json(), "command": command,
            "chunk": generator.CHUNK,
            "bias": [[kind, dim, [list(item) for item in cell]] for kind, dim, cell in plan.bias]}


def stored_bias(saved: list[Any]) -> generator.Bias:
    """A stored bias back as tuples (an old plan has none)."""
    return tuple((str(kind), int(dim), tuple((str(n), str(v)) for n, v in cell))
                 for kind, dim, cell in saved)


def fuzz(kind: Kind, n: int, seed: int, directory: Path, engines: Sequence[Adapter],
         options: RunOptions, per_group: int = 5, command: str = "",
         progress: Progress | None = None, shrink: int = SHRINK,
         bias: generator.Bias = ()) -> list[Group]:
    """Start a campaign into the empty (or new) ``directory``; run it; write its findings,
    the first ``shrink`` representatives of each group shrunk; ``bias``: failing cells the
    configuration-space family starts from (:mod:`crosscheck.studies.fuzz.bias`)."""
    if directory.exists() and any(directory.iterdir()):
        raise CampaignError(f"{directory} is not empty; choose another --out, empty it, or "
                            f"finish a killed campaign with --resume {directory}")
    command = command or f"crosscheck fuzz --kind {kind.value} --n {n} --seed {seed}"
    plan = Plan(kind, n, seed, tuple(type(a) for a in engines), options, bias)
    writing = Writing(per_group, shrink)
    (directory / CHUNKS).mkdir(parents=True)
    (directory / PLAN).write_text(json.dumps(_plan_json(plan, command, writing), indent=2)
                                  + "\n", encoding="utf-8")
    return _campaign(directory, plan, command, writing, progress)


def stored_plan(directory: Path) -> dict[str, Any]:
    """The plan of the campaign in ``directory`` (``campaign.json``), checked."""
    try:
        saved: dict[str, Any] = json.loads((directory / PLAN).read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise CampaignError(f"{directory} is not a fuzz campaign ({directory / PLAN}: "
                            f"{exc})") from None
    if saved.get("chunk") != generator.CHUNK:
        raise CampaignError(f"{directory / PLAN}: chunks of {saved.get('chunk')} cases, this "
                            f"version makes chunks of {generator.CHUNK}: the cases would differ")
    return saved


def resume(directory: Path, engines: Callable[[Sequence[str]], Sequence[Adapter]],
           jobs: int | None = None, progress: Progress | None = None,
           scheduler: str | None = None) -> list[Group]:
    """Finish the campaign in ``directory`` (``engines(names)`` makes its engines).

    The chunks on disk are kept; the others are regenerated from (seed, chunk) and run,
    in ``jobs`` lanes or on ``scheduler`` if given (where they run changes no result).  A
    plan written before shrinking existed shrinks :data:`SHRINK` per group.
    """
    saved = stored_plan(directory)
    where: dict[str, Any] = {"jobs": jobs} if jobs else {}
    where |= {"scheduler": scheduler} if scheduler else {}
    options = RunOptions.from_json(saved["options"] | where)
    plan = Plan(Kind(saved["kind"]), int(saved["n"]), int(saved["seed"]),
                tuple(type(a) for a in engines(saved["engines"])), options,
                stored_bias(saved.get("bias", [])))
    writing = Writing(int(saved["per_group"]), int(saved.get("shrink", SHRINK)))
    return _campaign(directory, plan, saved["command"], writing, progress)


def _campaign(directory: Path, plan: Plan, command: str, writing: Writing,
              progress: Progress | None) -> list[Group]:
    """Run the chunks not yet on disk, then group, shrink and write the findings of all of
    them."""
    start = time.perf_counter()
    total = generator.chunk_count(plan.n)
    before = finished_chunks(directory)
    todo = [k for k in range(total) if k not in before]
    tally = _run(directory, plan, todo, progress, start)
    ran = time.perf_counter()
    log = ShrinkLog()
    shrink = shrinker([cls() for cls in plan.engines], plan.options, log) \
        if writing.shrink else None
    groups = write_stream(directory, lambda: _batches(directory, total, tally),
                          lambda ids: _inputs(directory, ids), command, writing.per_group,
                          shrink, writing.shrink)
    (directory / "schema.json").write_text(json_schema_text(), encoding="utf-8")
    _write_info(directory, plan, command, writing, tally, groups,
                {"run_s": ran - start, "write_s": time.perf_counter() - ran,
                 "chunks_run": len(todo), "chunks_before": len(before)}, log)
    return groups


def _run(directory: Path, plan: Plan, todo: list[int], progress: Progress | None,
         start: float) -> Tally:
    """Run chunks ``todo``, writing each as it finishes."""
    tally = Tally()

    def finished(chunk: int, cases: int, blocks: list[Block]) -> None:
        write_chunk(directory, chunk, cases, blocks)
        tally.add({}, {b.engine: b.seconds for b in blocks})
        tally.cases += cases
        tally.sample(start)
        if progress:
            progress(cases * len(plan.engines))

    if progress:
        progress((plan.n - sum(min(generator.CHUNK, plan.n - k * generator.CHUNK) for k in todo))
                 * len(plan.engines))  # the chunks finished before a resume
    run_chunks(plan, iter(todo), finished)
    return tally


def _batches(directory: Path, total: int, tally: Tally) -> Iterator[list[Row]]:
    """Every chunk's findings; the first time through, its counts go into ``tally``."""
    count = not tally.counts
    for chunk in range(total):  # the chunks finished before a resume, too
        data = read_chunk(directory, chunk)
        if count:
            tally.counts.update(data["counts"])
        yield data["findings"]


def _inputs(directory: Path, ids: set[str]) -> dict[str, AnyCase]:
    chunks = sorted({int(cid.rsplit("-", 1)[1]) // generator.CHUNK for cid in ids})
    found: dict[str, AnyCase] = {}
    for chunk in chunks:
        for cid, data in _load(_chunk_path(directory, chunk, ".inputs")).items():
            if cid in ids:
                found[cid] = CASE_ADAPTER.validate_python(data)
    return found


def shrink_findings(findings: Sequence[tuple[str, AnyCase, Row]], engines: Sequence[Adapter],
                    options: RunOptions, max_calls: int = MAX_CALLS) -> dict[str, Shrunk]:
    """Shrink each (engine name, case, finding row) in ``options.jobs`` lanes, each with its
    worker pool (:mod:`crosscheck.studies.fuzz.shrink`); by case id."""
    by_name = {adapter.name: adapter for adapter in engines}

    def one(item: tuple[str, AnyCase, Row], executor: Executor) -> tuple[str, Shrunk]:
        engine, case, row = item
        return case.id, shrink_case(case, by_name[engine], Signature.of(row), executor,
                                    options, max_calls)

    with LocalLanes(replace(options, isolate=True)) as lanes:
        return dict(lanes.map(one, findings))


def written(shrunk: Shrunk, found: Row) -> tuple[AnyCase, str]:
    """The shrunk case as written (id ``<original>-shrunk``, tagged ``shrunk``) and its
    description: where it comes from, its finding's numbers and the original's."""
    assert shrunk.record is not None
    moves = ", ".join(f"{n} {kind}" for kind, n in Counter(k for k, _ in shrunk.steps).items())
    case = CASE_ADAPTER.validate_python(shrunk.case.model_dump() | {
        "id": shrunk.original.id + SHRUNK_SUFFIX, "tags": (*shrunk.case.tags, SHRUNK_TAG)})
    return case, (f"Shrunk from {shrunk.original.id} in {shrunk.calls} engine calls ({moves}). "
                  f"Fails the same way: {finding_text(shrunk.record.row())}. "
                  f"The original: {finding_text(dict(found))}")


@dataclass
class ShrinkLog:
    """What a campaign's shrinker did: every finding it shrank, and the seconds it took."""

    shrunk: list[Shrunk] = field(default_factory=list)
    seconds: float = 0.0


def shrinker(engines: Sequence[Adapter], options: RunOptions, log: ShrinkLog) -> Shrinker:
    """The campaign's :data:`~crosscheck.studies.fuzz.findings.Shrinker`: every finding given
    shrunk (and logged); those that shrank returned as written, with their description."""
    def run(found: Sequence[tuple[Group, AnyCase, Row]]) -> dict[str, tuple[AnyCase, str]]:
        start = time.perf_counter()
        results = shrink_findings([(g.engine, case, row) for g, case, row in found], engines,
                                  options)
        log.seconds += time.perf_counter() - start
        log.shrunk.extend(results[cid] for cid in sorted(results))
        rows = {case.id: row for _, case, row in found}
        return {cid: written(s, rows[cid]) for cid, s in sorted(results.items()) if s.changed}
    return run


def _shrink_info(log: ShrinkLog) -> dict[str, Any]:
    """fuzz.json's account of the shrinking: per finding shrunk, its calls and outcome."""
    shrunk = log.shrunk
    return {"max_calls": MAX_CALLS, "s": log.seconds,
            "calls": sum(s.calls for s in shrunk), "written": sum(s.changed for s in shrunk),
            "findings": [{"case": s.original.id, "engine": s.engine,
                          "quantity": s.signature.quantity, "calls": s.calls,
                          "crashed": s.crashed, "reproduced": s.record is not None,
                          "shrunk": s.changed} for s in shrunk]}


def _write_info(directory: Path, plan: Plan, command: str, writing: Writing, tally: Tally,
                groups: Sequence[Group], times: dict[str, float], log: ShrinkLog) -> None:
    engines = _plan_json(plan, command, writing)["engines"]
    seconds = times["run_s"]
    ran = tally.cases
    counts: dict[str, dict[str, int]] = {}
    for key, value in sorted(tally.counts.items()):
        engine, quantity, status, category = key.split("\t")
        label = f"{quantity} {status}" + (f" {category}" if category else "")
        counts.setdefault(engine, {})[label] = value
    info = {"command": command, "kind": plan.kind.value, "n": plan.n, "seed": plan.seed,
            "engines": engines, "per_group": writing.per_group, "shrink_per_group": writing.shrink,
            "options": plan.options.to_json(), "finished": now(), **times, "cases_run": ran,
            "cases_per_s": ran / seconds if seconds > 0 else None,
            "engine_cases_per_s": {name: ran / s for name, s in tally.seconds.items() if s > 0},
            "counts": counts, "memory": tally.memory,
            "findings": sum(g.count for g in groups), "groups": len(groups),
            "files": sum(bool(g.chosen) for g in groups),
            "shrink": _shrink_info(log), "machine": environment.machine()}
    (directory / "fuzz.json").write_text(json.dumps(info, indent=2) + "\n", encoding="utf-8")


def campaign_throughput(n: int, engines: Sequence[Adapter], jobs: int = 2, seed: int = 1,
                        kind: Kind = Kind.SPHERE,
                        clock: Callable[[], float] = time.perf_counter) -> dict[str, Any]:
    """The bench's figure: a fresh campaign of ``n`` cases in a temporary folder.

    Returns ``n``, ``jobs``, ``wall_s`` (``clock`` read before and after the campaign),
    ``cases_per_s`` (whole campaign, findings written but not shrunk: shrinking costs
    per group, not per case), ``run_cases_per_s`` (chunks
    only), ``engine_cases_per_s`` (cases per second of one engine's own time in its lane:
    query, prepare and scoring) and the peak resident memory of the parent and of the
    lanes (``memory``: samples over time).
    """
    options = RunOptions(quick=True, jobs=jobs)
    with tempfile.TemporaryDirectory(prefix="fuzz-bench-") as tmp:
        start = clock()
        fuzz(kind, n, seed, Path(tmp) / "out", engines, options, shrink=0)
        wall = clock() - start
        info = json.loads((Path(tmp) / "out" / "fuzz.json").read_text(encoding="utf-8"))
    memory = info["memory"]
    return {"n": n, "jobs": jobs, "engines": info["engines"], "wall_s": wall,
            "cases_per_s": n / wall, "run_cases_per_s": info["cases_per_s"],
            "engine_cases_per_s": info["engine_cases_per_s"],
            "peak_parent_mb": max((m["parent_mb"] for m in memory), default=None),
            "peak_lanes_mb": max((m["lanes_mb"] for m in memory), default=None),
            "memory": memory}
