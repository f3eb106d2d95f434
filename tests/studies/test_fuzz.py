"""The fuzzer: deterministic generation in the intended regimes, real runs, grouped case files."""

from __future__ import annotations

import argparse
import csv
import json
import math
import tomllib
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from crosscheck.cases import writer as casewriter
from crosscheck.cases.load import load_paths, semantic_problems
from crosscheck.cases.writer import case_block
from crosscheck.cli import fuzz as fuzz_command
from crosscheck.cli import main
from crosscheck.core.kinds import spec
from crosscheck.core.model import PAIR_KINDS, Kind, Status
from crosscheck.core.schema import CASE_ADAPTER, AabbCase, AnyCase, ResponseCase
from crosscheck.studies.fuzz import generator as fuzzgen
from crosscheck.studies.fuzz.findings import (
    choose,
    group_findings,
    write_findings,
)
from crosscheck.truth import oracle
from crosscheck.truth.categories import approach_speed
from reference_impl import exact

KINDS = [Kind(k) for k in PAIR_KINDS]  # scenes are not fuzzed
ENGINES = ["reference-f32", "fcl"]


def texts(gens: list[fuzzgen.Generated]) -> list[str]:
    return [case_block(g.case) for g in gens]


@pytest.mark.parametrize("kind", KINDS)
def test_generation_is_deterministic_per_seed_and_differs_across_seeds(kind: Kind) -> None:
    first = texts(fuzzgen.generate(kind, 60, seed=7))
    assert first == texts(fuzzgen.generate(kind, 60, seed=7))
    other = texts(fuzzgen.generate(kind, 60, seed=8))
    assert sum(a != b for a, b in zip(first, other, strict=True)) == 60
    assert texts(fuzzgen.generate(kind, 20, seed=7)) == first[:20]  # a longer run extends


@pytest.mark.parametrize("kind", KINDS)
def test_generated_cases_are_valid_with_stable_ids_and_families(kind: Kind) -> None:
    gens = fuzzgen.generate(kind, 300, seed=3)
    stem = kind.value.replace("_", "-")
    assert [g.case.id for g in gens] == [f"fuzz-{stem}-s3-{i}" for i in range(300)]
    for g in gens:
        assert semantic_problems(g.case) == [], g.case.id
        assert g.case.tags == ("fuzz", *g.parts) and g.parts[0] == g.family
        assert g.case.description.startswith(f"fuzz {g.family}")
        assert g.driver == fuzzgen.DRIVER[g.family]
    assert {g.family for g in gens} == {"space", *spec(kind).fuzz}
    assert {g.case.dim for g in gens} == {2, 3}
    words = " ".join(g.case.description for g in gens)
    assert "ulps per coordinate" in words and "B moved by relative gap" in words


def size(case: AnyCase) -> float:
    if isinstance(case, AabbCase):
        return max(x + y for x, y in zip(case.a.half, case.b.half, strict=True))
    return case.a.radius + case.b.radius


def signed_distance(case: AnyCase) -> float:
    if isinstance(case, ResponseCase):
        contact = exact.sphere_contact(case.a.center, case.a.radius, case.b.center, case.b.radius)
        distance = getattr(contact, "distance", math.nan)
    else:
        distance = oracle.truth(case).distance
    assert isinstance(distance, float)
    return distance


@pytest.mark.parametrize("kind", KINDS)
def test_cases_land_in_their_regimes(kind: Kind) -> None:
    gens = fuzzgen.generate(kind, 300, seed=11)
    near = [g for g in gens if "near-touching" in g.parts]
    assert len(near) > 60  # half the cases come from the configuration space
    for g in near:
        assert abs(signed_distance(g.case)) / size(g.case) < 0.1, g.case.id
    tiny = [g for g in near if g.family == "near-touching" and abs(g.value) < 1e-12]
    assert tiny, "some gaps are within a few ulps of touching"
    for g in gens:
        centres = [abs(x) for x in (*g.case.a.center, *g.case.b.center)]
        if g.family == "near-touching":  # boxes: over the touching axes' size, not the largest
            relative = signed_distance(g.case) / size(g.case)
            assert g.value == relative if kind is not Kind.AABB else (
                abs(g.value) >= abs(relative) and g.value * relative >= 0)
        if g.family == "scaled":
            assert 1e-9 <= g.value <= 1e9 and 0.09 * g.value <= size(g.case) <= 2.1 * g.value
        if g.family == "offset":
            assert 1 <= g.value <= 1e15 and max(centres) >= 0.5 * g.value
        if isinstance(g.case, ResponseCase):
            masses = sorted([g.case.a.mass, g.case.b.mass])
            assert g.case.restitution in (0.0, 0.5, 1.0)
            if g.family == "mass-ratio":
                assert math.isclose(masses[1] / masses[0], g.value, rel_tol=1e-9)
            if "offset" not in g.parts and g.family != "space":  # space: offsets round
                assert approach_speed(g.case) > 0, g.case.id


