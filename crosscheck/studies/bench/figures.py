"""``crosscheck bench``: the harness's own performance figures, each beside its target.

The figures, each a ratio or a measurement taken within this one run:

1. batch oracle: throughput of :mod:`reference_impl.batch` (verdicts) and of
   :mod:`reference_impl.batch_values` (correctly rounded sphere distances and
   normals) over the naive numpy float64 formula on 1M pairs, 1% within a few
   ulps of touching, and agreement with the pure exact oracle on every near
   pair plus a random sample (measured by :mod:`crosscheck.studies.bench.oracle`);
2. harness overhead: per case, ``execute`` (prepare, query, release) plus
   columnar scoring into result lines, against the engine's own API in a tight
   loop (:mod:`crosscheck.studies.bench.rawloops`), for FCL and pymunk detection on the
   streams of :mod:`crosscheck.studies.bench.streams`: counted in instructions under
   callgrind (:mod:`crosscheck.studies.bench.counted`; these judge the target) and in
   wall-clock time (recorded, never gating: the shared machine's clock drifts too much
   within a run); and for PyBullet over a long stream of sphere cases (its bodies are
   reused);
3. suite time: ``crosscheck run --quick`` with the seven variants of the targets and with
   every available variant, the full ``make run`` (every variant, repeat check included),
   ``crosscheck --help`` and ``crosscheck report`` of the full run, each a whole process
   timed as a subprocess, the median of three judged (:mod:`crosscheck.studies.bench.suite`);
4. memory: resident memory over the PyBullet stream (growth after the first
   fifth, bodies left in the client) and the peak RSS of the suite runs;
5. scale-out: the same cases on a Dask ``LocalCluster`` of 2 worker processes
   and locally; results must be identical (Dask is imported there only, as in
   :mod:`crosscheck.run.distributed`);
6. a fuzz campaign of a million sphere cases on the seven variants, run to the end
   (``--quick``: 2,000 cases, extrapolated and only recorded), with cases per second per
   engine (:func:`crosscheck.studies.fuzz.campaign.campaign_throughput`);
7. ``make test`` on a fresh clone, read from the measurement ``python -m
   tools.measure_setup --test`` writes (it clones and builds a venv: not re-run here).

``--quick`` uses smaller sizes (not for the batch oracle, whose target is set on 1M
pairs, nor for the counted figures, which are exact at their size) and skips the
full-suite run.
"""

from __future__ import annotations

import json
import logging
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

import adapters
from adapters import pybullet as pybullet_engine
from crosscheck.cases.load import load_paths
from crosscheck.core.options import RunOptions
from crosscheck.results.store import ResultsStore
from crosscheck.run import environment
from crosscheck.run.execute import execute
from crosscheck.run.launch import launch, new_info
from crosscheck.studies.bench import counted, rawloops, suite
from crosscheck.studies.bench.kit import RECORDED, ROOT, Figure, rss_mb, settle
from crosscheck.studies.bench.oracle import best_of, values_benchmark, verdicts_benchmark
from crosscheck.studies.bench.streams import (
    OVERHEAD_LIMIT_PCT,
    as_cases,
    engine_path,
    harness,
    overhead_streams,
    sphere_pairs,
)
from crosscheck.studies.fuzz import campaign

FORMAT_VERSION = 3
"""bench.json's version (history: :mod:`crosscheck.studies.bench.comparison`)."""


def batch_figures(n: int) -> list[Figure]:
    """Figure 1, for AABB and sphere pairs."""
    figures = []
    for kind in ("aabb", "sphere"):
        r = verdicts_benchmark(n=n, near_fraction=0.01, seed=0, kind=kind)
        figures.append(Figure(
            f"batch oracle {kind}: throughput / naive float64", r["ratio"], "x",
            ">= 0.5 and 100% verdict agreement",
            r["ratio"] >= 0.5 and r["agreement"] == 1.0, {"pairs": n, **r},
            note=(f"{r['batch_pairs_per_s'] / 1e6:.1f} vs {r['naive_pairs_per_s'] / 1e6:.1f} "
                  f"M pairs/s; agreement {r['agreement']:.0%} of {r['checked']:.0f}; "
                  f"{r['refined']:.0f} refined, {r['fallbacks']:.0f} to Fractions")))
    return figures


