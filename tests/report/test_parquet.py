"""results.parquet: the same rows as results.csv, with typed values that need no parsing."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.core.options import RunOptions
from crosscheck.report.render import render
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.conftest import response, sphere

CASES = [sphere(0.0, 2.0, id="apart"), sphere(0.0, 0.0, id="coincident"),
         response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], id="resp")]


def test_parquet_holds_the_csv_rows_with_typed_values(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    options, engines = RunOptions(quick=True, isolate=False), [fakes.OffByOne()]
    launch(ResultsStore(folder), CASES, engines, options,
           new_info(folder, "test", options, engines, CASES))
    render(folder)
    table = pd.read_parquet(folder / "results.parquet")
    text = pd.read_csv(folder / "results.csv", keep_default_na=False, dtype=str)
    assert list(table["case_id"]) == list(text["case_id"]) and len(table) == 8
    for row in table.itertuples():
        cell = text.loc[row.Index, "value"]
        if row.quantity == "hit":
            assert row.value_bool == json.loads(cell)
        elif row.quantity == "distance":
            assert row.value_float == json.loads(cell)
        elif cell != "null":
            assert list(row.value_vector) == json.loads(cell)
    for cell in [*text["value"], *text["truth"]]:  # strict JSON: no NaN, Infinity, undefined
        json.loads(cell, parse_constant=not_strict)
    coincident = table[(table["case_id"] == "coincident") & (table["quantity"] == "normal")]
    assert coincident["truth_vector"].isna().all()  # undefined: null, the status says why
    assert (coincident["status"] == "undefined").all()
    assert table["query_s"].dtype == "float64" and math.isnan(table["query_s"].iloc[0])


def not_strict(token: str) -> None:
    pytest.fail(f"{token} is not strict JSON")
