"""Fuzz chunks run in lane processes: whole chunks per task, crash and hang safety per case.

A campaign (:mod:`crosscheck.studies.fuzz.campaign`) runs chunks of
:data:`~crosscheck.studies.fuzz.generator.CHUNK` cases.  Sending every case x engine to a
worker, as a run does, costs more than the engines themselves, so here each of
``jobs`` lane processes takes a whole chunk: it generates the chunk's cases
(from the seed and chunk index only), computes their truth, runs every engine
in-process, case after case, and scores them, and sends back a summary per
engine: status counts and the finding rows only (:func:`run_engine`).

Safety stays per case.  Before each query the lane writes (case position,
engine position) into a shared marker.  If the lane dies (an engine aborts), the
parent reads the marker, settles that pair as ``crash``; if the marker stays on
one pair longer than the run's timeout, the parent kills the lane and settles the
pair as ``timeout``.  A new lane then takes the chunk up again at that engine,
from the chunk's cases and truth that the first lane sent back (no regeneration),
running the settled pairs no more.  Lanes are started by the ``forkserver``
method with the engines preloaded, so a restart costs milliseconds.

A case whose engine declares a known hang (``Adapter.known_hang``) is not run:
its rows are ``timeout`` with the declared reason (the generator never makes the
coincident centres that FCL's hang needs).
"""

from __future__ import annotations

import atexit
import pickle
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from contextlib import suppress
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from multiprocessing.process import BaseProcess
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Kind, Observation, Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.run.distributed import DaskLanes
from crosscheck.run.execute import Executor, Outcome, execute
from crosscheck.run.processes import CONTEXT, death, quiet_child, start
from crosscheck.run.scoring import score_case
from crosscheck.studies.fuzz import generator
from crosscheck.studies.fuzz.findings import Row, finding_row
from crosscheck.truth import oracle

Settled = dict[tuple[int, int], tuple[str, str]]
"""(case position, engine position) -> (status, reason) of pairs not to run again."""


@dataclass(frozen=True)
class Plan:
    """What a campaign runs: picklable (engines as classes), the same in every lane."""

    kind: Kind
    n: int
    seed: int
    engines: tuple[type[Adapter], ...]
    options: RunOptions
    bias: generator.Bias = ()
    """Failing cells the space family starts from (:mod:`crosscheck.studies.fuzz.bias`)."""


def chunk_truth(cases: Sequence[AnyCase]) -> list[Observation]:
    """The exact truth of a chunk's cases.

    Swap point: a batch oracle of distances and normals (``reference_impl/batch_values.py``,
    in progress) replaces this per-case loop; the batch verdicts alone
    (``reference_impl/batch.py``) would save nothing here, because the exact contact
    settles the hit on its way to the distance and normal.
    """
    return [oracle.truth(case) for case in cases]


def judge_chunk(cases: Sequence[AnyCase], adapter: Adapter, outcomes: Sequence[Outcome],
                truths: Sequence[Observation]) -> list[Record]:
    """The records of one engine on a chunk: the one call a columnar scorer
    (``crosscheck/truth/columnar.py``, in progress) replaces."""
    return [r for case, outcome, truth in zip(cases, outcomes, truths, strict=True)
            for r in score_case(case, adapter, outcome, truth)]


@dataclass
class Block:
    """One engine's summary of one chunk: status counts, findings, engine-side seconds."""

    engine: str
    counts: Counter[str] = field(default_factory=Counter)
    findings: list[Row] = field(default_factory=list)
    cases: dict[str, dict[str, Any]] = field(default_factory=dict)
    seconds: float = 0.0


def count_key(engine: str, quantity: str, status: str, category: str) -> str:
    """The key of a status count: ``engine quantity status category`` (tab-separated)."""
    return "\t".join((engine, quantity, status, category))


def fuzz_outcome(adapter: Adapter, case: AnyCase, options: RunOptions,
                 executor: Executor = execute) -> Outcome:
    """How a campaign runs one case on one engine: a declared known hang is not run (its
    outcome is ``timeout`` with the declared reason); any other case goes to ``executor``
    (in a lane, :func:`~crosscheck.run.execute.execute` in-process; the shrinker, a worker
    pool)."""
    hang = adapter.known_hang(case)
    if hang is not None:
        return Outcome(None, Status.TIMEOUT, f"not run in a fuzz campaign: declared known hang: "
                                             f"{hang}")
    return executor(adapter, case, options)


def _outcome(adapter: Adapter, case: AnyCase, options: RunOptions,
             settled: tuple[str, str] | None) -> Outcome:
    if settled is not None:
        return Outcome(None, Status(settled[0]), settled[1])
    return fuzz_outcome(adapter, case, options)


