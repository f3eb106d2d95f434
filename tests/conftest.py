"""Shared fixtures: case builders, a temporary run directory, and :func:`wait_until`, the one
place a test reads a clock (a safety bound on waiting, never a measurement:
tests/test_no_measured_time.py)."""

from __future__ import annotations

import base64
import gzip
import json
import os
import re
import signal
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from crosscheck.core.schema import CASE_ADAPTER, AnyCase

ROOT = Path(__file__).resolve().parent.parent


def pytest_configure(config: pytest.Config) -> None:
    """Tests keep the case cache (crosscheck/cases/cache.py) in a folder of their own, so a
    test run never reads or fills the user's ~/.cache/crosscheck."""
    os.environ.setdefault("CROSSCHECK_CACHE", tempfile.mkdtemp(prefix="crosscheck-test-cache-"))


LONG_FILES = (
    "tests/run/test_cost.py", "tests/pytest_plugin/test_plugin.py",
    "tests/guarantees/test_ctrl_c.py", "tests/run/test_pinned.py",
    "tests/report/test_browser.py", "tests/studies/test_repro.py",
    "tests/studies/test_fuzz.py", "tests/adapters/test_plugins.py",
    "tests/studies/test_fuzz_campaign.py", "tests/cli/test_output_width.py",
    "tests/studies/test_bench_counted.py", "tests/guarantees/test_resume.py",
)
"""The files that take longest after the whole suite's (each over 20 s on a loaded 2-core
machine), longest first: started right after it, so that no long file is the last one left
while the other worker idles.  Only the order depends on this list, never a result."""


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The tests of the whole suite's run (marked ``suite``, all in
    tests/report/test_page_layout.py) first, then :data:`LONG_FILES`: under make test's
    ``pytest -n 2 --dist loadfile --no-loadscope-reorder`` one worker starts that long run at
    once while the other takes the long files, then both share the short ones (longest
    first), instead of a long file being the last one left."""
    def order(item: pytest.Item) -> tuple[bool, int]:
        file = item.nodeid.split("::", 1)[0]
        return (item.get_closest_marker("suite") is None,
                LONG_FILES.index(file) if file in LONG_FILES else len(LONG_FILES))

    items.sort(key=order)  # stable: a file's tests keep their order


def sphere(a: float, b: float, ra: float = 0.5, rb: float = 0.5, dim: int = 3,
           **extra: Any) -> AnyCase:
    """A sphere case with centres on the x axis."""
    pad = [0.0] * (dim - 1)
    return CASE_ADAPTER.validate_python({
        "id": extra.pop("id", "s"), "description": "d", "kind": "sphere", "dim": dim,
        "a": {"center": [a, *pad], "radius": ra}, "b": {"center": [b, *pad], "radius": rb},
        **extra})


def aabb(ca: list[float], ha: list[float], cb: list[float], hb: list[float],
         **extra: Any) -> AnyCase:
    """An AABB case."""
    return CASE_ADAPTER.validate_python({
        "id": extra.pop("id", "b"), "description": "d", "kind": "aabb", "dim": len(ca),
        "a": {"center": ca, "half": ha}, "b": {"center": cb, "half": hb}, **extra})


def response(pa: list[float], va: list[float], pb: list[float], vb: list[float],
             ma: float = 1.0, mb: float = 1.0, **extra: Any) -> AnyCase:
    """A sphere response case with radius 0.5 spheres."""
    return CASE_ADAPTER.validate_python({
        "id": extra.pop("id", "r"), "description": "d", "kind": "sphere_response",
        "dim": len(pa),
        "a": {"center": pa, "radius": 0.5, "mass": ma, "velocity": va},
        "b": {"center": pb, "radius": 0.5, "mass": mb, "velocity": vb}, **extra})


@pytest.fixture
def write_toml(tmp_path: Path) -> Any:
    """Write TOML text to a file in a temporary folder and return its path."""
    def write(text: str, name: str = "cases.toml") -> Path:
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        return path
    return write


def embedded(html: str, script_id: str) -> Any:
    """The JSON a report page carries packed (gzip + base64) in ``<script id=script_id>``."""
    match = re.search(rf'<script type="application/octet-stream" id="{script_id}">([^<]*)'
                      r"</script>", html)
    assert match, f"no packed script {script_id!r} in the page"
    return json.loads(gzip.decompress(base64.b64decode(match.group(1))).decode("utf-8"))


def wait_until(condition: Callable[[], bool], what: str, timeout_s: float = 60.0,
               poll_s: float = 0.05) -> None:
    """Poll ``condition`` until it holds; after ``timeout_s`` fail saying ``what`` never came.

    A safety bound, not a measurement: the limit only stops a test that would wait forever
    (a child that never writes, say), so it is generous, and nothing asserts how long the
    wait took.  ``condition`` may itself assert (a child that died early, say).
    """
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() >= deadline:
            raise AssertionError(f"{what} (gave up after {timeout_s:g} s)")
        time.sleep(poll_s)


def lines_in(path: Path) -> int:
    """The number of lines in ``path`` so far (0 while it does not exist)."""
    return path.read_text(encoding="utf-8").count("\n") if path.exists() else 0


def ctrl_c_delivered() -> None:
    """For a child process, before it starts (``Popen(preexec_fn=...)``): Ctrl-C acts as in a
    terminal (its default action), also when the tests were started with SIGINT ignored (a
    background job of a non-interactive shell, whose children inherit the ignoring)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.fixture
def ctrl_c_raises() -> Any:
    """Ctrl-C raises KeyboardInterrupt in this process for the test's duration (Python's own
    handler), also when the tests were started with SIGINT ignored; restored afterwards."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


def wait_for_rows(path: Path, rows: int = 1) -> None:
    """Wait (up to 60 s) for a running crosscheck to write ``rows`` lines to ``path``."""
    wait_until(lambda: lines_in(path) >= rows, f"{path} never reached {rows} rows")
