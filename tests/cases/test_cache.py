"""The case cache (crosscheck.cases.cache) never changes what loading gives: cached cases
equal a fresh load exactly; a changed file or loader, a corrupt entry or an error means
the file is validated again."""

from __future__ import annotations

import hashlib
import pickle
import struct
from pathlib import Path
from typing import Any

import pytest

from crosscheck.cases import cache as case_cache
from crosscheck.cases import load
from crosscheck.cases.load import LoadResult, load_paths
from tests.conftest import ROOT

CASE = """[[case]]
id = "c1"
description = "two spheres a gap apart"
kind = "sphere"
dim = 2
a = {{ center = [0.0, 0.0], radius = {radius} }}
b = {{ center = [2.0, 0.0], radius = 0.5 }}
"""


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh cache folder for the test (never the user's)."""
    where = tmp_path / "cache"
    monkeypatch.setenv("CROSSCHECK_CACHE", str(where))
    monkeypatch.delenv("CROSSCHECK_NO_CACHE", raising=False)
    return where


@pytest.fixture
def validated(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The files validated afresh (not taken from the cache), in order."""
    seen: list[str] = []
    fresh = load.load_text

    def counting(path: Path, text: str) -> Any:
        seen.append(path.name)
        return fresh(path, text)
    monkeypatch.setattr(load, "load_text", counting)
    return seen


def exactly(result: LoadResult) -> list[tuple[object, ...]]:
    """Everything a case is, NaN and -0.0 included (a NaN is never == itself in a copy)."""
    return [(type(c), repr(c), sorted(c.model_fields_set)) for c in result.cases]


def case_file(tmp_path: Path, radius: str = "0.5") -> Path:
    path = tmp_path / "c.toml"
    path.write_text(CASE.format(radius=radius), encoding="utf-8")
    return path


def test_the_cached_suite_equals_a_fresh_load_exactly(folder: Path, validated: list[str]) -> None:
    cases = ROOT / "cases"
    first = load_paths([cases])
    files = len(validated)
    cached = load_paths([cases])
    fresh = load_paths([cases], cache=False)
    assert files == len(first.files) > 10 and len(validated) == files + len(fresh.files)
    assert exactly(cached) == exactly(fresh) == exactly(first)
    assert (cached.blocks, cached.files, cached.errors) == (fresh.blocks, fresh.files, [])


def test_an_edited_file_loads_its_new_cases(tmp_path: Path, folder: Path,
                                            validated: list[str]) -> None:
    path = case_file(tmp_path)
    assert load_paths([path]).cases[0].a.radius == 0.5
    assert load_paths([path]).cases[0].a.radius == 0.5
    assert validated == ["c.toml"]
    path.write_text(CASE.format(radius="0.75"), encoding="utf-8")
    assert load_paths([path]).cases[0].a.radius == 0.75
    assert validated == ["c.toml", "c.toml"]


def test_a_changed_loader_validates_again(tmp_path: Path, folder: Path, validated: list[str],
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    path = case_file(tmp_path)
    load_paths([path])
    monkeypatch.setattr(case_cache, "code_hash", lambda: "another loader")
    load_paths([path])
    assert validated == ["c.toml", "c.toml"]


def entries(folder: Path) -> list[Path]:
    return sorted(folder.glob("*.pickle"))


@pytest.mark.parametrize("damage", ["truncate", "flip", "empty", "not-cases", "garbage",
                                    "a-radius"])
def test_a_corrupt_entry_is_validated_again(tmp_path: Path, folder: Path, validated: list[str],
                                            damage: str) -> None:
    path = case_file(tmp_path)
    want = exactly(load_paths([path]))
    [entry] = entries(folder)
    raw = entry.read_bytes()
    payload = pickle.dumps(case_cache.Entry(1, ["not a case"]))  # type: ignore[list-item]
    entry.write_bytes({"truncate": raw[:len(raw) // 2], "empty": b"",
                       "flip": raw[:-1] + bytes([raw[-1] ^ 1]),
                       "not-cases": hashlib.sha256(payload).digest() + payload,
                       "garbage": raw[:32] + b"\x80\x05garbage",  # a wrong case if unchecked:
                       "a-radius": raw.replace(struct.pack(">d", 2.0), struct.pack(">d", 3.0))
                       }[damage])
    assert entry.read_bytes() != raw
    assert exactly(load_paths([path])) == want
    assert validated == ["c.toml", "c.toml"]
    assert exactly(load_paths([path])) == want and len(validated) == 2  # the entry was repaired


def test_an_error_is_never_cached(tmp_path: Path, folder: Path, validated: list[str]) -> None:
    path = case_file(tmp_path, radius="-1.0")
    for _ in range(2):
        result = load_paths([path])
        assert result.cases == [] and "a.radius" in result.errors[0].message
    assert validated == ["c.toml", "c.toml"] and entries(folder) == []


def test_the_cache_can_be_turned_off(tmp_path: Path, folder: Path, validated: list[str],
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    path = case_file(tmp_path)
    load_paths([path], cache=False)
    monkeypatch.setenv("CROSSCHECK_NO_CACHE", "1")
    load_paths([path])
    assert validated == ["c.toml", "c.toml"] and not folder.exists()


def test_an_unwritable_folder_only_costs_the_speed_up(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("CROSSCHECK_CACHE", str(blocker / "cache"))
    path = case_file(tmp_path)
    assert exactly(load_paths([path])) == exactly(load_paths([path], cache=False))