def run_engine(plan: Plan, adapter: Adapter, position: int, gens: Sequence[generator.Generated],
               truths: Sequence[Observation], settled: Settled,
               marker: Callable[[int, int], None]) -> Block:
    """Run and score one engine on a chunk; ``marker(case position, engine position)``
    is called before each query (``-1`` when done)."""
    start = time.perf_counter()
    outcomes = []
    for pos, gen in enumerate(gens):
        marker(pos, position)
        outcomes.append(_outcome(adapter, gen.case, plan.options, settled.get((pos, position))))
    marker(-1, -1)
    records = judge_chunk([g.case for g in gens], adapter, outcomes, truths)
    block = Block(adapter.name)
    for record in records:
        block.counts[count_key(record.engine, record.quantity, str(record.status),
                               record.category or "")] += 1
        if record.status.breaking:
            gen = gens[int(record.case_id.rsplit("-", 1)[1]) - gens[0].index]
            block.findings.append(finding_row(record.row(), gen))
            block.cases[gen.case.id] = gen.case.model_dump() | {"source": gen.case.source}
    block.seconds = time.perf_counter() - start
    return block


# --- the lane process ---------------------------------------------------------------------

Task = tuple[int, bytes | None, Settled, int]
"""(chunk, its pickled cases and truth or None, settled pairs, first engine position)."""


def _lane(conn: Connection, marker: Any, plan: Plan) -> None:
    """A lane's loop: take a chunk, send its state, then one Block per engine, then None."""
    quiet_child()  # the parent stops the lanes
    adapters = [cls() for cls in plan.engines]

    def mark(pos: int, engine: int) -> None:
        marker[0], marker[1] = pos, engine

    while True:
        task: Task | None = conn.recv()
        if task is None:
            return
        chunk, state, settled, first = task
        if state is None:
            gens = generator.generate_chunk(plan.kind, plan.seed, chunk, plan.n, plan.bias)
            truths = chunk_truth([g.case for g in gens])
            state = pickle.dumps((gens, truths), protocol=pickle.HIGHEST_PROTOCOL)
            conn.send(("state", state))
        else:
            gens, truths = pickle.loads(state)
        for position in range(first, len(adapters)):
            conn.send(("block", run_engine(plan, adapters[position], position, gens, truths,
                                           settled, mark)))
        conn.send(("done", len(gens)))


@dataclass
class ChunkWork:
    """A chunk in progress in the parent: what the lane has sent so far."""

    chunk: int
    state: bytes | None = None
    settled: Settled = field(default_factory=dict)
    blocks: list[Block] = field(default_factory=list)
    restarts: int = 0


Finished = Callable[[int, int, list[Block]], None]
"""Called in the parent with (chunk, its number of cases, one Block per engine)."""


class Lane:
    """One lane process, its pipe, its marker and the chunk it works on."""

    def __init__(self, plan: Plan) -> None:
        self.plan = plan
        self.marker: Any = CONTEXT.RawArray("q", [-1, -1])
        self.conn, child = CONTEXT.Pipe()
        self.process: BaseProcess = CONTEXT.Process(target=_lane, args=(child, self.marker, plan),
                                                    daemon=True)
        start(self.process)
        child.close()
        self.work: ChunkWork | None = None
        self.seen: tuple[int, int, float] = (-1, -1, time.monotonic())

    def give(self, work: ChunkWork) -> None:
        self.work = work
        self.seen = (-1, -1, time.monotonic())
        self.conn.send((work.chunk, work.state, work.settled, len(work.blocks)))

    def stuck(self, timeout_s: float) -> tuple[int, int] | None:
        """The pair the lane has been on for longer than ``timeout_s``, if any."""
        now, here = time.monotonic(), (int(self.marker[0]), int(self.marker[1]))
        if here != self.seen[:2]:
            self.seen = (*here, now)
            return None
        return here if here[0] >= 0 and now - self.seen[2] > timeout_s else None

    def stop(self, kill: bool = False) -> None:
        if kill:
            self.process.kill()
        else:
            with suppress(OSError):
                self.conn.send(None)
        self.process.join(5)
        if self.process.is_alive():
            self.process.kill()
            self.process.join()
        self.conn.close()


MAX_RESTARTS = 50
"""A chunk whose lane dies this often outside any engine call stops the campaign."""


