"""The bench's wall-clock figures: suite runs, ``--help`` and the report render, as subprocesses.

Every figure here is a command timed from outside, in its own session, so
that its imports, workers and report are all counted:

- ``crosscheck run --quick`` (three times: median and range) and the full
  ``crosscheck run`` with the seven engine variants the targets were set on
  (:data:`SEVEN`), and once each with every available engine, so that each
  engine added later shows its cost;
- the peak resident memory (PSS) of those runs;
- ``crosscheck --help`` (twenty times: median and quartiles);
- rendering the full run's report, timed inside a fresh interpreter around
  :func:`crosscheck.report.render.render` alone (the report layer is not
  imported here: a bench never renders in its own process).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

import adapters
from crosscheck.studies.bench.kit import ROOT, Figure, run_measured

SEVEN = ("reference", "reference-f32", "fcl", "pybullet", "pybullet-default", "pymunk",
         "pymunk-default")
"""The engine variants of the issue's targets (``--engine`` each)."""

QUICK_S, FULL_S, HELP_S, RENDER_S = 6.0, 45.0, 0.3, 1.0
"""Targets: ``run --quick``, the full run, ``--help`` and the report render (seconds)."""


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
    a = np.asarray(values, dtype=float)
    return {"median": float(np.median(a)), "q1": float(np.percentile(a, 25)),
            "q3": float(np.percentile(a, 75)), "min": float(a.min()), "max": float(a.max()),
            "n": float(len(a))}


def _run(extra: Sequence[str], folder: Path) -> tuple[int, float, float, str]:
    return run_measured([*cli(), "run", *extra, "--out", str(folder)])


def suite_figures(quick: bool, keep: Path) -> list[Figure]:
    """Suite wall times and peak memory; the full seven-engine run is left in ``keep/full``."""
    figures, peaks = [], []
    walls = []
    for n in range(3):
        code, wall, peak, tail = _run(["--quick", *_engines(SEVEN)], keep / f"quick-{n}")
        walls.append(wall)
        peaks.append(("--quick, seven", peak))
    s = spread(walls)
    figures.append(Figure(
        "suite time, crosscheck run --quick (seven variants)", s["median"], "s",
        f"<= {QUICK_S:.0f} s", code == 0 and s["median"] <= QUICK_S, {"runs": walls, **s},
        note=f"median of 3, range {s['min']:.1f}-{s['max']:.1f} s" + ("" if code == 0 else tail)))
    runs: list[tuple[str, list[str], str, float | None]] = [
        ("--quick, every available engine", ["--quick", *_engines(available())], "quick-all",
         None)]
    if not quick:
        runs = [("full, seven variants", _engines(SEVEN), "full", FULL_S),
                ("full, every available engine", _engines(available()), "full-all", None), *runs]
    for label, extra, name, limit in runs:
        code, wall, peak, tail = _run(extra, keep / name)
        peaks.append((label, peak))
        target = f"<= {limit:.0f} s" if limit else "reported"
        figures.append(Figure(f"suite time, crosscheck run ({label})", wall, "s", target,
                              code == 0 and (limit is None or wall <= limit),
                              {"returncode": code, "engines": extra[1::2]},
                              note="one run" + ("" if code == 0 else f"; {tail}")))
    label, peak = max(peaks, key=lambda p: p[1])
    figures.append(Figure("peak memory of a suite run (PSS, all processes)", peak, "MB",
                          "reported", True, {"runs": dict(peaks)},
                          note=f"largest: {label}; sampled every 0.1 s"))
    return figures


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


RENDER = """\
import json, sys, time
from pathlib import Path
from crosscheck.report.render import render
walls = []
for _ in range(3):
    start = time.perf_counter()
    render(Path(sys.argv[1]))
    walls.append(time.perf_counter() - start)
print(json.dumps(walls))
"""


def render_figure(folder: Path) -> Figure:
    """The report of a full run rendered three times in a fresh interpreter (render alone)."""
    done = subprocess.run([sys.executable, "-c", RENDER, str(folder)], cwd=ROOT,
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        return Figure("report render of the full run", float("nan"), "s", f"<= {RENDER_S} s",
                      False, {}, note=done.stderr[-300:])
    s = spread(json.loads(done.stdout.strip().splitlines()[-1]))
    return Figure("report render of the full run", s["median"], "s", f"<= {RENDER_S} s",
                  s["median"] <= RENDER_S, s,
                  note=f"median of 3, range {s['min']:.2f}-{s['max']:.2f} s (render() alone)")


def figures(quick: bool) -> list[Callable[[], list[Figure]]]:
    """The steps of this module, in order, sharing one temporary folder for the runs."""
    keep = Path(tempfile.mkdtemp(prefix="crosscheck-bench-"))

    def render_step() -> list[Figure]:
        folder = keep / ("full" if (keep / "full").exists() else "quick-0")
        return [render_figure(folder)]

    return [lambda: suite_figures(quick, keep), lambda: [help_figure()], render_step]
