"""Every registered adapter passes the conformance kit, and the kit fails broken adapters.

The kit (:mod:`crosscheck.testing`) holds the contract's checks, so an engine's own CI runs
the same ones; here it runs on every built-in adapter, then on fakes that each break one
promise, to show that it catches them and says where.
"""

from __future__ import annotations

import ast
from dataclasses import replace
from typing import Any, ClassVar

import numpy as np
import pytest

import adapters
from crosscheck.core.contract import Adapter, Capability, Conventions, all_capabilities
from crosscheck.core.model import Kind, Observation
from crosscheck.core.schema import AnyCase
from crosscheck.testing import ConformanceError, check_adapter, conformance_failures
from crosscheck.testing.fakes import Conforming, Unavailable
from crosscheck.truth import oracle

OWN_FORMULA = {"reference", "reference-f32"}
"""The textbook formula cites the textbook's file in this repository, not a public link."""


@pytest.mark.parametrize("name", [
    pytest.param(name, marks=() if name in OWN_FORMULA else pytest.mark.engine)
    for name in adapters.names()])
def test_registered_adapter_passes_the_conformance_kit(name: str) -> None:
    check_adapter(adapters.adapter_class(name), name=name,
                  public_sources=name not in OWN_FORMULA)


def test_the_conforming_fake_passes_also_in_a_worker() -> None:
    assert conformance_failures(Conforming, public_sources=False) == []


# --- fakes that break one promise each (module level: a worker process imports them) ---------

class WrongNormal(Conforming):
    """Normals from B to A."""

    name: ClassVar[str] = "fake-wrong-normal"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        if isinstance(truth.normal, tuple):
            return replace(truth, normal=tuple(-x for x in truth.normal))
        return truth


class NoSources(Conforming):
    name: ClassVar[str] = "fake-no-sources"
    conventions: ClassVar[Conventions] = Conventions()


class MissingVelocity(Conforming):
    """Reports v1 but not v2."""

    name: ClassVar[str] = "fake-missing-v2"

    def query(self, prepared: Any) -> Observation:
        return replace(oracle.truth(prepared), v2=None)


class ExtraQuantity(Conforming):
    """Puts a velocity into its detection answers."""

    name: ClassVar[str] = "fake-extra"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        return truth if truth.v1 is not None else replace(truth, v1=(0.0,) * prepared.dim)


class AlwaysHits(Conforming):
    name: ClassVar[str] = "fake-always-hits"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        return truth if truth.hit is None else replace(truth, hit=True)


class NumpyVerdict(Conforming):
    """A numpy bool for a verdict (not a bool: it does not travel as JSON)."""

    name: ClassVar[str] = "fake-numpy-bool"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        return truth if truth.hit is None else replace(truth, hit=np.bool_(truth.hit))


class Drifts(Conforming):
    """Each query a little further off: not repeatable."""

    name: ClassVar[str] = "fake-drifts"
    calls: ClassVar[list[int]] = []

    def query(self, prepared: Any) -> Observation:
        self.calls.append(1)
        truth = oracle.truth(prepared)
        if isinstance(truth.distance, float):
            return replace(truth, distance=truth.distance + 1e-9 * len(self.calls))
        return truth


class ClaimsEverything(Conforming):
    """Spheres only, but never says it skips anything."""

    name: ClassVar[str] = "fake-claims-everything"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE)

    def unsupported(self, case: AnyCase) -> str | None:
        return None


class IllFormedConventions(Conforming):
    name: ClassVar[str] = "fake-ill-formed"
    conventions: ClassVar[Conventions] = Conventions(
        zero_mass="zero", damping=-1.0, time_step=0.0, margins={"face": -1.0},
        touching={"vertex": True}, sources=("somewhere",))


class HangsWithoutSaying(Conforming):
    """Names a known hang everywhere but no hanging quantity."""

    name: ClassVar[str] = "fake-hang-unsaid"

    def known_hang(self, case: AnyCase) -> str | None:
        return "loops"

    def hanging_quantities(self, case: AnyCase) -> frozenset[str]:
        return frozenset()


class NeedsArgument(Conforming):
    name: ClassVar[str] = "fake-needs-argument"

    def __init__(self, path: str) -> None:
        self.path = path


class NotAnAdapter:
    name: ClassVar[str] = "fake-not-an-adapter"


