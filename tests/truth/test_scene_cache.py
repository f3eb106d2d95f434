"""The scene truths' disk cache (crosscheck.truth.scenes with crosscheck.core.disk_cache): a
stored exact run is read back exactly, never when the code or the entry changed, never
when caching is off."""

from __future__ import annotations

from pathlib import Path

import pytest

from crosscheck.core import disk_cache
from crosscheck.core.model import Observation
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.truth import scenes

CASE = CASE_ADAPTER.validate_python({
    "id": "two", "description": "two discs head on", "kind": "sphere_scene", "dim": 2,
    "duration": 1.0, "dt": 0.01, "bodies": [
        {"center": [0.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [1.0, 0.0]},
        {"center": [3.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [-1.0, 0.0]}]})
assert isinstance(CASE, SceneCase)


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("CROSSCHECK_CACHE", str(tmp_path))
    monkeypatch.delenv("CROSSCHECK_NO_CACHE", raising=False)
    monkeypatch.setattr(scenes, "_CACHE", {})
    return tmp_path / "truths"


def _computed(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Count the exact runs computed from here on (the disk cache's misses)."""
    computed: list[str] = []
    real = scenes._truth

    def counting(case: SceneCase) -> Observation:
        computed.append(case.id)
        return real(case)
    monkeypatch.setattr(scenes, "_truth", counting)
    return computed


def test_a_stored_truth_is_read_back_equal_without_computing_it(
        cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    computed = _computed(monkeypatch)
    first = scenes.truth(CASE)
    assert computed == ["two"] and len(list(cache.glob("*.pickle"))) == 1
    monkeypatch.setattr(scenes, "_CACHE", {})  # a new process: only the disk remains
    again = scenes.truth(CASE)
    assert computed == ["two"] and again == first and again is not first


def test_changed_code_or_a_corrupt_entry_is_computed_again(
        cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    computed = _computed(monkeypatch)
    first = scenes.truth(CASE)
    monkeypatch.setattr(scenes, "_CACHE", {})
    monkeypatch.setattr(scenes, "DISK_FORMAT", scenes.DISK_FORMAT + 1)  # as a code change
    scenes.truth(CASE)
    assert computed == ["two", "two"] and len(list(cache.glob("*.pickle"))) == 2
    for entry in cache.glob("*.pickle"):
        raw = entry.read_bytes()
        entry.write_bytes(raw[:-1] + bytes([raw[-1] ^ 1]))  # one bit changed: checksum fails
    monkeypatch.setattr(scenes, "_CACHE", {})
    assert scenes.truth(CASE) == first
    assert computed == ["two", "two", "two"]


def test_no_cache_computes_every_time_and_stores_nothing(
        cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CROSSCHECK_NO_CACHE", "1")
    computed = _computed(monkeypatch)
    scenes.truth(CASE)
    monkeypatch.setattr(scenes, "_CACHE", {})
    scenes.truth(CASE)
    assert computed == ["two", "two"] and disk_cache.folder("truths") is None
    assert not cache.exists()