def values_figure(n: int) -> Figure:
    """Figure 1b: correctly rounded sphere distances and normals in batch (double-double and
    a rounding test, :mod:`reference_impl.batch_values`) against the naive float64 formula."""
    r = values_benchmark(n=n, seed=0)
    same = r["identical"] == r["checked"]
    return Figure(
        "batch exact values sphere (distance, normal): throughput / naive float64", r["ratio"],
        "x", ">= 0.25 and every checked value bit-identical to the pure oracle",
        r["ratio"] >= 0.25 and same and r["checked"] >= 20_000, {"pairs": n, **r},
        note=(f"{r['batch_pairs_per_s'] / 1e6:.2f} vs {r['naive_pairs_per_s'] / 1e6:.1f} M pairs/s;"
              f" {r['identical']:.0f} of {r['checked']:.0f} identical (all {r['near']:.0f} near "
              f"ones included); settled: {_stages(r)}"))


MILLION = 1_000_000
"""The campaign of the target: a million sphere cases, run to the end (not extrapolated)."""


def campaign_figure(n: int, engines: Sequence[str],
                    clock: Callable[[], float] = time.perf_counter) -> Figure:
    """Figure 6: a fuzz campaign of ``n`` sphere cases (cases/s per engine are each engine's
    own lane time, scoring included; ``clock`` times the whole).  At :data:`MILLION` cases
    it is the target's campaign, judged on its wall time; smaller (``bench --quick``) it is
    extrapolated to a million and only recorded."""
    r = campaign.campaign_throughput(n, [adapters.get(e) for e in engines], clock=clock)
    real = n >= MILLION
    minutes = r["wall_s"] / 60 if real else MILLION / r["cases_per_s"] / 60
    per_engine = ", ".join(f"{e} {v:,.0f}" for e, v in r["engine_cases_per_s"].items())
    name = (f"fuzz campaign, sphere, {len(engines)} engines: {n:,} cases, run to the end"
            if real else f"fuzz campaign, sphere, {len(engines)} engines: 1,000,000 cases "
                         f"extrapolated from {n:,}")
    return Figure(
        name, minutes, "min", "<= 15 min" if real else RECORDED,
        minutes <= 15.0 if real else True,
        {key: value for key, value in r.items() if key != "memory"},
        note=(f"{r['cases_per_s']:.0f} cases/s; per engine (cases/s of its own time): "
              f"{per_engine}; peak memory parent {r['peak_parent_mb']:.0f} MB, lanes "
              f"{r['peak_lanes_mb']:.0f} MB" + ("" if real else "; one run, extrapolated")))


def _stages(r: dict[str, float]) -> str:
    return ", ".join(f"{k.removeprefix('stage_')} {v:.0f}" for k, v in r.items()
                     if k.startswith("stage_"))


def overhead_figure(engine: str, kind: str, raw: Callable[[], None], cases: Sequence[Any],
                    limit: float) -> Figure:
    """Harness per-case time over raw per-case time (best of three each), wall clock:
    recorded, never gating (the wall clock drifts too much on a shared machine to judge
    ``limit``; the counted figure of :mod:`crosscheck.studies.bench.counted` gates it).

    Also measured: the engine path alone (``execute``: prepare, query, release,
    no scoring), to show where the overhead goes.
    """

    n = len(cases)
    adapter, run_slice = harness(engine, cases)
    run_slice(0, n)  # warm up: imports, connections, caches
    settle()
    raw()
    raw_s, path_s = best_of(raw), best_of(engine_path(adapter, cases))
    harness_s = best_of(lambda: run_slice(0, n))
    over, path = harness_s / raw_s - 1.0, path_s / raw_s - 1.0
    return Figure(f"harness overhead {engine} {kind}", over * 100.0, "%", RECORDED, True,
                  {"cases": n, "raw_us": raw_s / n * 1e6, "engine_path_us": path_s / n * 1e6,
                   "harness_us": harness_s / n * 1e6, "engine_path_overhead_pct": path * 100.0},
                  note=(f"wall clock, never gating (the counted figure gates <= {limit:.0f}%): "
                        f"raw {raw_s / n * 1e6:.1f} us; engine path alone +{path * 100.0:.0f}%"),
                  gating=False)


