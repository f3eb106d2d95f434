"""The A/B symmetry check (:mod:`crosscheck.report.mirror`): the report lists every engine
answer on a swapped twin that does not mirror the original's, and only those."""

from __future__ import annotations

import pandas as pd

from crosscheck.report.mirror import asymmetries


def test_report_lists_engine_answers_that_do_not_mirror() -> None:
    rows = [
        {"case_id": "c", "engine": "e", "quantity": "normal", "value": "[0.6, 0.8]",
         "tolerance": 1e-9},
        {"case_id": "c.swapped", "twin_of": "c", "engine": "e", "quantity": "normal",
         "value": "[-0.6, -0.8]", "tolerance": 1e-9},
        {"case_id": "d", "engine": "e", "quantity": "v1", "value": "[1.0, 0.0]", "tolerance": 0.0},
        {"case_id": "d", "engine": "e", "quantity": "v2", "value": "[2.0, 0.0]", "tolerance": 0.0},
        {"case_id": "d.swapped", "twin_of": "d", "engine": "e", "quantity": "v1",
         "value": "[2.0, 0.0]",
         "tolerance": 0.0},
        {"case_id": "d.swapped", "twin_of": "d", "engine": "e", "quantity": "v2",
         "value": "[1.5, 0.0]",
         "tolerance": 0.0},
        {"case_id": "h", "engine": "e", "quantity": "hit", "value": "true", "tolerance": 0.0},
        {"case_id": "h.swapped", "twin_of": "h", "engine": "e", "quantity": "hit", "value": "false",
         "tolerance": 0.0},
    ]
    found = asymmetries(pd.DataFrame(rows).fillna({"twin_of": ""}))
    assert sorted(zip(found["case_id"], found["quantity"], strict=True)) == [
        ("d", "v1"), ("h", "hit")]


def test_identical_infinite_answers_mirror() -> None:
    rows = pd.DataFrame([
        {"case_id": "c", "engine": "e", "quantity": "distance", "value": "Infinity",
         "tolerance": 1e-9, "twin_of": ""},
        {"case_id": "c.swapped", "engine": "e", "quantity": "distance", "value": "Infinity",
         "tolerance": 1e-9, "twin_of": "c"},
        {"case_id": "d", "engine": "e", "quantity": "distance", "value": "Infinity",
         "tolerance": 1e-9, "twin_of": ""},
        {"case_id": "d.swapped", "engine": "e", "quantity": "distance", "value": "-Infinity",
         "tolerance": 1e-9, "twin_of": "d"}])
    assert asymmetries(rows)["case_id"].tolist() == ["d"]
