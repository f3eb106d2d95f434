"""The advise section of a report page, read as a reader reads it: the command its form writes
for the fields filled, and the answers it shows for the standard profiles beside ``crosscheck
advise --json``'s for the same options.  Shared by the browser tests of small runs
(tests/report/test_browser.py, test_advise_form_space.py) and of the whole suite's run
(tests/report/test_page_layout.py)."""

from __future__ import annotations

import json
import shlex
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Page

from crosscheck.cli import main
from crosscheck.report.advise.page import FIELDS
from crosscheck.report.text import instructions_iqr, median_iqr, percent
from tests.report.browser import opened

REAL_PROFILES = [
    ({"dim": "3", "kind": "sphere", "scale": "0.01:10", "offset": "10",
      "tolerance": "1e-9", "angle": "1e-9"},
     ["--dim", "3", "--kind", "sphere", "--scale", "0.01:10", "--offset", "10",
      "--tolerance", "1e-9", "--angle-tolerance", "1e-9"]),
    ({"dim": "2", "kind": "sphere", "scale": "0.1:10", "offset": "1e3",
      "tolerance": "1e-6", "angle": "1e-6"},
     ["--dim", "2", "--kind", "sphere", "--scale", "0.1:10", "--offset", "1e3",
      "--tolerance", "1e-6", "--angle-tolerance", "1e-6"]),
    ({"kind": "sphere_response", "ratio": "1e3", "speed": "10", "offset": "1e3",
      "velocity": "1e-9"},
     ["--kind", "sphere_response", "--offset", "1e3", "--speed", "10", "--mass-ratio", "1e3",
      "--velocity-tolerance", "1e-9"]),
    ({"tolerance": "1e-6", "rtol": "1e-6", "quantities": "hit,distance", "touching": "on"},
     ["--tolerance", "1e-6", "--rtol", "1e-6", "--quantities", "hit,distance",
      "--touching-contact"]),
]
"""Form fields and the ``advise`` options they state (in the form's order)."""

FLAGS = {f.name for f in FIELDS if f.flag}


def fill(page: Page, fields: dict[str, str]) -> str:
    """Fill the advise form (every field not given is cleared) and return the command it
    writes."""
    for field in FIELDS:
        selector = f"#advise-form [name={field.name}]"
        if field.name in FLAGS:
            page.set_checked(selector, field.name in fields)
        elif field.name in ("dim", "kind"):
            page.select_option(selector, fields.get(field.name, ""))
        else:
            page.fill(selector, fields.get(field.name, ""))
    return str(page.locator("#advise-command").inner_text())


def shown(page: Page) -> dict[str, list[tuple[str, ...]]]:
    """Per standard profile (by its options), the rows of its answer table as (engine, then
    its cells from the tier on: tier, cases, within, and its cost)."""
    found: dict[str, list[tuple[str, ...]]] = page.evaluate("""() => Object.fromEntries(
        Array.from(document.querySelectorAll('#advise-out details.advise-profile')).map(d => [
            d.dataset.options, Array.from(d.querySelectorAll('tr[data-engine]')).map(r =>
                [r.dataset.engine].concat(Array.from(r.cells).slice(2, -1)
                                          .map(c => c.textContent)))]))""")
    return {options: [tuple(row) for row in rows] for options, rows in found.items()}


def errors(messages: list[str]) -> list[str]:
    return [m for m in messages if m.startswith(("error", "pageerror"))]


def cli_rows(run_dir: Path, options: list[str],
             capsys: pytest.CaptureFixture[str]) -> list[tuple[str, ...]]:
    """``advise --json``'s answer as the page's rows (:func:`shown`; none: no answer)."""
    capsys.readouterr()
    code = main(["advise", str(run_dir), *options, "--json"])
    out = capsys.readouterr().out
    if code != 0 and not out.strip():
        return []
    data = json.loads(out)
    if not data["cases"]:
        return []
    graded = [*data["passing"], *data["partial"], *data["failing"], *data["baselines"]]
    counted = any(e["median_query_instructions"] is not None for e in graded)
    tiers = {"passes": "pass", "partial": "part", "fails": "fail", "unsupported": "none"}
    return [(e["engine"], tiers[e["tier"]], str(e["answered"]), percent(e["share_within"]),
             *((counted_cell(e),) if counted else ()),
             "-" if e["median_query_s"] is None
             else median_iqr(e["median_query_s"], e["query_iqr_s"]))
            for e in graded]


def counted_cell(grade: dict[str, Any]) -> str:
    """A grade's instructions per query ± IQR as advise prints them ('-': not counted)."""
    median = grade["median_query_instructions"]
    return "-" if median is None else instructions_iqr(median, grade["query_instructions_iqr"])


def form_and_cli(run_dir: Path, profiles: list[tuple[dict[str, str], list[str]]],
                 capsys: pytest.CaptureFixture[str]
                 ) -> tuple[list[Any], list[Any], list[str]]:
    """The page's form and answers beside the command line's: per profile, the command the
    form writes and the answer rows ``advise --json`` gives for it; then, per standard
    profile, the page's rows and ``advise --json``'s; and the page's console errors."""
    messages: list[str] = []
    with opened(run_dir / "report.html", messages) as page:
        commands = [fill(page, fields) for fields, _ in profiles]
        answers = shown(page)
    found = [*commands, *answers.values()]
    expected = [*(shlex.join(["crosscheck", "advise", str(run_dir), *options])
                  for _, options in profiles),
                *(cli_rows(run_dir, shlex.split(options), capsys) for options in answers)]
    return found, expected, errors(messages)
