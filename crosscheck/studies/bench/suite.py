"""The bench's wall-clock figures: suite runs, ``--help`` and the report render, as subprocesses.

Every figure here is a command timed from outside, in its own session, so
that its imports, workers and report are all counted:

- ``crosscheck run --quick`` with the seven engine variants the targets were set on
  (:data:`SEVEN`) and with every available one, README's first look ``make run
  ARGS=--quick`` (the Makefile adds ``--repeat-check``), ``make run`` (the standard tier,
  every variant, the repeat check and the timing phase) and the same with ``--timer
  instructions``: each :data:`RUNS` times, median and range;
- with ``--deep``, ``make run-deep`` once (the deep tier's time is recorded, not judged);
- the peak memory (PSS, every process of the session) of the standard runs;
- ``crosscheck --help`` (twenty times: median and quartiles);
- ``crosscheck report`` of the last standard run (and of the deep run), whole process, and
  the size of the standard run's report.html.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import adapters
from crosscheck.results import timings
from crosscheck.studies.bench.kit import RECORDED, ROOT, Figure, run_measured

SEVEN = ("reference", "reference-f32", "fcl", "pybullet", "pybullet-default", "pymunk",
         "pymunk-default")
"""The engine variants of the issue's targets (``--engine`` each)."""

QUICK_S, QUICK_ALL_S, FIRST_LOOK_S, FULL_ALL_S, COUNTED_S = 6.0, 12.0, 20.0, 90.0, 180.0
"""Targets (seconds, whole-process medians): ``run --quick`` with the seven variants and with
every available one, ``make run ARGS=--quick``, ``make run`` (the standard tier, every
available variant, the timing phase and the repeat check) and the same with ``--timer
instructions``."""
HELP_S, REPORT_S, REPORT_DEEP_S, REPORT_MB, MEMORY_MB = 0.3, 1.5, 5.0, 3.0, 1024.0
"""Targets: ``--help``, ``crosscheck report`` of a standard and of a deep run (seconds), the
standard run's report.html (MB) and the peak memory of a standard run (PSS, MB)."""

RUNS = 3
"""Runs of each suite figure: the median is judged, the range reported."""


def cli() -> list[str]:
    """The command that runs crosscheck in a subprocess (the venv's script when there is one)."""
    script = Path(sys.executable).parent / "crosscheck"
    return [str(script)] if script.exists() else [sys.executable, "-m", "crosscheck.cli"]


def available() -> list[str]:
    """Every registered engine that can run here."""
    names = []
    for name in adapters.names():
        try:
            if adapters.get(name).available() is None:
                names.append(name)
        except Exception:
            continue
    return names


def _engines(names: Sequence[str]) -> list[str]:
    return [arg for name in names for arg in ("--engine", name)]


def spread(values: Sequence[float]) -> dict[str, float]:
    """Median, quartiles, extremes and count of ``values``."""
    s = timings.spread(values)
    return {"median": s.median, "q1": s.q1, "q3": s.q3, "min": float(min(values)),
            "max": float(max(values)), "n": float(s.n)}


def _run(extra: Sequence[str], folder: Path) -> tuple[int, float, float, str]:
    return run_measured([*cli(), "run", *extra, "--out", str(folder)])


def _median_figure(name: str, walls: list[float], codes: list[int], limit: float,
                   tail: str) -> Figure:
    s = spread(walls)
    ok = all(code == 0 for code in codes) and s["median"] <= limit
    return Figure(name, s["median"], "s", f"<= {limit:g} s", ok, {"runs": walls, **s},
                  note=f"median of {len(walls)}, range {s['min']:.1f}-{s['max']:.1f} s"
                       + ("" if all(code == 0 for code in codes) else f"; {tail}"))


def suite_figures(quick: bool, keep: Path, full_runs: int = RUNS,
                  deep: bool = False) -> list[Figure]:
    """Suite wall times (each the median of :data:`RUNS` whole processes; ``make run`` and its
    counted twin ``full_runs`` times; ``make run-deep`` once, with ``deep``) and the peak
    memory of the standard runs; the last standard run is left in ``keep/full`` (with
    ``quick``: the last quick run of every variant in ``keep/quick-all``), the deep run in
    ``keep/deep``, for the report figures."""
    every = available()
    n = len(every)
    plan: list[tuple[str, list[str], str, float, int]] = [
        ("crosscheck run --quick (seven variants)", ["--quick", *_engines(SEVEN)], "quick",
         QUICK_S, RUNS),
        (f"crosscheck run --quick (every available variant: {n})",
         ["--quick", *_engines(every)], "quick-all", QUICK_ALL_S, RUNS),
        (f"make run ARGS=--quick: crosscheck run --repeat-check --quick (every available "
         f"variant: {n})", ["--repeat-check", "--quick", *_engines(every)], "first-look",
         FIRST_LOOK_S, RUNS)]
    if not quick:
        plan += [
            (f"make run: crosscheck run --repeat-check, standard tier (every available "
             f"variant: {n})", ["--repeat-check", *_engines(every)], "full", FULL_ALL_S,
             full_runs),
            (f"make run ARGS='--timer instructions', standard tier (every available variant: "
             f"{n})", ["--repeat-check", "--timer", "instructions", *_engines(every)],
             "counted", COUNTED_S, full_runs)]
    figures, peaks = [], []
    for label, extra, name, limit, runs in plan:
        walls, codes, tail = [], [], ""
        for k in range(runs):
            folder = keep / (name if k == runs - 1 else f"{name}-{k}")
            code, wall, peak, tail = _run(extra, folder)
            walls.append(wall)
            codes.append(code)
            peaks.append((label, peak))
        figures.append(_median_figure(f"suite time, {label}", walls, codes, limit, tail))
    label, peak = max(peaks, key=lambda p: p[1])
    figures.append(Figure("peak memory of a standard suite run (PSS, all processes)", peak,
                          "MB", f"<= {MEMORY_MB:g} MB", peak <= MEMORY_MB, {"runs": dict(peaks)},
                          note=f"largest: {label}; sampled every 0.1 s"))
    if deep and not quick:
        figures.append(deep_figure(keep / "deep", every))
    return figures


