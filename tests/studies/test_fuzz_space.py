"""The fuzzer's ``space`` family: cases drawn from the whole configuration space, biased
toward cells where an engine already failed."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest

from crosscheck.cases.load import semantic_problems
from crosscheck.cases.space import classify
from crosscheck.core.model import Kind
from crosscheck.studies.fuzz import stored_plan
from crosscheck.studies.fuzz.bias import BiasError, bias_from
from crosscheck.studies.fuzz.campaign import stored_bias
from crosscheck.studies.fuzz.generator import SPACE_SHARE, failing_cells, generate
from tests.studies.test_fuzz import fuzz_cli


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


def test_a_campaign_biased_by_another_stores_its_bias_and_resumes_it(tmp_path: Path) -> None:
    first, second = tmp_path / "first", tmp_path / "second"
    base = ["--kind", "sphere_toi", "--n", "200", "--seed", "3", "--engine", "reference",
            "--no-shrink"]  # float64 sampled at the interval's ends: some rows are errors
    assert fuzz_cli(*base, "--out", str(first)) == 0
    bias = bias_from(first)
    assert bias and {(kind, dim) for kind, dim, _ in bias} <= {("sphere_toi", 2),
                                                               ("sphere_toi", 3)}
    assert fuzz_cli(*base, "--bias", str(first), "--out", str(second)) == 0
    plan = json.loads((second / "campaign.json").read_text())
    assert len(plan["bias"]) == len(bias) and "--bias" in plan["command"]
    assert stored_plan(second)["bias"] == plan["bias"]
    campaign_bias = stored_bias(plan["bias"])
    assert campaign_bias == bias  # what resume regenerates the chunks with


def test_bias_must_be_a_run_or_a_campaign(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                          ) -> None:
    code = fuzz_cli("--kind", "aabb", "--n", "3", "--seed", "0", "--bias", str(tmp_path),
                    "--out", str(tmp_path / "x"))
    assert code == 2 and not (tmp_path / "x").exists()
    assert f"--bias {tmp_path}: not a stored run" in capsys.readouterr().err.replace("\n", "")
    with pytest.raises(BiasError):
        bias_from(tmp_path)
