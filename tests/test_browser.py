"""The report as a user sees it: rendered by headless Chromium, with no console errors.

Uses Debian's chromium (``make test`` installs it when it can) driven by
Playwright.  Outside CI the test is skipped when chromium is missing; in CI
(``CI`` set) a missing browser fails it.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from crosscheck.cli import main
from tests.conftest import ROOT

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"]
EVIL = "<script>window.__pwned = true</script>"


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if CHROMIUM is None:
        if os.environ.get("CI"):
            pytest.fail("chromium is required in CI for the browser test (make test installs it)")
        pytest.skip("chromium not installed")
    work = tmp_path_factory.mktemp("browser")
    cases = work / "cases.toml"
    text = (ROOT / "cases" / "sphere.toml").read_text()
    cases.write_text(text.replace('description = "', f'description = "{EVIL} ', 1))
    out = work / "run"
    assert main(["run", str(cases), "--engine", "reference", "--engine", "pymunk",
                 "--min-sample", "0.001", "--out", str(out)]) == 0
    return out


def test_report_renders_without_console_errors(run_dir: Path) -> None:
    from playwright.sync_api import sync_playwright

    messages: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        page.on("console", lambda m: messages.append(f"{m.type}: {m.text}"))
        page.on("pageerror", lambda e: messages.append(f"pageerror: {e}"))
        page.goto((run_dir / "report.html").as_uri())
        page.wait_for_load_state("load")
        page.screenshot(path=str(run_dir / "report.png"), full_page=True)
        tables = page.locator("table").count()
        charts = page.locator(".js-plotly-plot").count()
        rows = page.locator("#summary tbody tr").count()
        pwned = page.evaluate("window.__pwned === true")
        requests = page.evaluate("performance.getEntriesByType('resource').map(e => e.name)")
        browser.close()
    assert [m for m in messages if m.startswith(("error", "pageerror"))] == []
    assert (run_dir / "report.png").stat().st_size > 10_000
    assert tables >= 4 and rows == 2  # reference and pymunk, one kind
    assert charts >= 1
    assert not pwned, "a case description ran as script"
    assert [r for r in requests if r.startswith("http")] == []


@pytest.fixture(scope="module")
def timed_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A synthetic run folder with timings (timings.jsonl and run.json's timing), rendered."""
    if CHROMIUM is None:
        if os.environ.get("CI"):
            pytest.fail("chromium is required in CI for the browser test (make test installs it)")
        pytest.skip("chromium not installed")
    from crosscheck.report.render import render
    from tests.test_report import timed_run

    folder = timed_run(tmp_path_factory.mktemp("browser-timed") / "run")
    render(folder)
    return folder


def test_speed_points_show_their_timing_whiskers(timed_dir: Path) -> None:
    from playwright.sync_api import sync_playwright

    messages: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        page.on("console", lambda m: messages.append(f"{m.type}: {m.text}"))
        page.on("pageerror", lambda e: messages.append(f"pageerror: {e}"))
        page.goto((timed_dir / "report.html").as_uri())
        page.wait_for_load_state("load")
        page.screenshot(path=str(timed_dir / "report.png"), full_page=True)
        bars = page.locator("#speed-sphere g.errorbar").count()
        across = page.locator("#speed-sphere g.errorbar path.xerror").count()
        upward = page.locator("#speed-sphere g.errorbar path.yerror").count()
        legend = page.locator("#speed-sphere .legendtext").all_text_contents()
        timing = page.locator("#timing").count()
        browser.close()
    assert [m for m in messages if m.startswith(("error", "pageerror"))] == []
    assert bars >= 3  # fast, exact and noisy on the sphere chart
    assert across == 3 and upward == 3  # each point: its IQR across, its error whisker up
    assert "noisy (timing unstable)" in legend
    assert timing == 1
