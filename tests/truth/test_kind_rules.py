"""Truth finds each kind's exact truth and judge by the names its spec gives
(:mod:`crosscheck.core.kinds`), and its grouping of the scene quantities is the spec's list."""

from __future__ import annotations

import pytest

from crosscheck.core.kinds import SPECS, Kind, KindSpec, quantities_of
from crosscheck.testing import samples
from crosscheck.truth import oracle, scene_measures, scenes, score


@pytest.mark.parametrize("kind", SPECS, ids=lambda s: str(s.kind))
def test_the_truth_and_judge_a_spec_names_are_registered(kind: KindSpec) -> None:
    assert kind.truth in oracle.TRUTHS
    assert kind.judge in score.JUDGES


def test_every_registered_truth_and_judge_is_some_kinds() -> None:
    assert set(oracle.TRUTHS) == {s.truth for s in SPECS}
    assert set(score.JUDGES) == {s.judge for s in SPECS}


@pytest.mark.parametrize("kind", [k for k in Kind if k is not Kind.SPHERE_SCENE], ids=str)
def test_the_truth_of_a_kind_gives_its_quantities(kind: Kind) -> None:
    truth = oracle.truth(samples.first(kind, 3).case)
    assert all(truth.get(q) is not None for q in quantities_of(kind))


def test_the_scene_truths_groups_are_the_scene_kinds_quantities() -> None:
    assert quantities_of(Kind.SPHERE_SCENE) == scenes.QUANTITIES + scene_measures.MEASURES