class Abstract(Adapter):
    """No query."""

    name: ClassVar[str] = "fake-abstract"
    engine: ClassVar[str] = "fake"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE)
    conventions: ClassVar[Conventions] = Conforming.conventions

    def version(self) -> str:
        return "0"

    def prepare(self, case: AnyCase) -> Any:
        return case


class ConfiguredAtRuntime(Conforming):
    """Right only once a test sets ``offset`` to 0: a worker process re-imports the default."""

    name: ClassVar[str] = "fake-configured"
    offset: ClassVar[float] = 1.0

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        if isinstance(truth.distance, float):
            return replace(truth, distance=truth.distance + self.offset)
        return truth


# --- the kit catches each, and says where --------------------------------------------------

BROKEN: list[tuple[type[Any], set[str], str]] = [
    (WrongNormal, {"overlap", "gap"}, "unit vector from A to B (+x)"),
    (NoSources, {"conventions"}, "sources"),
    (MissingVelocity, {"observe"}, "no v2"),
    (ExtraQuantity, {"observe"}, "also v1"),
    (AlwaysHits, {"gap"}, "hit False"),
    (NumpyVerdict, {"overlap", "gap"}, "(numpy."),
    (Drifts, {"repeat"}, "the same answer"),
    (ClaimsEverything, {"unsupported"}, "skip reason"),
    (IllFormedConventions, {"conventions"}, "zero_mass"),
    (HangsWithoutSaying, {"hangs"}, "known_hang"),
    (NeedsArgument, {"made"}, "no arguments"),
    (NotAnAdapter, {"declared"}, "subclass of crosscheck.core.contract.Adapter"),
    (Abstract, {"declared"}, "query"),
    (Unavailable, {"available"}, "not installed here"),
]


@pytest.mark.parametrize(("cls", "checks", "words"), BROKEN, ids=[b[0].__name__ for b in BROKEN])
def test_the_kit_fails_a_broken_adapter_and_says_where(cls: type[Any], checks: set[str],
                                                       words: str) -> None:
    failures = conformance_failures(cls, public_sources=False, worker=False)
    assert {f.check for f in failures} == checks
    assert any(words in str(f) for f in failures), [str(f) for f in failures]
    for failure in failures:
        assert str(failure).startswith(f"{cls.name} ({cls.__module__}.{cls.__qualname__}): ")
        assert "expected " in str(failure)
    with pytest.raises(ConformanceError) as raised:
        check_adapter(cls, public_sources=False, worker=False)
    assert len(raised.value.failures) == len(failures)


def test_a_failure_names_the_case_and_what_was_expected() -> None:
    failures = conformance_failures(WrongNormal, public_sources=False, worker=False)
    gap_y = [f for f in failures if "along -y" in f.case]
    assert len(gap_y) == 4  # aabb and sphere, 2-D and 3-D
    for failure in gap_y:
        assert "B 1.5 from A along -y (gap 0.5)" in str(failure)
        assert "a unit vector from A to B (-y)" in failure.expected
        assert ast.literal_eval(failure.got)[1] == 1.0  # it said +y


def test_the_kit_asks_for_public_sources_unless_told_not_to() -> None:
    failures = conformance_failures(Conforming, worker=False)
    assert [f.expected.split(" ")[0:3] for f in failures] == [
        ["at", "least", "one"], ["module", "crosscheck.testing.fakes's", "docstring"]]


def test_the_kit_checks_the_registered_name() -> None:
    failures = conformance_failures(Conforming, name="other", public_sources=False,
                                    worker=False)
    assert [(f.check, f.expected, f.got) for f in failures] == [
        ("declared", "name 'other'", "'fake-conforming'")]


def test_a_class_that_cannot_be_pickled_fails_the_worker_check() -> None:
    class Local(Conforming):
        name: ClassVar[str] = "fake-local"

    failures = conformance_failures(Local, public_sources=False)
    assert [f.check for f in failures] == ["worker"]
    assert "pickled by reference" in failures[0].expected


def test_state_a_worker_process_does_not_see_fails_the_worker_check(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(ConfiguredAtRuntime, "offset", 0.0)
    failures = conformance_failures(ConfiguredAtRuntime, public_sources=False)
    assert [f.check for f in failures] == ["worker"]
    assert failures[0].expected.startswith("the same answer as in this process")
    assert "distance=0.75" in failures[0].got  # the overlap of 0.25, plus the default offset