def test_decade_labels() -> None:
    case = fuzzgen.generate(Kind.SPHERE, 1, seed=0)[0].case
    labels = [fuzzgen.Generated(case, "near-touching", ("near-touching",), "relative gap", v, 0)
              .decade for v in (-3.2e-9, 0.0, 2e12, 1.0)]
    assert labels == ["1e-09", "0", "1e+12", "1e+00"]


@pytest.mark.parametrize("kind", KINDS)
def test_case_blocks_round_trip_exactly(kind: Kind) -> None:
    for g in fuzzgen.generate(kind, 150, seed=5):
        block = tomllib.loads(case_block(g.case))["case"][0]
        assert CASE_ADAPTER.validate_python(block) == g.case


# --- real runs ------------------------------------------------------------------------------

def fuzz_cli(*argv: str) -> int:
    parser = argparse.ArgumentParser(prog="crosscheck")
    fuzz_command.register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["fuzz", *argv])
    code: int = args.func(args)
    return code


ARGS = ["--kind", "sphere", "--n", "200", "--seed", "1", "--jobs", "2", "--per-group", "3",
        *[x for name in ENGINES for x in ("--engine", name)]]


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    first, second = (tmp_path_factory.mktemp(name) / "out" for name in ("one", "two"))
    assert fuzz_cli(*ARGS, "--out", str(first)) == 0
    assert fuzz_cli(*ARGS, "--out", str(second)) == 0
    return first, second


