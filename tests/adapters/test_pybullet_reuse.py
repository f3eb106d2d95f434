"""The PyBullet adapters reuse bodies: a reused body answers exactly as a new one, and sphere
detection, which builds no body, exactly as two bodies.

``prepare`` takes idle bodies from a per-client pool (boxes, responses) and ``release`` parks
them with collision off; these tests pin what that must not change (observations, whatever
ran before) and what it must bound (bodies and shapes in a client).  The reference is a
separate process with the pool off (every case on new bodies, as before pooling).  Sphere
detection asks ``getClosestPoints`` on the cached shapes: the reference is the body path
(``pair`` and ``detect``) on the same inputs.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from collections.abc import Iterator
from typing import Any

import pytest

import adapters
from adapters import pybullet as pbe
from adapters.pybullet import PyBulletDefault, PyBulletTuned, engine
from adapters.pybullet import calls as pool
from adapters.pybullet import calls as shared_pybullet
from adapters.pybullet.calls import Pair, Shapes
from crosscheck.core.model import Observation
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from tests.conftest import ROOT, aabb, response, sphere

pytestmark = [pytest.mark.engine,
              pytest.mark.skipif(adapters.get("pybullet").available() is not None,
                                 reason="pybullet is not installed")]

VARIANTS: dict[str, type[PyBulletTuned]] = {"pybullet": PyBulletTuned,
                                            "pybullet-default": PyBulletDefault}

FRESH = """
import json, sys
from adapters import pybullet as pbe
from adapters.pybullet import calls
from crosscheck.core.schema import CASE_ADAPTER
calls.IDLE_LIMIT = calls.RESPONSE_IDLE_LIMIT = 0  # no pool: every release removes its bodies
variants = {"pybullet": pbe.PyBulletTuned(), "pybullet-default": pbe.PyBulletDefault()}
out = [repr(variants[name].observe(CASE_ADAPTER.validate_json(case)))
       for name, case in json.load(sys.stdin)]
print("FRESH " + json.dumps(out))
"""


def fresh(runs: list[tuple[str, AnyCase]]) -> list[str]:
    """repr of each run's observation in a new process, every case on new bodies."""
    payload = json.dumps([(name, CASE_ADAPTER.dump_json(case).decode()) for name, case in runs])
    done = subprocess.run([sys.executable, "-c", FRESH], input=payload, capture_output=True,
                          text=True, cwd=ROOT, timeout=120, check=True)
    line = next(x for x in done.stdout.splitlines() if x.startswith("FRESH "))
    out: list[str] = json.loads(line.removeprefix("FRESH "))
    return out


def own(variant: str, tag: str) -> PyBulletTuned:
    """An adapter of ``variant`` with worlds of its own (named ``<variant>-<tag>``)."""
    base = VARIANTS[variant]
    cls = type(f"{base.__name__}{tag.title()}", (base,), {"name": f"{variant}-{tag}"})
    adapter: PyBulletTuned = cls()
    return adapter


def world_of(adapter: PyBulletTuned, response_world: bool = False) -> pbe.World:
    name = adapter.name + ("/response" if response_world else "")
    return pbe.world(name, adapter.world, response=response_world)


def count(w: pbe.World) -> int:
    bodies: int = engine().getNumBodies(physicsClientId=w.cid)
    return bodies


def observe(adapter: PyBulletTuned, case: AnyCase) -> tuple[Observation, Any]:
    prepared = adapter.prepare(case)
    try:
        return adapter.query(prepared), prepared.built
    finally:
        adapter.release(prepared)


DETECTION = [
    sphere(0.0, 0.75, ra=0.5, rb=0.5),                       # overlap
    sphere(0.0, 1.0 + 2.0**-40, ra=0.5, rb=0.5),             # a 2^-40 gap
    sphere(0.0, 1.0, ra=0.5, rb=0.5),                        # touching
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 0.0, 0.0], [1.0, 1.0, 1.0]),  # face touch
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0], [1.0, 1.0, 1.0]),  # edge touch
    aabb([0.0, 0.0], [1.0, 1.0], [1.5, 0.5], [1.0, 1.0]),    # 2-D overlap
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.9, 0.3, -0.2], [1.0, 1.0, 1.0]),
]
RESPONSE = [
    response([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 0.0]),  # oblique
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0],
             ma=3.0, mb=0.25),                                                   # masses
    response([0.0, 0.0], [0.1, 0.0], [1.0, 0.0], [0.0, 0.0], restitution=0.5),   # slow
    response([0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [0.99, 0.0, 0.0], [-1.0, 0.0, 0.0],
             ma=0.5, mb=7.0, restitution=0.25),                                  # overlapped
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0],
             restitution=-0.5),                     # ignored by changeDynamics: not pooled
]