class ChunkLanes:
    """``jobs`` lanes running chunks; a dead or stuck lane is replaced (see the module doc)."""

    def __init__(self, plan: Plan, jobs: int) -> None:
        self.plan = plan
        modules = sorted({cls.__module__ for cls in plan.engines})
        CONTEXT.set_forkserver_preload(["crosscheck.studies.fuzz.lanes", *modules])
        self.lanes = [Lane(plan) for _ in range(max(1, jobs))]

    def __enter__(self) -> ChunkLanes:
        return self

    def __exit__(self, *exc: object) -> None:
        for lane in self.lanes:
            lane.stop(kill=exc[0] is not None)

    def run(self, chunks: Iterator[int], finished: Finished) -> None:
        """Run every chunk; ``finished`` is called as each one completes."""
        todo = chunks
        for lane in self.lanes:
            self._next(lane, todo)
        while any(lane.work for lane in self.lanes):
            busy = [lane for lane in self.lanes if lane.work]
            ready = wait([x for lane in busy for x in (lane.conn, lane.process.sentinel)], 0.2)
            for i, lane in enumerate(self.lanes):
                if lane.work and (lane.conn in ready or lane.process.sentinel in ready):
                    self._read(i, lane, todo, finished)
                elif lane.work:
                    self._watch(i, lane)

    def _next(self, lane: Lane, todo: Iterator[int]) -> None:
        chunk = next(todo, None)
        lane.work = None
        if chunk is not None:
            lane.give(ChunkWork(chunk))

    def _read(self, i: int, lane: Lane, todo: Iterator[int], finished: Finished) -> None:
        work = lane.work
        assert work is not None
        try:
            while lane.conn.poll():
                what, payload = lane.conn.recv()
                if what == "state":
                    work.state = payload
                elif what == "block":
                    work.blocks.append(payload)
                else:
                    finished(work.chunk, payload, work.blocks)
                    self._next(lane, todo)
                    return
        except (EOFError, OSError):
            pass
        if not lane.process.is_alive():
            self._replace(i, Status.CRASH, death(lane.process.exitcode))

    def _watch(self, i: int, lane: Lane) -> None:
        if lane.stuck(self.plan.options.timeout_s) is not None:
            self._replace(i, Status.TIMEOUT, f"no answer in {self.plan.options.timeout_s:g} s "
                                             f"(worker killed)")

    def _replace(self, i: int, status: Status, reason: str) -> None:
        """Settle the pair the lane was on, start a new lane, give it the chunk again."""
        old = self.lanes[i]
        work = old.work
        assert work is not None
        pos, engine = int(old.marker[0]), int(old.marker[1])
        old.stop(kill=True)
        if pos >= 0:
            work.settled[(pos, engine)] = (status.value, reason)
        else:
            work.restarts += 1
            if work.restarts > MAX_RESTARTS:
                raise RuntimeError(f"fuzz chunk {work.chunk}: its lane died {MAX_RESTARTS} "
                                   f"times outside any engine ({reason})")
        lane = self.lanes[i] = Lane(self.plan)
        lane.give(work)


# --- on a Dask worker ------------------------------------------------------------------------

_here: dict[tuple[Plan, int], ChunkLanes] = {}
_here_lock = threading.Lock()


def _stop_here() -> None:
    with _here_lock:
        for lanes in _here.values():
            lanes.__exit__(None, None, None)
        _here.clear()


atexit.register(_stop_here)


@dataclass(frozen=True)
class DaskChunk:
    """A chunk as a Dask task (:class:`~crosscheck.run.distributed.DaskLanes`): run in a lane
    of this Dask worker thread, kept for the worker's life, so crashes stay per case."""

    plan: Plan

    def __call__(self, chunk: int, executor: Executor) -> tuple[int, int, list[Block]]:
        key = (self.plan, threading.get_ident())
        with _here_lock:
            lanes = _here.get(key) or _here.setdefault(key, ChunkLanes(self.plan, 1))
        done: list[tuple[int, int, list[Block]]] = []
        lanes.run(iter([chunk]), lambda k, cases, blocks: done.append((k, cases, blocks)))
        return done[0]


def run_chunks(plan: Plan, chunks: Iterator[int], finished: Finished) -> list[int]:
    """Run ``chunks`` in local lanes, or on ``plan.options.scheduler``'s Dask cluster;
    ``finished`` is called in this process as each one completes.  Returns the pids whose
    memory is ours to watch (the local lanes; none on a cluster)."""
    if plan.options.scheduler:
        with DaskLanes(plan.options) as dask:
            for chunk, cases, blocks in dask.map(DaskChunk(plan), chunks):
                finished(chunk, cases, blocks)
        return []
    with ChunkLanes(plan, plan.options.jobs) as lanes:
        lanes.run(chunks, finished)
    return [lane.process.pid or 0 for lane in lanes.lanes]

