"""The case streams of the harness-overhead figures, and the harness path run over them.

What it is for: the wall-clock overhead figures (:mod:`crosscheck.studies.bench.figures`) and
the counted ones (:mod:`crosscheck.studies.bench.counted`, whose worker runs under callgrind)
measure the same four streams (FCL in 3-D and pymunk in 2-D, spheres and boxes) the same
way; this module is the one definition of both, light enough to import under Valgrind
(no Dask, no PyBullet, no run launcher):

- :func:`sphere_pairs`, :func:`box_pairs` and :func:`as_cases`: random pairs, as plain tuples
  for the raw loops (:mod:`crosscheck.studies.bench.rawloops`) and as the harness's cases;
- :func:`overhead_streams`: the four streams, each with its raw loop;
- :func:`harness`: ``execute`` per case plus columnar scoring into JSON lines, as a worker
  and the runner do; :func:`engine_path`: ``execute`` alone.

>>> [(s.engine, s.kind, len(s.pairs)) for s in overhead_streams(3)]
[('fcl', 'sphere', 3), ('fcl', 'aabb', 3), ('pymunk', 'sphere', 3), ('pymunk', 'aabb', 3)]
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import adapters
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER
from crosscheck.run.execute import execute
from crosscheck.run.runner import score_lines
from crosscheck.studies.bench import rawloops
from crosscheck.truth import oracle

OVERHEAD_LIMIT_PCT = 50.0
"""The harness-overhead target: execute plus scoring at most this much over the raw loop."""
OPTIONS = RunOptions(quick=True)
"""The options every case of the overhead figures is executed with."""


def sphere_pairs(n: int, dim: int, seed: int, radii: Sequence[float]) -> list[tuple[Any, ...]]:
    """``n`` random sphere pairs, about a third overlapping, radii drawn from ``radii``."""
    rng = np.random.default_rng(seed)
    pa = rng.uniform(-10, 10, (n, dim))
    pb = pa + rng.uniform(-2.5, 2.5, (n, dim))
    r = rng.choice(np.asarray(radii), (n, 2))
    return [(pa[i].tolist(), float(r[i, 0]), pb[i].tolist(), float(r[i, 1])) for i in range(n)]


def box_pairs(n: int, dim: int, seed: int) -> list[tuple[Any, ...]]:
    """``n`` random box pairs (centre, half-widths), about half overlapping."""
    rng = np.random.default_rng(seed)
    ca = rng.uniform(-10, 10, (n, dim))
    cb = ca + rng.uniform(-3, 3, (n, dim))
    ha, hb = rng.uniform(0.2, 1.5, (n, dim)), rng.uniform(0.2, 1.5, (n, dim))
    return [(ca[i].tolist(), ha[i].tolist(), cb[i].tolist(), hb[i].tolist()) for i in range(n)]


def as_cases(pairs: Sequence[tuple[Any, ...]], boxes: bool) -> list[Any]:
    """The harness's case objects for ``pairs`` (validated, as the loader makes them)."""
    key = "half" if boxes else "radius"
    return [CASE_ADAPTER.validate_python({
        "id": f"bench-{i}", "description": "bench", "kind": "aabb" if boxes else "sphere",
        "dim": len(pa), "a": {"center": pa, key: sa}, "b": {"center": pb, key: sb}})
        for i, (pa, sa, pb, sb) in enumerate(pairs)]


@dataclass(frozen=True)
class Stream:
    """One engine x kind of the overhead figures: its pairs and the maker of its raw loop."""

    engine: str
    kind: str
    pairs: list[tuple[Any, ...]]
    make: Callable[[Sequence[Any], bool], rawloops.Loop]

    @property
    def boxes(self) -> bool:
        return self.kind == "aabb"

    def raw(self) -> rawloops.Loop:
        """The engine's own API over the pairs, in a tight loop."""
        return self.make(self.pairs, self.boxes)

    def cases(self) -> list[Any]:
        """The pairs as the harness's cases."""
        return as_cases(self.pairs, self.boxes)


def overhead_streams(n: int) -> list[Stream]:
    """The four streams of ``n`` cases: FCL (3-D) then pymunk (2-D), spheres then boxes."""
    streams = []
    for engine, dim, make in (("fcl", 3, rawloops.fcl_loop), ("pymunk", 2, rawloops.pymunk_loop)):
        streams.append(Stream(engine, "sphere", sphere_pairs(n, dim, 1, (0.5, 0.8, 1.0, 1.3)),
                              make))
        streams.append(Stream(engine, "aabb", box_pairs(n, dim, 2), make))
    return streams


def harness(engine: str, cases: Sequence[Any]) -> tuple[Any, Callable[[int, int], None]]:
    """The adapter, and a function running cases ``[lo, hi)`` as the harness does.

    Per case: ``execute`` (prepare, query, release); then the slice is scored as the
    runner scores it, in columns into the JSON lines it writes
    (:func:`~crosscheck.run.runner.score_lines`); the exact truths are computed here,
    once, outside anything measured.
    """

    adapter = adapters.get(engine)
    truths = [oracle.truth(c) for c in cases]

    def run_slice(lo: int, hi: int) -> None:
        outcomes = [execute(adapter, case, OPTIONS) for case in cases[lo:hi]]
        score_lines(cases[lo:hi], adapter, outcomes, truths[lo:hi])

    return adapter, run_slice


def engine_path(adapter: Any, cases: Sequence[Any]) -> Callable[[], None]:
    """``execute`` (prepare, query, release) of every case on ``adapter``, no scoring."""

    def run() -> None:
        for case in cases:
            execute(adapter, case, OPTIONS)

    return run