def orders(cases: list[AnyCase]) -> Iterator[AnyCase]:
    """Every case several times, after different others (X, Y, ..., X again)."""
    yield from cases
    yield from reversed(cases)
    yield from cases[::2]
    yield from cases[1::2]
    yield from cases


@pytest.mark.parametrize("variant", VARIANTS)
def test_reused_bodies_answer_as_new_ones_in_any_order(variant: str) -> None:
    adapter = own(variant, "order")
    runs = list(orders(DETECTION + RESPONSE))
    want = fresh([(variant, case) for case in runs])
    reused = 0
    for case, expected in zip(runs, want, strict=True):
        w = world_of(adapter, response_world=case.kind == "sphere_response")
        idle = set(w.lru)
        obs, pair = observe(adapter, case)
        assert repr(obs) == expected, (case.id, case)
        if isinstance(pair, Pair):  # sphere detection takes no body
            reused += len({pair.a, pair.b} & idle)
    bodied = [case for case in runs if case.kind != "sphere"]
    assert reused >= len(bodied)  # most runs took both bodies from the pool


def test_a_case_repeated_after_others_matches_its_first_run() -> None:
    adapter = own("pybullet-default", "xyx")
    x, y = RESPONSE[0], RESPONSE[1]
    first, _ = observe(adapter, x)
    observe(adapter, y)
    idle = set(world_of(adapter, response_world=True).lru)
    again, pair_again = observe(adapter, x)
    assert again == first
    assert {pair_again.a, pair_again.b} <= idle  # reused: both came from the pool


def test_bodies_and_shapes_stay_bounded_over_many_cases() -> None:
    adapter = own("pybullet", "bound")
    w, r = world_of(adapter), world_of(adapter, response_world=True)
    radii = [0.05 + 0.02 * k for k in range(50)]
    halves = [[0.5, 1.0, 1.5], [1.0, 1.0, 1.0], [0.25, 0.5, 2.0]]
    for i in range(2000):
        k = i % 7
        if k < 5:
            case = sphere(0.0, 0.3 * (i % 5), ra=radii[i % 50], rb=radii[(7 * i) % 50])
        elif k == 5:
            ha, hb = halves[i % 3], halves[(i // 3) % 3]
            case = aabb([0.0, 0.0, 0.0], ha, [1.0, 0.5, 0.0], hb)
        else:
            case = response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0],
                            [-1.0, 0.0, 0.0], ma=1.0 + i % 3)
        observe(adapter, case)
        assert w.busy == 0 and r.busy == 0
        assert count(w) == len(w.lru) <= pool.IDLE_LIMIT
        assert count(r) == len(r.lru) <= pool.RESPONSE_IDLE_LIMIT
    assert sum(len(bodies) for bodies in w.idle.values()) == len(w.lru)
    assert len(w.shapes) <= len(radii) + len(halves)
    assert len(r.shapes) == 1  # radius-0.5 responses: one shape


def test_a_client_full_of_shapes_is_replaced_between_cases(
        monkeypatch: pytest.MonkeyPatch) -> None:
    adapter = own("pybullet", "recycle")
    w = world_of(adapter)
    monkeypatch.setattr(pool, "SHAPE_LIMIT", 8)
    for i in range(60):
        ra, rb = 0.1 + 0.01 * i, 0.2 + 0.01 * i  # two new shapes every case
        obs, _ = observe(adapter, sphere(0.0, 1.0, ra=ra, rb=rb))
        assert len(w.shapes) <= 8 and count(w) <= pool.IDLE_LIMIT
        assert obs.distance == pytest.approx(1.0 - ra - rb, abs=1e-12)
    bt = engine()  # the old client is gone: only the current one answers
    assert bt.getNumBodies(physicsClientId=w.cid) == len(w.lru)


