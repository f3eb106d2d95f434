"""A report page's size and load figures in headless Chromium, written as JSON for the docs.

    python -m tools.measure_report reports/<run>            # the run's report.html
    python -m tools.measure_report reports/<run>/report.html --screenshot docs/images/report.png

Loads the page ``--loads`` times (default 7) in a fresh tab at 1400 x 1000 and measures,
from the navigation's start: the load event, the first chart drawn, and every chart drawn;
and whether the page overflows its width.  Relative paths are taken from the current
folder.  The figures go to ``docs/measurements/report-load.json`` (``--output``) with the
page's size and SHA-256, the machine and the commit, so ``make docs-figures`` uses them
only for the very report they measured.  Needs Playwright and Debian's chromium
(``make browser`` installs it).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import statistics
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from crosscheck.results.runinfo import now
from crosscheck.run import environment

ROOT = Path(__file__).resolve().parent.parent
OUTPUT = ROOT / "docs" / "measurements" / "report-load.json"
VIEWPORT = {"width": 1400, "height": 1000}
ARGS = ["--no-sandbox", "--disable-gpu"]
FIRST_CHART = "document.querySelectorAll('.plotly-graph-div .main-svg').length >= 1"


def page_of(target: Path) -> Path:
    """The report page of ``target``: the file itself, or ``report.html`` in a run folder."""
    page = target / "report.html" if target.is_dir() else target
    if not page.is_file():
        raise SystemExit(f"error: {page} does not exist (give a run folder or its report.html)")
    return page.resolve()  # a file URI needs an absolute path


def sha256(path: Path) -> str:
    """The SHA-256 of a file's bytes, in hex."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def measure(page: Path, loads: int, screenshot: Path | None) -> dict[str, Any]:
    """Load ``page`` ``loads`` times; the seconds to each milestone per load, chart count and
    overflow in pixels."""
    from playwright.sync_api import sync_playwright

    chromium = shutil.which("chromium") or "/usr/bin/chromium"
    times: dict[str, list[float]] = {"load_s": [], "first_chart_s": [], "all_charts_s": []}
    charts = overflow = 0
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=ARGS)
        for i in range(loads):
            tab = browser.new_page(viewport=VIEWPORT)  # type: ignore[arg-type]
            start = time.perf_counter()
            tab.goto(page.as_uri(), wait_until="load")
            times["load_s"].append(time.perf_counter() - start)
            charts = tab.locator(".plotly-graph-div").count()
            tab.wait_for_function(FIRST_CHART, timeout=60_000)
            times["first_chart_s"].append(time.perf_counter() - start)
            tab.wait_for_function(
                f"document.querySelectorAll('.js-plotly-plot').length >= {charts}",
                timeout=120_000)
            times["all_charts_s"].append(time.perf_counter() - start)
            overflow = int(tab.evaluate("document.documentElement.scrollWidth - window.innerWidth"))
            if screenshot is not None and i == 0:
                tab.screenshot(path=str(screenshot))
            tab.close()
        browser.close()
    return {"charts": charts, "overflow_px": overflow, **times}


def summary(values: Sequence[float]) -> str:
    """Median, min and max of seconds: 'median 0.51 s (min 0.44, max 0.59, n=7)'."""
    return (f"median {statistics.median(values):.2f} s (min {min(values):.2f}, "
            f"max {max(values):.2f}, n={len(values)})")


def main(argv: Sequence[str] | None = None) -> int:
    """Measure, print the figures and write them to ``--output``."""
    cli = argparse.ArgumentParser(prog="python -m tools.measure_report", description=__doc__,
                                  formatter_class=argparse.RawDescriptionHelpFormatter)
    cli.add_argument("target", type=Path, help="a run folder or its report.html")
    cli.add_argument("--loads", type=int, default=7, help="page loads measured")
    cli.add_argument("--screenshot", type=Path, help="write the first load's view here (PNG)")
    cli.add_argument("--output", type=Path, default=OUTPUT, help="the JSON file to write")
    args = cli.parse_args(argv)
    page = page_of(args.target)
    figures = measure(page, args.loads, args.screenshot)
    record = {"report": str(args.target), "bytes": page.stat().st_size, "sha256": sha256(page),
              "loads": args.loads, "viewport": VIEWPORT, "browser": "headless Chromium",
              **figures, "measured": now(),
              "machine": environment.machine()}
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    print(f"size {record['bytes']:,} bytes; charts {figures['charts']}; "
          f"overflow {figures['overflow_px']} px")
    for key, label in (("load_s", "load event"), ("first_chart_s", "first chart drawn"),
                       ("all_charts_s", "all charts drawn")):
        print(f"{label}: {summary(figures[key])}")
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
