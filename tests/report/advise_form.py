"""The advise form of a report page, filled as a reader fills it, and its answer set beside
``crosscheck advise --json``'s: shared by the browser tests of small runs
(tests/report/test_browser.py) and of the whole suite's run (tests/report/test_page_layout.py)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Page

from crosscheck.cli import main
from crosscheck.report.speed import instructions_iqr, median_iqr
from tests.report.browser import opened

REAL_PROFILES = [
    ({"dim": "3", "kind": "sphere", "lo": "0.01", "hi": "10", "offset": "10",
      "tolerance": "1e-9", "angle": "1e-9"},
     ["--dim", "3", "--kind", "sphere", "--scale", "0.01:10", "--offset", "10",
      "--tolerance", "1e-9", "--angle-tolerance", "1e-9"]),
    ({"dim": "2", "kind": "sphere", "lo": "0.1", "hi": "10", "offset": "1e3",
      "tolerance": "1e-6", "angle": "1e-6"},
     ["--dim", "2", "--kind", "sphere", "--scale", "0.1:10", "--offset", "1e3",
      "--tolerance", "1e-6", "--angle-tolerance", "1e-6"]),
    ({"kind": "sphere_response", "ratio": "1e3", "speed": "10", "offset": "1e3",
      "velocity": "1e-9"},
     ["--kind", "sphere_response", "--mass-ratio", "1e3", "--speed", "10", "--offset", "1e3",
      "--velocity-tolerance", "1e-9"]),
    ({"tolerance": "1e-6", "rtol": "1e-6", "quantities": "hit,distance"},
     ["--tolerance", "1e-6", "--rtol", "1e-6", "--quantities", "hit,distance"]),
]

FULL_PROFILES = [
    REAL_PROFILES[0],
    ({"dim": "3", "kind": "aabb", "lo": "0.1", "hi": "10", "offset": "1e4",
      "tolerance": "1e-4", "angle": "1e-4"},
     ["--dim", "3", "--kind", "aabb", "--scale", "0.1:10", "--offset", "1e4",
      "--tolerance", "1e-4", "--angle-tolerance", "1e-4"]),
    REAL_PROFILES[1],
    REAL_PROFILES[2],
]
"""The four scene profiles of docs/comparing-and-advice.md."""


def submit(page: Page, fields: dict[str, str]) -> list[tuple[str, ...]]:
    """Fill the advise form (every field not given is cleared), submit it and return the answer
    table's rows as (engine, tier, cover, within, and its cost: median ± IQR; or, where an
    engine was counted, instructions per query ± IQR and the wall clock's median ± IQR)."""
    for name in ("dim", "kind"):
        page.select_option(f"#advise-form select[name={name}]", fields.get(name, ""))
    for name in ("lo", "hi", "offset", "speed", "ratio", "dt", "travel", "lasts", "interval",
                 "tag", "tolerance", "rtol", "angle", "velocity", "time", "fraction",
                 "quantities"):
        page.fill(f"#advise-form input[name={name}]", fields.get(name, ""))
    page.click("#advise-go")
    page.wait_for_function("!/Judging/.test(document.getElementById('advise-out').textContent)")
    rows: list[tuple[str, ...]] = page.eval_on_selector_all(
        "#advise-out tr[data-engine]",
        "rows => rows.map(r => [r.dataset.engine].concat("
        " Array.from(r.cells).slice(2, -1).map(c => c.textContent)))")
    return [tuple(row) for row in rows]


def errors(messages: list[str]) -> list[str]:
    return [m for m in messages if m.startswith(("error", "pageerror"))]


def form_and_cli(run_dir: Path, profiles: list[tuple[dict[str, str], list[str]]],
                 capsys: pytest.CaptureFixture[str]) -> tuple[list[Any], list[Any], list[str]]:
    """Per profile: the form's answer rows, advise --json's as the same rows (:func:`submit`),
    and the page's console errors."""
    expected = []
    for _, options in profiles:
        capsys.readouterr()
        assert main(["advise", str(run_dir), *options, "--json"]) == 0
        data = json.loads(capsys.readouterr().out)
        graded = [*data["passing"], *data["partial"], *data["failing"], *data["baselines"]]
        counted = any(e["median_query_instructions"] is not None for e in graded)
        expected.append([
            (e["engine"], e["tier"], f"{e['coverage']:.0%}",
             "-" if e["share_within"] is None else f"{e['share_within']:.0%}",
             *((counted_cell(e),) if counted else ()),
             "-" if e["median_query_s"] is None
             else median_iqr(e["median_query_s"], e["query_iqr_s"]))
            for e in graded])
    messages: list[str] = []
    with opened(run_dir / "report.html", messages) as page:
        found = [submit(page, fields) for fields, _ in profiles]
    return found, expected, errors(messages)


def counted_cell(grade: dict[str, Any]) -> str:
    """A grade's instructions per query ± IQR as advise prints them ('-': not counted)."""
    median = grade["median_query_instructions"]
    return "-" if median is None else instructions_iqr(median, grade["query_instructions_iqr"])
