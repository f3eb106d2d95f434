"""Covering designs: ``[[cover]]`` blocks, what they cover, and coverage of any suite."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from crosscheck.cases.cover import coverage, expand_cover, plan_of
from crosscheck.cases.load import load_paths
from crosscheck.cases.space import classify
from crosscheck.core.model import Kind
from crosscheck.core.schema import CoverBlock

Write = Callable[..., Path]


def block(**fields: object) -> CoverBlock:
    return CoverBlock.model_validate({"id": "cv", "description": "d", **fields})


@pytest.mark.parametrize(("kind", "dim", "strength"), [
    ("aabb", 3, 2), ("aabb", 2, 3), ("sphere", 3, 2), ("sphere", 2, 2),
    ("sphere_response", 3, 2), ("sphere_toi", 3, 2), ("sphere_toi", 2, 3)])
def test_every_required_cell_is_covered_by_a_case_or_reported(kind: str, dim: int,
                                                              strength: int) -> None:
    cover = block(kind=kind, dim=dim, strength=strength)
    plan = plan_of(cover)
    design = expand_cover(cover)
    covered: set[tuple[tuple[str, str], ...]] = set()
    for case in design.cases:  # placed back by their geometry, not by their ids
        cell = {n: v for n, v in classify(case).items() if n in plan.names}
        covered |= {t for t in plan.tuples() if all(cell.get(n) == v for n, v in t)}
    assert covered | set(design.unreachable) == plan.tuples()
    assert not covered & set(design.unreachable)
    assert design.required == len(plan.tuples())
    assert len(design.unreachable) <= 0.03 * design.required


def test_a_strength_2_design_is_near_the_smallest_possible() -> None:
    design = expand_cover(block(kind="aabb", dim=3))
    assert 17 * 9 <= len(design.cases) <= 1.25 * 17 * 9  # gap levels x directions


def test_a_design_is_reproducible_and_its_seed_changes_it() -> None:
    ids = [c.id for c in expand_cover(block(kind="sphere", dim=2)).cases]
    assert ids == [c.id for c in expand_cover(block(kind="sphere", dim=2)).cases]
    assert ids != [c.id for c in expand_cover(block(kind="sphere", dim=2, seed=1)).cases]
    assert len(set(ids)) == len(ids)


def test_generated_cases_are_ordinary_cases(write_toml: Write) -> None:
    path = write_toml('[[cover]]\nid = "cv"\ndescription = "d"\nkind = "sphere"\ndim = 2\n'
                      'dimensions = ["direction", "gap"]\nlevels = { gap = ["0", "+1"] }\n')
    loaded = load_paths([path], cache=False)
    assert loaded.errors == [] and loaded.blocks == 0
    originals = [c for c in loaded.cases if not c.twin_of]
    assert all(c.origin == "cv" and "cover" in c.tags for c in originals)
    assert {c.id + ".swapped" for c in originals} == {c.id for c in loaded.cases if c.twin_of}
    assert "cv.dir=+y,gap=+1" in {c.id for c in originals}


@pytest.mark.parametrize(("extra", "field", "reason"), [
    ('dimensions = ["direction", "aspect"]', "dimensions",
     "sphere in 2-D has no dimension 'aspect'"),
    ('levels = { gap = ["+1e99"] }', "levels.gap", "no level ['+1e99'] of gap"),
    ('levels = { mass_ratio = ["1"] }', "levels.mass_ratio", "not one of the block's dimensions"),
    ("strength = 3\nstrong = [\"gap\", \"scale\"]", "strong", "strength 3 needs three"),
    ("strength = 4", "strength", ""),
    ('kind = "sphere_scene"', "kind", ""),
])
def test_a_malformed_block_names_file_block_field_and_reason(write_toml: Write, extra: str,
                                                             field: str, reason: str) -> None:
    text = '[[cover]]\nid = "bad"\ndescription = "d"\ndim = 2\n' + extra + "\n"
    if "kind =" not in extra:
        text += 'kind = "sphere"\n'
    path = write_toml(text)
    (error,) = load_paths([path], cache=False).errors
    assert error.message.startswith(f"{path}:")
    assert f"[[cover]] 'bad': field {field}: " in error.message
    assert reason in error.message
    assert error.line == next(i for i, line in enumerate(text.splitlines(), 1)
                              if line.startswith(field.split(".")[0]))


def test_coverage_counts_the_cells_of_any_cases() -> None:
    design = expand_cover(block(kind="aabb", dim=2, dimensions=["direction", "gap"],
                                levels={"gap": ["+1"]}))
    (aabb_2d,) = [c for c in coverage(design.cases) if (c.kind, c.dim) == (Kind.AABB, 2)]
    assert aabb_2d.cases == 6
    # direction x gap: 6 cells; every case also fills its default levels' pairs
    assert aabb_2d.covered == len({(n1, v1, n2, v2) for case in design.cases
                                   for (n1, v1) in classify(case).items()
                                   for (n2, v2) in classify(case).items() if n1 < n2})
    assert all(c.covered == 0 for c in coverage(design.cases) if c.kind is not Kind.AABB)