def findings(directory: Path) -> list[dict[str, str]]:
    with (directory / "findings.csv").open(encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


@pytest.mark.engine
def test_real_run_finds_disagreements_and_writes_valid_case_files(runs: tuple[Path, Path]
                                                                   ) -> None:
    directory = runs[0]
    rows = findings(directory)
    assert {r["engine"] for r in rows if r["status"] == "disagree"} == set(ENGINES)
    assert any(r["category"] == "error" for r in rows)  # beyond every declared tolerance
    files = sorted(directory.glob("*.toml"))
    loaded = load_paths(files)
    assert loaded.errors == [] and files
    written = [c for c in loaded.cases if "swapped" not in c.tags]
    ids = [c.id for c in written]
    assert len(ids) == len(set(ids))  # each case written once across all files
    by_id = {g.case.id: g.case for g in fuzzgen.generate(Kind.SPHERE, 200, seed=1)}
    shrunk = [c for c in written if "shrunk" in c.tags]
    assert shrunk  # each group's first representative, shrunk (tests/studies/test_fuzz_shrink)
    for case in written:
        if case in shrunk:
            original = case.id.removesuffix("-shrunk")
            assert ids[ids.index(case.id) + 1] == original  # just before its original
            assert case.description.startswith(f"Shrunk from {original} in ")
            continue
        assert case.model_dump() == by_id[case.id].model_dump() | {
            "description": case.description}  # the inputs exactly; the findings added
        assert case.description.startswith(by_id[case.id].description + ". Found: ")
        assert "vs truth" in case.description or "crash" in case.description
    for path in files:
        text = path.read_text()
        assert text.startswith("#:schema ./schema.json\n# Fuzz findings, group")
        assert "Found by: crosscheck fuzz --kind sphere --n 200 --seed 1" in text
        assert 1 <= text.count("[[case]]") - text.count("-shrunk\"") <= 3
    assert main(["validate", str(directory)]) == 0
    info = json.loads((directory / "fuzz.json").read_text())
    assert sum(sum(c.values()) for c in info["counts"].values()) == 200 * 3 * len(ENGINES)
    assert sum(v for c in info["counts"].values() for k, v in c.items()
               if k.split()[1] in Status.members("breaking")) == len(rows)  # all listed


@pytest.mark.engine
def test_same_seed_gives_byte_identical_outputs(runs: tuple[Path, Path]) -> None:
    first, second = runs
    names = sorted(p.name for p in first.glob("*.toml"))
    assert names == sorted(p.name for p in second.glob("*.toml"))
    for name in [*names, "findings.csv"]:
        assert (first / name).read_bytes() == (second / name).read_bytes(), name


@pytest.mark.engine
def test_refuses_a_folder_with_output_and_unknown_engines(runs: tuple[Path, Path],
                                                          tmp_path: Path) -> None:
    assert fuzz_cli(*ARGS, "--out", str(runs[0])) == 2
    with pytest.raises(SystemExit) as refused:  # argparse: not one of the engine names
        fuzz_cli("--kind", "aabb", "--n", "3", "--seed", "0", "--engine", "nope",
                 "--out", str(tmp_path / "x"))
    assert refused.value.code == 2
    assert not (tmp_path / "x").exists()


# --- grouping -------------------------------------------------------------------------------

def synthetic(gens: list[fuzzgen.Generated]) -> pd.DataFrame:
    """Two engines disagree on every case: many findings, few group keys."""
    rows: list[dict[str, Any]] = []
    for g in gens:
        for engine in ("e1", "e2"):
            rows.append({"case_id": g.case.id, "engine": engine, "kind": "sphere", "dim": 3,
                         "quantity": "hit", "status": "disagree", "category": "error",
                         "value": "true", "truth": "false", "error": 1.0 + g.index % 7,
                         "tolerance": 0.0, "reason": "r"})
    return pd.DataFrame(rows)


def test_grouping_caps_files_and_cases_per_file(tmp_path: Path) -> None:
    gens = [g for g in fuzzgen.generate(Kind.SPHERE, 800, seed=2) if g.family == "near-touching"]
    frame = synthetic(gens)
    groups = write_findings(tmp_path, {g.case.id: g for g in gens}, frame, "cmd", per_group=4)
    files = list(tmp_path.glob("*.toml"))
    assert len(frame) > 300 and len(groups) < 10 and len(files) <= len(groups)
    assert sum(g.count for g in groups) == len(frame)
    for g in groups:
        assert len(g.chosen) <= 4
        assert len({(r["engine"], r["quantity"], r["category"]) for r in g.rows}) == 1
        assert len({meta_decade(gens, r["case_id"]) for r in g.rows}) > 1  # decades share a file
        errors = [r["error"] for r in g.rows]
        assert errors == sorted(errors, reverse=True)  # representatives: the largest errors
    written = [c.id for c in load_paths(files).cases if "swapped" not in c.tags]
    assert len(written) == len(set(written)) == sum(len(g.chosen) for g in groups)
    assert len(findings(tmp_path)) == len(frame)


def meta_decade(gens: list[fuzzgen.Generated], case_id: str) -> str:
    return next(g.decade for g in gens if g.case.id == case_id)


def test_small_groups_choose_first_and_no_case_is_chosen_twice() -> None:
    gens = [g for g in fuzzgen.generate(Kind.SPHERE, 60, seed=4) if g.family == "near-touching"]
    frame = synthetic(gens)
    frame.loc[frame["engine"] == "e2", "quantity"] = "distance"
    frame = pd.concat([frame, frame.iloc[:1].assign(engine="e3")], ignore_index=True)
    groups = group_findings(frame, {g.case.id: g for g in gens})
    owner = choose(groups, per_group=2)
    lonely = next(g for g in groups if g.engine == "e3")
    assert lonely.chosen == [frame.iloc[0]["case_id"]]  # its only case, before bigger groups
    assert len(owner) == sum(len(g.chosen) for g in groups)
    assert all(owner[c] is g for g in groups for c in g.chosen)
    assert casewriter.SCHEMA_LINE == "#:schema ./schema.json"


def test_findings_within_declared_tolerance_are_listed_not_written(tmp_path: Path) -> None:
    gens = [g for g in fuzzgen.generate(Kind.SPHERE, 40, seed=5) if g.family == "near-touching"]
    frame = synthetic(gens).assign(category="tolerance")
    groups = write_findings(tmp_path, {g.case.id: g for g in gens}, frame, "cmd", per_group=4)
    assert groups and all(g.rows and not g.chosen for g in groups)
    assert list(tmp_path.glob("*.toml")) == []
    assert len(findings(tmp_path)) == len(frame)
