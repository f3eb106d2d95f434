"""The one-parse reader of a run's JSON-lines files reads what a line-by-line read does."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.results.jsonlines import by_column, each_distinct, parse_lines


def test_a_whole_file_is_every_line_parsed(tmp_path: Path) -> None:
    rows = [{"a": 1, "b": "x"}, {"a": 2.5, "b": None}, {"a": [1, 2], "b": "NaN"}]
    path = tmp_path / "rows.jsonl"
    path.write_text("".join(json.dumps(r) + "\n" for r in rows) + "\n  \n", encoding="utf-8")
    assert parse_lines(path) == rows


def test_a_half_written_last_line_is_left_out(tmp_path: Path) -> None:
    path = tmp_path / "rows.jsonl"
    path.write_text('{"a": 1}\n{"a": NaN}\n{"a": 3, "b', encoding="utf-8")
    parsed = parse_lines(path)
    assert parsed[0] == {"a": 1} and math.isnan(parsed[1]["a"]) and len(parsed) == 2


def test_lines_that_only_join_into_json_are_not_taken_as_rows(tmp_path: Path) -> None:
    path = tmp_path / "rows.jsonl"
    path.write_text('{"a": 1}\n1, 2\n', encoding="utf-8")  # one row: "1, 2" is no JSON line
    assert parse_lines(path) == [{"a": 1}]


def test_a_missing_file_has_no_rows(tmp_path: Path) -> None:
    assert parse_lines(tmp_path / "none.jsonl") == []


def test_columns_fill_a_missing_field_as_the_frame_constructor_does() -> None:
    rows: list[dict[str, Any]] = [{"a": 1, "b": "x"}, {"a": 2}]
    built = pd.DataFrame(by_column(rows, ("a", "b")), columns=["a", "b"])
    pd.testing.assert_frame_equal(built, pd.DataFrame(rows, columns=["a", "b"]))


def test_each_distinct_value_is_mapped_once() -> None:
    calls: list[str] = []

    def upper(text: str) -> str:
        calls.append(text)
        return text.upper()

    mapped = each_distinct(pd.Series(["a", "b", "a", "a"], index=[3, 4, 5, 6]), upper)
    assert mapped.tolist() == ["A", "B", "A", "A"] and mapped.index.tolist() == [3, 4, 5, 6]
    assert calls == ["a", "b"]
