"""FCL and coal reuse their pairs: a reused pair answers exactly as a new one.

``release`` keeps a detection pair (geometries, objects or functors, requests) idle, and the
next case of its geometry takes it and sets its sizes and centres instead of building
anew.  The reference is a separate process with the pool off (``IDLE_LIMIT`` 0: every case
on a new pair, as before reuse).  The cases avoid FCL's deep sphere overlaps, whose signed
distance differs from call to call (EPA; measured on the suite).
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator

import pytest

import adapters
from crosscheck.core.contract import Adapter
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from tests.conftest import ROOT, aabb, sphere

pytestmark = pytest.mark.engine

ENGINES = [name for name in ("fcl", "coal", "coal-default")
           if adapters.get(name).available() is None]

FRESH = """
import importlib, json, sys
import adapters
from crosscheck.core.schema import CASE_ADAPTER
name, cases = json.load(sys.stdin)
adapter = adapters.get(name)
importlib.import_module(adapter.calls).IDLE_LIMIT = 0  # no pool: every case on a new pair
out = [repr(adapter.observe(CASE_ADAPTER.validate_json(case))) for case in cases]
print("FRESH " + json.dumps(out))
"""

CASES = [
    sphere(0.0, 0.75, ra=0.5, rb=0.5),                                  # overlap
    sphere(0.0, 3.0, ra=0.5, rb=1.5),                                   # apart
    sphere(0.0, 1.0, ra=0.25, rb=0.75),                                 # touching
    CASE_ADAPTER.validate_python({
        "id": "d2", "description": "d", "kind": "sphere", "dim": 2,
        "a": {"center": [0.0, 0.0], "radius": 1.0}, "b": {"center": [3.0, 4.0], "radius": 2.0}}),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.5, 0.0, 0.0], [1.0, 1.0, 1.0]),   # overlap
    aabb([0.0, 0.0, 0.0], [0.5, 1.0, 2.0], [3.0, 0.0, 0.0], [1.0, 0.5, 0.25]),  # apart
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0], [1.0, 1.0, 1.0]),   # edge touch
    aabb([0.0, 0.0], [1.0, 2.0], [1.5, 0.5], [1.0, 1.0]),                      # 2-D overlap
    aabb([0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]),                      # 2-D zero size
]


def orders(cases: list[AnyCase]) -> Iterator[AnyCase]:
    """Every case several times, after different others (X, Y, ..., X again)."""
    yield from cases
    yield from reversed(cases)
    yield from cases[::2]
    yield from cases[1::2]


def fresh(name: str, cases: list[AnyCase]) -> list[str]:
    """repr of each case's observation in a new process, every case on a new pair."""
    payload = json.dumps([name, [CASE_ADAPTER.dump_json(case).decode() for case in cases]])
    done = subprocess.run([sys.executable, "-c", FRESH], input=payload, capture_output=True,
                          text=True, cwd=ROOT, timeout=120, check=True)
    line = next(x for x in done.stdout.splitlines() if x.startswith("FRESH "))
    out: list[str] = json.loads(line.removeprefix("FRESH "))
    return out


@pytest.mark.parametrize("name", ENGINES)
def test_reused_pairs_answer_as_new_ones_in_any_order(name: str) -> None:
    adapter: Adapter = adapters.get(name)
    runs = list(orders(CASES))
    for case, expected in zip(runs, fresh(name, runs), strict=True):
        assert repr(adapter.observe(case)) == expected, (name, case)


@pytest.mark.parametrize("name", ENGINES)
def test_a_released_pair_is_the_next_case_of_its_geometry(name: str) -> None:
    adapter: Adapter = adapters.get(name)
    first = adapter.prepare(CASES[0])
    adapter.release(first)
    box = adapter.prepare(CASES[4])  # another geometry: not the sphere pair
    second = adapter.prepare(CASES[1])
    try:
        assert second.built is first.built and box.built is not first.built
        assert repr(adapter.query(second)) == fresh(name, [CASES[1]])[0]
    finally:
        adapter.release(second)
        adapter.release(box)