def test_idle_bodies_make_no_contact_with_the_pair() -> None:
    adapter = own("pybullet", "idle")
    w, bt = world_of(adapter), engine()
    for k in range(6):  # overlapping pairs round the origin: idle bodies are left there
        ha, hb = [0.4 + 0.05 * k] * 3, [0.45 + 0.05 * k] * 3
        observe(adapter, aabb([-0.1 * k, 0.0, 0.0], ha, [0.2, 0.0, 0.0], hb))
    idle = list(w.lru)
    assert len(idle) >= 6  # 7 half-widths, 0.4 to 0.7
    unit = [0.5, 0.5, 0.5]
    apart = aabb([-0.6, 0.0, 0.0], unit, [0.6, 0.0, 0.0], unit)  # 0.2 apart, among them
    prepared = adapter.prepare(apart)
    try:
        obs = adapter.query(prepared)
        # the idle bodies overlap the pair (closest points ignore the collision filter) ...
        assert any(bt.getClosestPoints(body, other, 0.0, physicsClientId=w.cid)
                   for body in idle if body not in (prepared.built.a, prepared.built.b)
                   for other in (prepared.built.a, prepared.built.b))
        # ... but make no contact with it, nor with each other
        assert obs.hit is False and obs.distance == pytest.approx(0.2, abs=1e-12)
        assert bt.getContactPoints(physicsClientId=w.cid) == ()
    finally:
        adapter.release(prepared)
    prepared = adapter.prepare(aabb([0.0, 0.0, 0.0], unit, [0.3, 0.0, 0.0], unit))  # overlapping
    try:
        assert adapter.query(prepared).hit is True
        pairs = {(p[1], p[2]) for p in bt.getContactPoints(physicsClientId=w.cid)}
        assert pairs == {(prepared.built.a, prepared.built.b)}
    finally:
        adapter.release(prepared)


def test_idle_bodies_stay_still_and_out_of_a_response() -> None:
    adapter = own("pybullet-default", "still")
    r, bt = world_of(adapter, response_world=True), engine()
    for k in range(3):  # leave idle bodies of other radii on the next pair's path
        observe(adapter, CASE_ADAPTER.validate_python({
            "id": "r", "description": "d", "kind": "sphere_response", "dim": 3,
            "a": {"center": [0.2 * k, 0.0, 0.0], "radius": 0.3 + 0.1 * k, "mass": 1.0,
                  "velocity": [0.5, 0.0, 0.0]},
            "b": {"center": [1.5, 0.0, 0.0], "radius": 0.7 + 0.1 * k, "mass": 1.0,
                  "velocity": [-0.5, 0.0, 0.0]}}))
    idle = list(r.lru)
    assert len(idle) == pool.RESPONSE_IDLE_LIMIT

    def state(bodies: list[int]) -> list[Any]:
        return [(bt.getBasePositionAndOrientation(b, physicsClientId=r.cid),
                 bt.getBaseVelocity(b, physicsClientId=r.cid)) for b in bodies]

    before = state(idle)
    assert all(v == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)) for _, v in before)
    # A runs into where the idle bodies stand (x from 0.2 to 1.5), one of them reused
    case = response([-0.5, 0.0, 0.0], [2.0, 0.0, 0.0], [0.6, 0.0, 0.0], [0.0, 0.0, 0.0])
    obs, pair = observe(adapter, case)
    still = [k for k, b in enumerate(idle) if b in r.lru and b not in (pair.a, pair.b)]
    assert len(still) >= pool.RESPONSE_IDLE_LIMIT - 2  # one taken, one evicted at most
    assert state([idle[k] for k in still]) == [before[k] for k in still]
    assert repr(obs) == fresh([("pybullet-default", case)])[0]


def test_a_failed_prepare_gives_back_what_it_took(monkeypatch: pytest.MonkeyPatch) -> None:
    adapter = own("pybullet", "fail")
    w = world_of(adapter)
    unit = [0.5, 0.5, 0.5]
    observe(adapter, aabb([0.0, 0.0, 0.0], unit, [0.75, 0.0, 0.0], unit))  # two bodies idle
    idle, bodies = len(w.lru), count(w)
    taken: list[int] = []
    take = pool.take

    def failing(*args: Any) -> int:
        if taken:
            raise engine().error("second body failed")
        taken.append(take(*args))
        return taken[-1]

    monkeypatch.setattr(pool, "take", failing)
    with pytest.raises(engine().error):
        adapter.prepare(aabb([0.0, 0.0, 0.0], unit, [0.75, 0.0, 0.0], unit))
    assert w.busy == 0 and len(w.lru) == idle and count(w) == bodies and taken[0] in w.lru
    taken.clear()
    with pytest.raises(engine().error):  # new bodies (not pooled): removed
        adapter.prepare(aabb([0.0, 0.0, 0.0], [4e5] * 3, [9e5, 0.0, 0.0], [4e5] * 3))
    assert w.busy == 0 and len(w.lru) == idle and count(w) == bodies


