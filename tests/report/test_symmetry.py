"""The A/B symmetry check (:mod:`crosscheck.report.symmetry`): the report lists every engine
answer on a swapped twin that does not mirror the original's, and only those; its summary counts
them per engine x quantity, leaving out the pairs whose truth is undefined."""

from __future__ import annotations

import re
from typing import Any

import pandas as pd

from crosscheck.report import symmetry
from crosscheck.report.style import templates
from crosscheck.report.symmetry import asymmetries
from crosscheck.results.run import decoded


def row(case_id: str, quantity: str, value: str, engine: str = "e", tolerance: float = 0.0,
        status: str = "disagree") -> dict[str, Any]:
    """One result row; ``<id>.swapped`` is the twin of ``<id>``."""
    twin_of = case_id.removesuffix(".swapped") if case_id.endswith(".swapped") else ""
    return {"case_id": case_id, "engine": engine, "quantity": quantity, "value": value,
            "tolerance": tolerance, "status": status, "twin_of": twin_of}


def with_values(rows: list[dict[str, Any]]) -> pd.DataFrame:
    """The rows as a results frame with its values decoded, as the report reads a run."""
    frame = pd.DataFrame(rows)
    return frame.join(decoded(frame))


def test_report_lists_engine_answers_that_do_not_mirror() -> None:
    rows = [
        row("c", "normal", "[0.6, 0.8]", tolerance=1e-9),
        row("c.swapped", "normal", "[-0.6, -0.8]", tolerance=1e-9),
        row("d", "v1", "[1.0, 0.0]"), row("d", "v2", "[2.0, 0.0]"),
        row("d.swapped", "v1", "[2.0, 0.0]"), row("d.swapped", "v2", "[1.5, 0.0]"),
        row("h", "hit", "true"), row("h.swapped", "hit", "false"),
    ]
    found = asymmetries(with_values(rows))
    assert sorted(zip(found["case_id"], found["quantity"], strict=True)) == [
        ("d", "v1"), ("h", "hit")]


def test_identical_infinite_answers_mirror() -> None:
    rows = with_values([
        row("c", "distance", "Infinity", tolerance=1e-9),
        row("c.swapped", "distance", "Infinity", tolerance=1e-9),
        row("d", "distance", "Infinity", tolerance=1e-9),
        row("d.swapped", "distance", "-Infinity", tolerance=1e-9)])
    assert asymmetries(rows)["case_id"].tolist() == ["d"]


RUN = with_values([
    # e: one asymmetric hit (a), one mirrored hit (b), one asymmetric normal (n)
    row("a", "hit", "true"), row("a.swapped", "hit", "false"),
    row("b", "hit", "true"), row("b.swapped", "hit", "true"),
    row("n", "normal", "[1.0, 0.0]"), row("n.swapped", "normal", "[1.0, 0.0]"),
    # e: coincident centres, the normal's truth undefined: it does not mirror, not counted
    row("u", "normal", "[1.0, 0.0]", status="undefined"),
    row("u.swapped", "normal", "[1.0, 0.0]", status="undefined"),
    # f: every answer mirrors
    row("a", "hit", "true", engine="f"), row("a.swapped", "hit", "true", engine="f"),
])


def test_summary_counts_per_engine_and_quantity_without_undefined_truths() -> None:
    counts = symmetry.summary(symmetry.compared(RUN))
    cells = {e["engine"]: e["cells"] for e in counts["engines"]}
    assert cells == {"e": {"hit": [1, 2], "normal": [1, 1]}, "f": {"hit": [0, 1]}}
    assert (counts["asymmetric"], counts["compared"]) == (2, 4)
    assert counts["undefined"] == {"pairs": 1, "asymmetric": 1}


def test_the_csv_keeps_every_asymmetric_answer_and_marks_undefined_truths() -> None:
    found = asymmetries(RUN)
    assert list(found.columns[:6]) == ["case_id", "engine", "quantity", "value", "swapped_value",
                                       "expected_swapped"]
    assert dict(zip(found["case_id"], found["truth_undefined"], strict=True)) == {
        "a": False, "n": False, "u": True}


def test_the_section_shows_the_counts_and_folds_each_engines_cases() -> None:
    context = symmetry.section(RUN, ["f", "e"])
    page = templates().get_template("_symmetry.html.j2").render(**context)
    assert "A/B symmetry (2 asymmetric answers of 4 compared)" in page
    assert "Left out: 1 pair whose truth is undefined" in page
    assert "Every answer mirrors on f (1 pair)" in page
    table = page[page.index('<table id="symmetry">'):page.index("</table>")]
    assert re.findall(r"<b>(\d+)</b> / (\d+)", table) == [("1", "2"), ("1", "1"), ("2", "3")]
    folds = re.findall(r'<details class="symmetry-cases"[^>]*>', page)
    assert folds == ['<details class="symmetry-cases" data-engine="e">']  # closed: no "open"
    listed = page[page.index('data-engine="e"'):]
    assert listed.count('href="#case-') == 3  # a, n, and u marked as undefined
    assert "normal <small>(truth undefined)</small>" in listed
