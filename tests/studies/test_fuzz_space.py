"""The fuzzer's ``space`` family: cases drawn from the whole configuration space, biased
toward cells where an engine already failed."""

from __future__ import annotations

from collections import Counter

from crosscheck.cases.load import semantic_problems
from crosscheck.cases.space import classify
from crosscheck.core.model import Kind
from crosscheck.studies.fuzz.generator import SPACE_SHARE, failing_cells, generate


def test_times_of_impact_are_fuzzed_from_the_space() -> None:
    made = generate(Kind.SPHERE_TOI, 300, 4)
    assert {g.family for g in made} == {"space"}
    assert all(not semantic_problems(g.case) for g in made)
    assert [g.case for g in made] == [g.case for g in generate(Kind.SPHERE_TOI, 300, 4)]
    cells = [classify(g.case) for g in made]
    assert {c.get("duration") for c in cells} == {"1e-3", "1", "1e3"}
    assert {c["direction"] for c in cells if c.get("direction")} >= {"+z", "-y", "oblique"}


def test_the_space_family_asks_far_apart_deep_and_off_axis_pairs() -> None:
    made = generate(Kind.AABB, 1000, 2)
    space = [g for g in made if g.family == "space"]
    assert abs(len(space) / len(made) - SPACE_SHARE) < 0.06
    cells = [classify(g.case) for g in space]
    gaps = Counter(c.get("gap") for c in cells)
    assert gaps["+1e3"] + gaps["+10"] >= 20 and gaps["deep"] >= 10
    directions = Counter(c.get("direction") for c in cells)
    assert min(directions[d] for d in ("+y", "-y", "+z", "-z", "diag-3")) >= 5
    assert Counter(c.get("size_ratio") for c in cells)["1e6"] >= 20


def test_a_bias_draws_more_cases_near_the_failing_cells() -> None:
    seeds = generate(Kind.AABB, 400, 9)
    failing = {g.case.id for g in seeds if g.family == "space" and g.case.dim == 3
               and classify(g.case).get("direction") == "-z"}
    bias = failing_cells([g.case for g in seeds], failing)
    assert bias and all(kind == "aabb" and dim == 3 for kind, dim, _ in bias)

    def share_at_minus_z(cases_bias: tuple[tuple[str, int, tuple[tuple[str, str], ...]], ...]
                         ) -> float:
        made = [g for g in generate(Kind.AABB, 2000, 5, cases_bias)
                if g.family == "space" and g.case.dim == 3]
        return sum(classify(g.case).get("direction") == "-z" for g in made) / len(made)

    plain, biased = share_at_minus_z(()), share_at_minus_z(bias)
    assert plain < 0.16 < 0.3 < biased  # 1 of 9 directions, against about half the cases
