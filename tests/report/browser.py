"""The browser the report tests read pages in: Debian's chromium driven by Playwright.

Outside CI a test that needs it is skipped when chromium is missing; in CI (``CI`` set) a
missing browser fails it (``make test`` installs chromium when it can).
"""

from __future__ import annotations

import contextlib
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Page, sync_playwright

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"]


def needs_chromium() -> None:
    """Skip without chromium, but fail in CI, where make test installs it."""
    if CHROMIUM is None:
        if os.environ.get("CI"):
            pytest.fail("chromium is required in CI for the browser test (make test installs it)")
        pytest.skip("chromium not installed")


@contextlib.contextmanager
def opened(page_file: Path, messages: list[str] | None = None,
           width: int = 1400) -> Iterator[Page]:
    """``page_file`` open in headless chromium at ``width`` x 1000; console lines and page
    errors go to ``messages`` (as ``"<type>: <text>"``)."""
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page(viewport={"width": width, "height": 1000})
        if messages is not None:
            page.on("console", lambda m: messages.append(f"{m.type}: {m.text}"))
            page.on("pageerror", lambda e: messages.append(f"pageerror: {e}"))
        page.goto(page_file.as_uri())
        try:
            yield page
        finally:
            browser.close()
