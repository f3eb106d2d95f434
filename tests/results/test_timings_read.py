"""``read_timings`` parses an unchanged file once, and never hands out its kept copy."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pytest

from crosscheck.results import timings
from crosscheck.results.timings import FILE, TimingRecord, read_timings


def _record(case_id: str) -> str:
    return TimingRecord(case_id, "e", "sphere", "call", 1, 0.0,
                        values=(1.0, 2.0, 3.0)).to_json() + "\n"


def test_a_changed_file_is_read_again(tmp_path: Path) -> None:
    (tmp_path / FILE).write_text(_record("a"), encoding="utf-8")
    assert read_timings(tmp_path)["case_id"].tolist() == ["a"]
    with (tmp_path / FILE).open("a", encoding="utf-8") as handle:
        handle.write(_record("b"))
    assert read_timings(tmp_path)["case_id"].tolist() == ["a", "b"]


def test_an_unchanged_file_is_parsed_once_and_each_read_is_a_copy(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / FILE).write_text(_record("a"), encoding="utf-8")
    first = read_timings(tmp_path)
    first.loc[0, "median_s"] = -1.0
    parsed: list[object] = []
    original = timings.spread

    def counted(values: Sequence[float]) -> timings.Spread:
        parsed.append(values)
        return original(values)

    monkeypatch.setattr(timings, "spread", counted)
    again = read_timings(tmp_path)
    assert parsed == [] and again.loc[0, "median_s"] == 2.0


def test_no_file_is_no_rows(tmp_path: Path) -> None:
    assert read_timings(tmp_path).empty