def overhead_figures(n: int) -> list[Figure]:
    """Figure 2 for FCL (3-D) and pymunk (2-D): spheres and boxes, wall clock (recorded)."""
    return [overhead_figure(s.engine, s.kind, s.raw(), s.cases(), OVERHEAD_LIMIT_PCT)
            for s in overhead_streams(n)]


def pybullet_figures(n: int, clock: Callable[[], float] = time.perf_counter) -> list[Figure]:
    """Figures 2 (PyBullet stream) and 4 (memory over it).

    The stream is what a worker does per case in a ``--quick`` run: ``execute``
    (prepare on pooled bodies, query, release); scoring runs in the parent, so the
    harness with records is timed on a tenth of the cases and shown beside it.  ``clock``
    times the stream (the raw loop and the harness are :func:`best_of` runs).
    """

    pairs = sphere_pairs(n, 3, 3, radii=(0.5, 1.0))
    cases = as_cases(pairs, False)
    raw, close = rawloops.pybullet_loop(pairs)
    raw()  # warm up
    raw_s = best_of(raw)
    close()
    adapter, run_slice = harness("pybullet", cases)
    options = RunOptions(quick=True)
    run_slice(0, min(n, 100))  # warm up: connect the client, make the first bodies
    settle()
    cid = pybullet_engine.client(adapter.name, adapter.world)
    before = pybullet_engine.engine().getNumBodies(physicsClientId=cid)
    step = max(1, n // 10)
    rss: list[float] = []
    start = clock()
    for lo in range(0, n, step):
        for case in cases[lo:lo + step]:
            execute(adapter, case, options)
        rss.append(rss_mb())
    path_s = clock() - start
    full_s = best_of(lambda: run_slice(0, step), 1) * n / step
    bodies = pybullet_engine.engine().getNumBodies(physicsClientId=cid)
    ratio = path_s / raw_s
    growth = rss[-1] - rss[min(1, len(rss) - 1)]
    us = {"raw_us": raw_s / n * 1e6, "engine_path_us": path_s / n * 1e6,
          "harness_us": full_s / n * 1e6}
    return [
        Figure("pybullet sphere stream: per-case cost / raw query", ratio, "x", "<= 3",
               ratio <= 3.0, {"cases": n, **us},
               note=(f"{n} cases: raw {us['raw_us']:.1f} us, execute {us['engine_path_us']:.1f}"
                     f" us; with records {us['harness_us']:.1f} us")),
        Figure("memory growth over the pybullet stream (after the first fifth)", growth, "MB",
               "< 20 MB (flat), bodies bounded", growth < 20.0 and bodies <= 64,
               {"rss_mb": [round(x, 1) for x in rss], "bodies_left": bodies,
                "bodies_before": before},
               note=(f"RSS {rss[0]:.0f} -> {rss[-1]:.0f} MB; {bodies} bodies in the client"
                     f" ({before} before the stream)")),
    ]


def dask_figure(quick: bool) -> Figure:
    """Figure 5: the same cases on a 2-worker LocalCluster and locally, compared."""
    import dask
    from distributed import LocalCluster


    files = ["sphere.toml"] if quick else ["sphere.toml", "response.toml", "aabb.toml"]
    cases = load_paths([ROOT / "cases" / f for f in files]).cases
    engines = [adapters.get(e) for e in ("reference", "pymunk", "pybullet")]
    timing = ["setup_s", "query_s", "query_iqr_s", "loops", "unstable"]
    frames, walls = [], []
    with (tempfile.TemporaryDirectory() as tmp,
          dask.config.set({"distributed.worker.daemon": False}),
          LocalCluster(n_workers=2, processes=True, threads_per_worker=1,  # type: ignore[no-untyped-call]
                       dashboard_address=None, silence_logs=logging.ERROR) as cluster):
        dask_options = RunOptions(quick=True, scheduler=cluster.scheduler_address)
        for name, options in (("local", RunOptions(quick=True, jobs=2)), ("dask", dask_options)):
            folder = Path(tmp) / name
            info = new_info(folder, f"crosscheck bench ({name})", options, engines, cases)
            start = time.perf_counter()
            run = launch(ResultsStore(folder), cases, engines, options, info)
            walls.append(time.perf_counter() - start)
            frame = run.results.drop(columns=timing)
            frame = frame.sort_values(["case_id", "engine", "quantity"])
            frames.append(frame.reset_index(drop=True))
    same = frames[0].equals(frames[1])
    return Figure("scale-out: Dask LocalCluster (2 workers) / local wall time", walls[1] / walls[0],
                  "x", "results identical", same,
                  {"cases": len(cases), "rows": len(frames[0]), "identical": same,
                   "local_s": walls[0], "dask_s": walls[1]},
                  note=(f"{len(frames[0])} rows {'identical' if same else 'DIFFER'}; local "
                        f"{walls[0]:.1f} s, cluster {walls[1]:.1f} s"))


def measure(quick: bool, progress: Callable[[str], None] | None = None,
            full_runs: int = suite.RUNS, campaign: int | None = None,
            deep: bool = False) -> list[Figure]:
    """Every figure, in order; ``progress`` is told as each group starts and ends.

    ``full_runs``: how many times the full ``make run`` is timed (its figure is their
    median); ``campaign``: the fuzz campaign's cases (default 2,000 with ``quick``, else
    :data:`MILLION`; under a million the figure is extrapolated and only recorded); ``deep``:
    also time ``make run-deep`` once and render its report."""
    whole, help_, render = suite.figures(quick, full_runs, deep)
    cases = campaign if campaign is not None else 2_000 if quick else MILLION
    steps: list[tuple[str, Callable[[], list[Figure]]]] = [
        ("batch oracle, 1M pairs", lambda: batch_figures(1_000_000)),  # the target's size
        ("batch exact values, 1M pairs", lambda: [values_figure(1_000_000)]),
        ("harness overhead (fcl, pymunk), wall clock",
         lambda: overhead_figures(1_000 if quick else 5_000)),
        ("harness overhead (fcl, pymunk), counted instructions",
         lambda: counted.counted_figures(counted.CASES)),
        ("pybullet stream and memory", lambda: pybullet_figures(10_000 if quick else 100_000)),
        ("suite time" + (" (--quick only)" if quick else ""), whole),
        ("crosscheck --help", help_),
        ("report render", render),
        ("Dask scale-out", lambda: [dask_figure(quick)]),
        ("fuzz campaign", lambda: [campaign_figure(cases, suite.SEVEN)])]
    figures: list[Figure] = []
    started = time.perf_counter()
    for n, (label, step) in enumerate(steps, start=1):
        if progress:
            progress(f"bench {n}/{len(steps)}: {label} ...")
        figures += step()
        if progress:
            progress(f"bench {n}/{len(steps)}: {label} done "
                     f"({time.perf_counter() - started:.0f} s so far)")
    return figures


def write(figures: Sequence[Figure], out: Path, quick: bool) -> Path:
    """``out/bench.json``: the figures with the machine and versions they were measured on."""
    out.mkdir(parents=True, exist_ok=True)
    path = out / "bench.json"
    payload = {"format_version": FORMAT_VERSION, "quick": quick,
               "command": "crosscheck bench" + (" --quick" if quick else ""),
               "machine": environment.machine(), "figures": [asdict(f) for f in figures]}
    path.write_text(json.dumps(payload, indent=2, default=_plain) + "\n")
    return path


def _plain(x: Any) -> Any:
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"cannot write {type(x).__name__} to bench.json")
