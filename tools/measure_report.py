"""Measure a report page (python tools/measure_report.py PAGE [SCREENSHOT.png]) in headless chromium: load event, charts in view drawn, all charts drawn."""
import sys, time, statistics
from pathlib import Path
from playwright.sync_api import sync_playwright

page_file = Path(sys.argv[1]); shot = sys.argv[2] if len(sys.argv) > 2 else None
ARGS = ["--no-sandbox", "--disable-gpu"]
loads, views, alls = [], [], []
with sync_playwright() as p:
    browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
    for i in range(7):
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        t0 = time.perf_counter()
        page.goto(page_file.as_uri(), wait_until="load")
        loads.append(time.perf_counter() - t0)
        total = page.locator(".plotly-graph-div").count()
        page.wait_for_function("document.querySelectorAll('.plotly-graph-div .main-svg').length >= 1", timeout=60000)
        views.append(time.perf_counter() - t0)
        page.wait_for_function(f"document.querySelectorAll('.js-plotly-plot').length >= {total}", timeout=120000)
        alls.append(time.perf_counter() - t0)
        overflow = page.evaluate("document.documentElement.scrollWidth - window.innerWidth")
        if shot and i == 0:
            page.screenshot(path=shot)
        page.close()
    browser.close()
def s(xs): return f"median {statistics.median(xs):.2f} s (min {min(xs):.2f}, max {max(xs):.2f}, n={len(xs)})"
print(f"size {page_file.stat().st_size:,} bytes; charts {total}; overflow {overflow}px")
print("load event:", s(loads)); print("first chart drawn:", s(views)); print("all charts drawn:", s(alls))