def deep_figure(folder: Path, every: Sequence[str]) -> Figure:
    """``make run-deep`` once: its time recorded, not judged (no target)."""
    code, wall, peak, tail = _run(["--deep", "--repeat-check", *_engines(every)], folder)
    note = f"one run; peak PSS {peak:.0f} MB" + ("" if code == 0 else f"; {tail}")
    return Figure(f"suite time, make run-deep: crosscheck run --deep --repeat-check (every "
                  f"available variant: {len(every)})", wall, "s", RECORDED, code == 0,
                  {"runs": [wall], "peak_mb": peak}, note=note)


def timed(command: Sequence[str], times: int) -> list[float]:
    """Wall seconds of ``command`` run ``times`` times (output discarded)."""
    walls = []
    for _ in range(times):
        start = time.perf_counter()
        subprocess.run(command, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       check=False)
        walls.append(time.perf_counter() - start)
    return walls


def help_figure() -> Figure:
    """``crosscheck --help``, twenty times."""
    s = spread(timed([*cli(), "--help"], 20))
    return Figure("crosscheck --help", s["median"], "s", f"<= {HELP_S} s",
                  s["median"] <= HELP_S, s,
                  note=f"median of 20, IQR {s['q1']:.3f}-{s['q3']:.3f} s")


def report_figure(folder: Path, limit: float = REPORT_S) -> Figure:
    """``crosscheck report`` of a stored run, whole process, :data:`RUNS` times."""
    walls = timed([*cli(), "report", str(folder)], RUNS)
    s = spread(walls)
    rows = sum(1 for _ in (folder / "results.jsonl").open(encoding="utf-8"))
    return Figure(f"crosscheck report of the {folder.name} run ({rows:,} rows)", s["median"],
                  "s", f"<= {limit:g} s", s["median"] <= limit, {"rows": rows, **s},
                  note=f"median of {RUNS}, range {s['min']:.2f}-{s['max']:.2f} s "
                       "(whole process)")


def report_size_figure(folder: Path) -> Figure:
    """The size of a stored run's report.html (what ``crosscheck report`` just wrote)."""
    mb = (folder / "report.html").stat().st_size / 1e6
    return Figure(f"report.html of the {folder.name} run", mb, "MB", f"<= {REPORT_MB:g} MB",
                  mb <= REPORT_MB, {"bytes": (folder / "report.html").stat().st_size})


def fresh_clone_figure(measurements: Path) -> Figure:
    """``make test`` on a fresh clone, as ``python -m tools.measure_setup --test`` measured it
    (docs/measurements/setup.json): read, not re-measured (it clones and builds a venv)."""
    try:
        data = json.loads(measurements.read_text(encoding="utf-8"))["make test"]
        seconds = float(data["seconds"])
        note = (f"measured {data['measured']} at commit "
                f"{str(data['machine'].get('git_commit', ''))[:12]} by python -m "
                "tools.measure_setup --test (one run; not re-measured here)")
    except (OSError, ValueError, KeyError, TypeError) as exc:
        return Figure("make test on a fresh clone", float("nan"), "s", "<= 240 s", False, {},
                      note=f"no measurement in {measurements}: {exc}")
    return Figure("make test on a fresh clone", seconds, "s", "<= 240 s", seconds <= 240.0,
                  data, note=note)


def figures(quick: bool, full_runs: int = RUNS,
            deep: bool = False) -> list[Callable[[], list[Figure]]]:
    """The steps of this module, in order, sharing one temporary folder for the runs."""
    keep = Path(tempfile.mkdtemp(prefix="crosscheck-bench-"))

    def report_step() -> list[Figure]:
        folder = keep / ("full" if (keep / "full").exists() else "quick-all")
        found = [report_figure(folder), report_size_figure(folder)]
        if (keep / "deep").exists():
            found.append(report_figure(keep / "deep", REPORT_DEEP_S))
        return [*found, fresh_clone_figure(ROOT / "docs" / "measurements" / "setup.json")]

    return [lambda: suite_figures(quick, keep, full_runs, deep), lambda: [help_figure()],
            report_step]
