"""The results table opens on the engines' most severe answers, not on their crashes and
errors on bad input: the data comes in that order, and the page keeps it until a header is
clicked."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from crosscheck.report.results_table import results_data
from crosscheck.report.style import templates
from tests.conftest import sphere
from tests.report.browser import opened


def row(case_id: str, engine: str, status: str, error: float = math.nan) -> dict[str, Any]:
    return {"case_id": case_id, "engine": engine, "quantity": "distance", "value": "1.0",
            "truth": "1.0", "error": error, "tolerance": 0.0, "status": status, "category": "",
            "reason": "", "query_s": math.nan, "query_iqr_s": math.nan, "twin_of": ""}


def test_the_data_puts_bad_input_rows_after_the_engines_answers() -> None:
    cases = {"nan": sphere(math.nan, 2.0, id="nan", tags=["bad-input"]),
             "small": sphere(0.0, 1.0, id="small"), "large": sphere(0.0, 3.0, id="large"),
             "fine": sphere(0.0, 2.0, id="fine")}
    frame = pd.DataFrame([row("nan", "e", "crash"), row("fine", "e", "agree", 0.0),
                          row("small", "e", "disagree", 0.1), row("large", "e", "disagree", 2.0),
                          row("nan", "f", "agree", 0.0)])
    data = results_data(frame, cases, set())
    order = [(data["cases"][r["case"]]["id"], r["engine"]) for r in data["rows"]]
    assert order == [("large", "e"), ("small", "e"), ("fine", "e"), ("nan", "e"), ("nan", "f")]


def test_the_table_keeps_the_datas_order_when_it_opens() -> None:
    html = templates().get_template("_disagreements.html.j2").render(
        packed="", dt_js="", dt_css="", rows=0, breaking=0, nondeterministic=0, quantities=[],
        cases=0)
    assert 'id="results-table"' in html and 'data-order="[]"' in html


@pytest.mark.browser
def test_the_page_opens_on_an_engines_disagreement_not_on_its_error_on_bad_input(
        fakes_dir: Path) -> None:
    """fake-off disagrees on every distance and errs on the NaN case: an error is more severe
    than a disagreement, yet the table opens on the disagreements."""
    with opened(fakes_dir / "report.html") as page:
        page.wait_for_selector("#results-table[data-ready]")
        ids = page.locator("#results-table tbody tr td.case a.case-id").all_inner_texts()
    assert set(ids[:4]) == {"s0", "s1", "s2", "s3"} and ids[-1] == "s-nan"