def test_cases_outside_the_pool_get_new_bodies_removed_on_release() -> None:
    adapter = own("pybullet", "outside")
    w, r = world_of(adapter), world_of(adapter, response_world=True)
    unit = [0.5, 0.5, 0.5]
    observe(adapter, aabb([0.0, 0.0, 0.0], unit, [0.75, 0.0, 0.0], unit))
    bodies = count(w)
    for case in (aabb([0.0, 0.0, 0.0], [4e5] * 3, [6e5, 0.0, 0.0], [4e5] * 3),  # too large
                 aabb([0.0, 0.0, 0.0], unit, [2e12, 0.0, 0.0], unit),  # beyond COORD_LIMIT
                 aabb([0.0, 0.0], [0.0, 1.0], [0.5, 0.0], [1.0, 1.0])):  # a 0 half-width
        prepared = adapter.prepare(case)
        assert prepared.built.pooled is False
        adapter.release(prepared)
        assert count(w) == bodies
    bad = response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0],
                   restitution=-0.5)
    prepared = adapter.prepare(bad)
    assert prepared.built.pooled is False
    adapter.release(prepared)
    assert count(r) == len(r.lru)


def test_the_pooled_path_prints_nothing_and_skips_the_redirect(
        monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]) -> None:
    adapter = own("pybullet", "quiet")
    unit = [0.5, 0.5, 0.5]
    cases = (sphere(0.0, 0.75), aabb([0.0, 0.0, 0.0], unit, [0.75, 0.0, 0.0], unit))
    for case in cases:
        observe(adapter, case)  # connect and make the shapes and bodies
    capfd.readouterr()
    redirects: list[int] = []
    quiet = pool.quiet

    def counted() -> Any:
        redirects.append(1)
        return quiet()

    monkeypatch.setattr(pool, "quiet", counted)
    monkeypatch.setattr(shared_pybullet, "quiet", counted)
    for _ in range(3):
        for case in cases:
            obs, _ = observe(adapter, case)
            assert obs.hit is True and math.isclose(obs.distance or 0.0, -0.25, abs_tol=1e-12)
    assert redirects == []
    assert capfd.readouterr() == ("", "")


def test_release_returns_bodies_to_the_pool_and_variants_use_separate_clients() -> None:
    tuned, default = own("pybullet", "clients"), own("pybullet-default", "clients")
    w = world_of(tuned)
    unit = [0.5, 0.5, 0.5]
    case = aabb([0.0, 0.0, 0.0], unit, [1.0, 0.0, 0.0], unit)
    prepared, other = tuned.prepare(case), default.prepare(case)
    assert prepared.built.cid != other.built.cid and prepared.built.cid == w.cid
    assert count(w) == 2 and w.busy == 2 and not w.lru
    tuned.release(prepared)
    default.release(other)
    assert count(w) == 2 and w.busy == 0 and set(w.lru) == {prepared.built.a, prepared.built.b}


SPHERES = [
    *(case for case in DETECTION if case.kind == "sphere"),
    sphere(0.0, 0.0, ra=0.5, rb=0.25),                       # coincident centres
    sphere(0.0, 3.0, ra=0.5, rb=0.5),                        # apart
    sphere(0.0, 6e5, ra=4e5, rb=4e5),                        # too large for a dynamic body
    sphere(0.0, 2e12),                                       # beyond COORD_LIMIT
    CASE_ADAPTER.validate_python({
        "id": "d2", "description": "d", "kind": "sphere", "dim": 2,
        "a": {"center": [0.0, 0.0], "radius": 1.0}, "b": {"center": [1.2, 1.6], "radius": 1.0}}),
]


@pytest.mark.parametrize("variant", VARIANTS)
def test_sphere_detection_builds_no_body_and_answers_as_two_bodies(variant: str) -> None:
    adapter = own(variant, "shapes")
    w = world_of(adapter)
    for case in SPHERES:
        before = count(w)
        obs, built = observe(adapter, case)
        assert isinstance(built, Shapes) and count(w) == before and w.busy == 0
        inputs = adapter.call(case).inputs
        bodies = pool.pair(inputs["world_name"], inputs["settings"], False, inputs["a"],
                           inputs["b"], inputs["a_center"], inputs["b_center"], inputs["dim"],
                           pooled=False)
        try:
            assert repr(obs) == repr(adapter.observation(pool.detect(bodies))), case.id
        finally:
            pool.release(bodies)
