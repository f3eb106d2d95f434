"""Every registered adapter honours the contract: declared, available, repeatable, sourced."""

from __future__ import annotations

import importlib

import pytest

import adapters
from crosscheck.core.contract import Adapter
from crosscheck.core.model import Kind, quantities_of
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from tests.conftest import aabb, response, sphere

ENGINES = ["fcl", "pybullet", "pybullet-default", "pymunk", "pymunk-default"]


def sample(kind: Kind, dim: int) -> AnyCase:
    pad = [0.0] * (dim - 1)
    if kind is Kind.AABB:
        return aabb([0.0, *pad], [0.5] * dim, [0.75, *pad], [0.5] * dim)
    if kind is Kind.SPHERE:
        return sphere(0.0, 0.75, dim=dim)
    if kind is Kind.SPHERE_SCENE:
        return scene(dim)
    return response([0.0, *pad], [1.0, *pad], [1.0, *pad], [-1.0, *pad])


@pytest.mark.parametrize("name", adapters.names())
def test_adapter_is_available_and_declared(name: str) -> None:
    adapter = adapters.get(name)
    assert adapter.name == name
    assert adapter.available() is None
    assert adapter.version()
    assert adapter.capabilities
    assert adapter.conventions.sources


@pytest.mark.parametrize("name", ENGINES)
def test_engine_conventions_cite_public_sources_in_the_module_docstring(name: str) -> None:
    adapter = adapters.get(name)
    links = [s for s in adapter.conventions.sources if s.startswith("https://")]
    assert links, f"{name} cites no link"
    module = importlib.import_module(type(adapter).__module__)
    doc = (module.__doc__ or "").lower()
    assert "conventions" in doc and "sources" in doc


@pytest.mark.parametrize("name", adapters.names())
def test_query_is_repeatable_and_in_harness_conventions(name: str) -> None:
    adapter: Adapter = adapters.get(name)
    for kind, dim in sorted(adapter.capabilities):
        if kind is Kind.SPHERE_SCENE:
            continue  # a query steps the scene on: see test_scene_runs_are_deterministic
        case = sample(kind, dim)
        assert adapter.unsupported(case) is None
        prepared = adapter.prepare(case)
        try:
            first, second = adapter.query(prepared), adapter.query(prepared)
        finally:
            adapter.release(prepared)
        assert first == second, (name, kind, dim)
        for quantity in quantities_of(kind):
            value = first.get(quantity)
            if isinstance(value, tuple):
                assert len(value) == dim, (name, kind, dim, quantity)
        if kind is not Kind.SPHERE_RESPONSE:
            assert first.hit is True
            assert isinstance(first.distance, float) and first.distance < 0
            assert first.normal is None or first.normal[0] > 0.99  # A -> B is +x


def scene(dim: int) -> AnyCase:
    pad = [0.0] * (dim - 1)
    return CASE_ADAPTER.validate_python({
        "id": "scene", "description": "d", "kind": "sphere_scene", "dim": dim, "duration": 2.0,
        "dt": 0.01, "bodies": [
            {"center": [-1.0, *pad], "radius": 0.5, "mass": 1.0, "velocity": [1.0, *pad]},
            {"center": [1.0, *pad], "radius": 0.5, "mass": 1.0, "velocity": [-1.0, *pad]}]})


@pytest.mark.parametrize("name", adapters.names())
def test_scene_runs_are_deterministic_and_in_harness_conventions(name: str) -> None:
    adapter: Adapter = adapters.get(name)
    dims = sorted(d for k, d in adapter.capabilities if k is Kind.SPHERE_SCENE)
    for dim in dims:
        runs = []
        for _ in range(2):
            prepared = adapter.prepare(scene(dim))
            try:
                runs.append(adapter.query(prepared))
            finally:
                adapter.release(prepared)
        first, second = runs
        assert first.positions == second.positions and first.velocities == second.velocities
        assert isinstance(first.positions, tuple) and len(first.positions) == 2
        assert all(len(p) == dim for p in first.positions)
        assert first.wall_s is not None and first.wall_s > 0
        # equal masses head-on at e = 1: they have exchanged velocities by t = 2
        assert isinstance(first.velocities, tuple) and first.velocities[0][0] < 0


@pytest.mark.parametrize("name", adapters.names())
def test_unsupported_pairs_have_a_reason(name: str) -> None:
    adapter = adapters.get(name)
    for kind in Kind:
        for dim in (2, 3):
            reason = adapter.unsupported(sample(kind, dim))
            assert (reason is None) == ((kind, dim) in adapter.capabilities)
            assert reason is None or name.split("-")[0] in reason or "engine" in reason


@pytest.mark.parametrize("name", adapters.names())
def test_declared_hangs_and_conventions_are_well_formed(name: str) -> None:
    adapter: Adapter = adapters.get(name)
    conventions = adapter.conventions
    assert conventions.zero_mass in ("static", "")
    assert conventions.negative_extents in ("absolute", "")
    assert conventions.damping >= 0.0
    assert conventions.time_step is None or conventions.time_step > 0.0
    for kind, dim in sorted(adapter.capabilities):
        if kind is Kind.SPHERE_SCENE:
            continue
        case = sample(kind, dim)
        hanging = adapter.hanging_quantities(case)
        assert hanging <= set(quantities_of(kind))
        assert (adapter.known_hang(case) is None) == (not hanging), (name, kind, dim)
        prepared = adapter.prepare(case)
        try:  # skipping nothing is the query itself
            assert adapter.query_without(prepared, frozenset()) == adapter.query(prepared)
        finally:
            adapter.release(prepared)
