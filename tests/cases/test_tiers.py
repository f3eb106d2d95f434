"""The suite's tiers: ``crosscheck run`` runs cases/ (standard), ``--deep`` adds cases-deep/;
the tier a run holds is in its run.json; the deep tier holds every standard case and more,
and the standard tier keeps every kind and dimension."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from crosscheck.cases.load import load_paths
from crosscheck.cases.tiers import tier_of
from crosscheck.cli import main
from tests.conftest import ROOT


def test_deep_runs_both_folders_and_run_json_says_which_tier(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "cases").mkdir()
    (tmp_path / "cases-deep").mkdir()
    shutil.copy(ROOT / "cases" / "sphere.toml", tmp_path / "cases")
    shutil.copy(ROOT / "cases" / "aabb.toml", tmp_path / "cases-deep")
    monkeypatch.chdir(tmp_path)
    for flags, tier, files in ((["--deep"], "deep", 2), ([], "standard", 1)):
        out = tmp_path / f"run-{tier}"
        assert main(["run", *flags, "--quick", "--engine", "reference", "--out", str(out)]) == 0
        info = json.loads((out / "run.json").read_text())
        assert info["tier"] == tier and len(info["case_files"]) == files


def test_the_deep_tier_holds_every_standard_case_and_the_standard_tier_every_kind() -> None:
    standard = load_paths([ROOT / "cases"])
    deep = load_paths([ROOT / "cases", ROOT / "cases-deep"])
    assert not standard.errors and not deep.errors
    ids = {c.id for c in standard.cases}
    assert ids < {c.id for c in deep.cases}
    assert {(c.kind, c.dim) for c in standard.cases} == {(c.kind, c.dim) for c in deep.cases}
    assert tier_of(deep.files) == "deep" and tier_of(standard.files) == "standard"
