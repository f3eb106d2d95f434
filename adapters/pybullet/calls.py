"""PyBullet's calls (the ``pybullet``, ``pybullet-default`` and ``pybullet-ccd`` pairs), plain
data in and out.

Everything that drives pybullet (the pairs, the scenes, the bench) shares the quiet import
(``engine()``: the import prints a banner), ``quiet()`` (C-level stdout and stderr on
/dev/null for what prints ``b3Warning`` lines) and ``connect(settings)`` (a DIRECT client,
gravity 0, the settings), below.

A box pair or a response is two base-only multibodies on shapes cached per client, taken
from a pool of idle bodies per world (a world: a client and its pool, by name); a body is
new when none of its shape is idle, or the pair is not ``pooled``.  A detection body gets a
dynamic base's collision filter (a static base's excludes static-static pairs).  Box
detection asks ``performCollisionDetection``, ``getContactPoints`` (the verdict) and the
deepest of ``getClosestPoints`` within ``bound`` (``contactNormalOnB``, B to A: flipped).
Sphere detection builds no body (``sphere_shapes``, ``closest``: at the end): the deepest of
``getClosestPoints`` on the two cached shapes, the verdict its distance <= 0.  A response
sets restitutions (A = e, B = 1: multiplied), mass when pooled and the per-body settings;
each ask resets centres and velocities and steps until the bodies no longer approach along
the line of centres the step detected from (not above ``tol``), at most ``max_steps``.  2-D:
z = 0 (a response leaving it raises); ``resolved_at``: where the first contact step began.

A scene (``sphere_scene``) gets a DIRECT client of its own (never a pair's): gravity 0 (the
scene's, when it has one), ``fixedTimeStep`` dt, ``numSubSteps`` 0, ``numSolverIterations``
if given, and the variant's ``world`` settings; a static ``GEOM_PLANE`` per wall (a mass-0 base
at ``offset x normal``, restitution sqrt(e), the friction settings of ``body``), then a base-only
multibody per sphere (``useMaximalCoordinates`` when ``maximal``: a rigid body, with
``ccdSweptSphereRadius`` ``ccd`` x its radius when ``ccd`` > 0) with restitution sqrt(e) and
``body``.  The ask times only ``stepSimulation`` and reads the bases' positions and velocities
(a 2-D scene that leaves the plane z = 0 raises).  Releasing empties the client
(``resetSimulation``) and keeps it for a next scene of the same world settings
(``SCENE_IDLE_CLIENTS`` at most; a connect costs 30-50 ms, a reset 0.2 ms).  What this
measures and why: :mod:`adapters.pybullet.scene`.

What the pairs, responses and scenes share:
- ``engine()``: the pybullet module, imported once, lazily (importing this module does not
  import it; the import prints a banner);
- ``quiet()``: pybullet's banner and ``b3Warning`` lines go to the C-level stdout/stderr,
  so what prints them runs with file descriptors 1 and 2 on /dev/null (a redirect costs
  ~8 us);
- ``connect(settings)``: a new DIRECT client (no GUI) with gravity 0 and ``settings``.

(Longer than 400 lines: one module is what a repro script holds verbatim; the pooled pairs
and the scenes' reused clients are about 150 lines each, the sphere shapes about 45.)
"""

import contextlib
import ctypes
import functools
import math
import os
import sys
import time
from collections import OrderedDict
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from adapters.shared import approach_speed, to3
from adapters.shared.scene import (
    check_scene,
    check_surroundings,
    in_scene_dim,
    scene_answer,
    step_and_record,
)

_MODULE: list[Any] = []


@contextlib.contextmanager
def quiet() -> Iterator[None]:
    """Send C-level stdout and stderr to /dev/null (the banner, b3Warning lines)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = (os.dup(1), os.dup(2))
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        ctypes.CDLL(None).fflush(None)  # C stdio buffers empty into /dev/null
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, null):
            os.close(fd)


def engine() -> Any:
    """The pybullet module, imported quietly once (its import prints a banner)."""
    if not _MODULE:
        with quiet():
            import pybullet
        _MODULE.append(pybullet)
    return _MODULE[0]


def connect(settings: dict[str, float]) -> int:
    """A new DIRECT client with gravity 0 and ``settings``."""
    bt = engine()
    with quiet():
        cid: int = bt.connect(bt.DIRECT)
        bt.setGravity(0.0, 0.0, 0.0, physicsClientId=cid)
        if settings:
            bt.setPhysicsEngineParameter(**settings, physicsClientId=cid)
    return cid


Answer = dict[str, Any]
Vec3 = tuple[float, float, float]
ShapeKey = tuple[str, tuple[float, ...]]

IDENTITY = (0.0, 0.0, 0.0, 1.0)
GROUP, MASK = 1, -1
"""createMultiBody's collision filter for a dynamic base (DefaultFilter, AllFilter)."""
IDLE_LIMIT = 16
RESPONSE_IDLE_LIMIT = 4
SHAPE_LIMIT = 2048
COORD_LIMIT = 1e12
"""Largest coordinate or speed of a body fit to go back to the pool."""

@dataclass(eq=False)
class World:
    """One DIRECT client: its cached shapes and its pool of idle bodies.

    ``idle`` maps a shape id to its idle bodies (most recently released last), ``lru``
    every idle body to its shape id (least recently released first); ``busy`` counts the
    bodies handed out and not yet released (the client is replaced only when it is 0).
    ``static``: a detection world, whose bodies are static and pair with each other.
    """

    settings: dict[str, float]
    limit: int
    cid: int
    static: bool = False
    shapes: dict[ShapeKey, int] = field(default_factory=dict)
    idle: dict[int, list[int]] = field(default_factory=dict)
    lru: OrderedDict[int, int] = field(default_factory=OrderedDict)
    busy: int = 0


_WORLDS: dict[str, World] = {}


def world(name: str, settings: dict[str, float], response: bool = False) -> World:
    """The world (client and pool) called ``name``, connected once per process."""
    if name not in _WORLDS:
        limit = RESPONSE_IDLE_LIMIT if response else IDLE_LIMIT
        _WORLDS[name] = World(settings, limit, connect(settings), static=not response)
    return _WORLDS[name]


def recycle(w: World) -> None:
    """Replace the world's client by a new one: the only way to free shapes once used."""
    with quiet():
        engine().disconnect(physicsClientId=w.cid)
    w.shapes.clear()
    w.idle.clear()
    w.lru.clear()
    w.cid = connect(w.settings)


def shape(w: World, geom: str, size: tuple[float, ...]) -> int:
    """A cached collision shape: a sphere of radius size[0] or a box of half-widths size."""
    key = (geom, size)
    if key not in w.shapes:
        bt = engine()
        with quiet():
            if geom == "sphere":
                sid = bt.createCollisionShape(bt.GEOM_SPHERE, radius=size[0],
                                              physicsClientId=w.cid)
            else:
                sid = bt.createCollisionShape(bt.GEOM_BOX, halfExtents=size,
                                              physicsClientId=w.cid)
        w.shapes[key] = sid
    return w.shapes[key]


def take(w: World, sid: int, mass: float, centre: Vec3, pooled: bool) -> int:
    """A body of shape ``sid`` at ``centre``, colliding: an idle one if pooled, else new."""
    bt = engine()
    bodies = w.idle.get(sid) if pooled else None
    if bodies:
        body = bodies.pop()
        del w.lru[body]
        bt.resetBasePositionAndOrientation(body, centre, IDENTITY, physicsClientId=w.cid)
        bt.setCollisionFilterGroupMask(body, -1, GROUP, MASK, physicsClientId=w.cid)
    else:
        with quiet():
            body = bt.createMultiBody(baseMass=mass, baseCollisionShapeIndex=sid,
                                      basePosition=centre, physicsClientId=w.cid)
        if w.static:  # a static base's own filter excludes static-static pairs
            bt.setCollisionFilterGroupMask(body, -1, GROUP, MASK, physicsClientId=w.cid)
    w.busy += 1
    return int(body)


def give_back(w: World, body: int, sid: int, keep: bool) -> None:
    """Return ``body`` to the pool, collision off, if ``keep`` (else remove it); trim the pool."""
    bt = engine()
    w.busy -= 1
    if keep:
        bt.setCollisionFilterGroupMask(body, -1, 0, 0, physicsClientId=w.cid)
        w.idle.setdefault(sid, []).append(body)
        w.lru[body] = sid
        if len(w.lru) <= w.limit:
            return
        body, sid = w.lru.popitem(last=False)
        w.idle[sid].remove(body)
    with quiet():
        bt.removeBody(body, physicsClientId=w.cid)


def settled(cid: int, body: int) -> bool:
    """Whether a response body ended finite and within ``COORD_LIMIT`` (fit to reuse)."""
    bt = engine()
    position, orientation = bt.getBasePositionAndOrientation(body, physicsClientId=cid)
    linear, angular = bt.getBaseVelocity(body, physicsClientId=cid)
    return (all(abs(x) <= COORD_LIMIT for x in (*position, *linear))
            and all(math.isfinite(x) for x in (*orientation, *angular)))


@dataclass(frozen=True, slots=True)
class Motion:
    """What a response ask resets (3-D centres and velocities) and its approach tolerance."""

    pa: Vec3
    pb: Vec3
    va: Vec3
    vb: Vec3
    tol: float


@dataclass(slots=True)
class Pair:
    """A built pair: the client, the two body ids and what the ask needs.

    ``world`` and ``shapes`` say where the bodies go back; ``pooled`` False: they are
    removed on release.
    """

    cid: int
    dim: int
    a: int
    b: int
    bound: float
    world: World
    shapes: tuple[int, int]
    pooled: bool
    motion: Motion | None = None
    max_steps: int = 0


def pair(world_name: str, settings: dict[str, float], response: bool,
         a: tuple[str, tuple[float, ...], float], b: tuple[str, tuple[float, ...], float],
         a_center: Vec3, b_center: Vec3, dim: int, pooled: bool) -> Pair:
    """Two bodies (``(geometry, size, mass)``: a sphere's radius, a box's half-widths) at the
    centres in the world ``world_name``; the client is replaced first when it holds too many
    shapes and none of its bodies is out."""
    w = world(world_name, settings, response=response)
    (geom_a, size_a, mass_a), (geom_b, size_b, mass_b) = a, b
    if (not w.busy and len(w.shapes) + 2 > SHAPE_LIMIT
            and ((geom_a, size_a) not in w.shapes or (geom_b, size_b) not in w.shapes)):
        recycle(w)
    sa, sb = shape(w, geom_a, size_a), shape(w, geom_b, size_b)
    taken: list[int] = []
    try:
        taken.append(take(w, sa, mass_a, a_center, pooled))
        taken.append(take(w, sb, mass_b, b_center, pooled))
        return Pair(w.cid, dim, taken[0], taken[1], 1.0 + 2.0 * math.dist(a_center, b_center),
                    w, (sa, sb), pooled)
    except Exception:
        for body, sid in zip(taken, (sa, sb), strict=False):
            give_back(w, body, sid, pooled)
        raise


def detect(built: Pair) -> Answer:
    """The verdict (contact points after collision detection), the deepest closest point's
    distance and its normal (flipped: A to B)."""
    bt, cid = engine(), built.cid
    bt.performCollisionDetection(physicsClientId=cid)
    hit = len(bt.getContactPoints(built.a, built.b, physicsClientId=cid)) > 0
    points = bt.getClosestPoints(built.a, built.b, built.bound, physicsClientId=cid)
    if not points:
        return {"hit": hit}
    deepest = min(points, key=lambda point: point[8])
    normal = tuple(-float(x) for x in deepest[7][:built.dim])
    return {"hit": hit, "distance": float(deepest[8]), "normal": normal}


def response_pair(world_name: str, settings: dict[str, float], body_settings: dict[str, float],
                  a: tuple[str, tuple[float, ...], float], b: tuple[str, tuple[float, ...], float],
                  a_center: Vec3, b_center: Vec3, a_velocity: Vec3, b_velocity: Vec3,
                  restitution: float, dim: int, pooled: bool, tol: float,
                  max_steps: int) -> Pair:
    """:func:`pair` of two dynamic bodies, their dynamics set, and the motion to reset."""
    built = pair(world_name, settings, True, a, b, a_center, b_center, dim, pooled)
    try:
        with quiet():
            for body, mass, e in ((built.a, a[2], restitution), (built.b, b[2], 1.0)):
                reused = {"mass": mass} if built.pooled else {}  # a new body has its mass
                engine().changeDynamics(body, -1, restitution=e, **reused, **body_settings,
                                        physicsClientId=built.cid)
    except Exception:
        release(built)
        raise
    built.motion = Motion(a_center, b_center, a_velocity, b_velocity, tol)
    built.max_steps = max_steps
    return built


def respond(built: Pair) -> Answer:
    """Reset, then step until the bodies no longer approach: their velocities and where the
    solver first met the contact."""
    bt, cid, m = engine(), built.cid, built.motion
    assert m is not None, "a response pair"
    for body, p, v in ((built.a, m.pa, m.va), (built.b, m.pb, m.vb)):
        bt.resetBasePositionAndOrientation(body, p, (0.0, 0.0, 0.0, 1.0), physicsClientId=cid)
        bt.resetBaseVelocity(body, v, (0.0, 0.0, 0.0), physicsClientId=cid)
    resolved: tuple[Vec3, Vec3] | None = None
    for _ in range(built.max_steps):
        pa = bt.getBasePositionAndOrientation(built.a, physicsClientId=cid)[0]
        pb = bt.getBasePositionAndOrientation(built.b, physicsClientId=cid)[0]
        bt.stepSimulation(physicsClientId=cid)
        if resolved is None and bt.getContactPoints(built.a, built.b, physicsClientId=cid):
            resolved = (pa, pb)  # the first step that reported the contact started here
        va = bt.getBaseVelocity(built.a, physicsClientId=cid)[0]
        vb = bt.getBaseVelocity(built.b, physicsClientId=cid)[0]
        if not approach_speed(pa, pb, va, vb) > m.tol:  # NaN (coincident): stop
            break
    if built.dim == 3:
        return {"v1": tuple(va), "v2": tuple(vb), "resolved_at": resolved}
    if abs(va[2]) > 0.0 or abs(vb[2]) > 0.0:  # NaN passes through, as the engine gave it
        raise RuntimeError(f"2-D response left the plane z = 0: vz = {va[2]!r}, {vb[2]!r}")
    at = None if resolved is None else (tuple(resolved[0][:2]), tuple(resolved[1][:2]))
    return {"v1": tuple(va[:2]), "v2": tuple(vb[:2]), "resolved_at": at}


def release(built: Pair) -> None:
    """The bodies back to their pool (a response body only if it ended fit to reuse, at
    rest), or removed."""
    for body, sid in ((built.a, built.shapes[0]), (built.b, built.shapes[1])):
        keep = built.pooled
        if keep and built.motion is not None:
            keep = settled(built.cid, body)
            if keep:  # an idle body stands still through other cases' steps
                engine().resetBaseVelocity(body, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                                           physicsClientId=built.cid)
        give_back(built.world, body, sid, keep)


SCENE_IDLE_CLIENTS = 6
"""Emptied scene clients kept for the next scenes, whatever their settings."""
_SCENE_IDLE: list[tuple[tuple[tuple[str, float], ...], int]] = []
"""Emptied scene clients and their world settings, least recently released first."""


def scene_world(world_settings: dict[str, float], dt: float,
                iterations: int | None) -> dict[str, float]:
    """A scene's ``setPhysicsEngineParameter`` arguments: the variant's, with the scene's
    fixed step (no sub-steps) and iterations."""
    settings = dict(world_settings)
    settings.update(fixedTimeStep=dt, numSubSteps=0)
    if iterations is not None:
        settings["numSolverIterations"] = iterations
    return settings


def _scene_client(settings: dict[str, float]) -> int:
    """The most recently emptied client of these world settings, or a new one."""
    key = tuple(sorted(settings.items()))
    for k in range(len(_SCENE_IDLE) - 1, -1, -1):
        if _SCENE_IDLE[k][0] == key:
            return _SCENE_IDLE.pop(k)[1]
    return connect(settings)


def _add_wall(cid: int, normal: Any, offset: float, restitution: float,
              body: dict[str, float], maximal: bool) -> int:
    bt = engine()
    n = to3(normal)
    friction = {key: value for key, value in body.items() if key.endswith("Friction")}
    with quiet():
        plane = bt.createCollisionShape(bt.GEOM_PLANE, planeNormal=n, physicsClientId=cid)
        uid: int = bt.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=plane,
                                      basePosition=tuple(offset * x for x in n),
                                      useMaximalCoordinates=maximal, physicsClientId=cid)
        bt.changeDynamics(uid, -1, restitution=math.sqrt(restitution), **friction,
                          physicsClientId=cid)
    return uid


def _add_sphere(cid: int, shapes: dict[float, int], sphere: Any, restitution: float,
                body: dict[str, float], maximal: bool, ccd: float) -> int:
    bt = engine()
    center, radius, mass, velocity = sphere
    extra = dict(body)
    if ccd > 0.0:
        extra["ccdSweptSphereRadius"] = ccd * radius
    with quiet():
        if radius not in shapes:
            shapes[radius] = bt.createCollisionShape(bt.GEOM_SPHERE, radius=radius,
                                                     physicsClientId=cid)
        uid: int = bt.createMultiBody(baseMass=mass, baseCollisionShapeIndex=shapes[radius],
                                      basePosition=to3(center), useMaximalCoordinates=maximal,
                                      physicsClientId=cid)
        bt.changeDynamics(uid, -1, restitution=math.sqrt(restitution), **extra,
                          physicsClientId=cid)
    bt.resetBaseVelocity(uid, to3(velocity), (0.0, 0.0, 0.0), physicsClientId=cid)
    return uid


def scene(bodies: tuple[Any, ...], dim: int, restitution: float, dt: float,
          iterations: int | None, gravity: tuple[float, ...], walls: tuple[Any, ...],
          steps: int, record_every: int, world_settings: dict[str, float],
          body: dict[str, float], maximal: bool, ccd: float) -> dict[str, Any]:
    """The scene in a client of its own (see the module docstring)."""
    check_scene(bodies, dim, restitution, dt)
    check_surroundings(gravity, walls, dim)
    settings = scene_world(world_settings, dt, iterations)
    cid = _scene_client(settings)
    built: dict[str, Any] = {
        "cid": cid, "dim": dim, "spheres": (), "key": tuple(sorted(settings.items())),
        "dt": dt, "steps": steps, "record_every": record_every, "bodies": bodies,
        "gravity": gravity, "walls": walls}
    shapes: dict[float, int] = {}
    try:
        if any(gravity):
            engine().setGravity(*to3(gravity), physicsClientId=cid)
        built["planes"] = tuple(_add_wall(cid, normal, offset, restitution, body, maximal)
                                for normal, offset in walls)
        built["spheres"] = tuple(_add_sphere(cid, shapes, sphere, restitution, body, maximal,
                                             ccd) for sphere in bodies)
    except Exception:
        release_scene(built)
        raise
    return built


def scene_state(built: dict[str, Any]) -> tuple[list[Any], list[Any]]:
    """The 3-D centres and linear velocities of the scene's spheres, in scene order."""
    bt, cid = engine(), built["cid"]
    positions = [bt.getBasePositionAndOrientation(b, physicsClientId=cid)[0]
                 for b in built["spheres"]]
    velocities = [bt.getBaseVelocity(b, physicsClientId=cid)[0] for b in built["spheres"]]
    return positions, velocities


def step_scene(built: dict[str, Any], clock: Any = time.perf_counter) -> Answer:
    """Step the scene to its end (only ``stepSimulation`` is timed, by ``clock``): the final
    state, the measures and the trajectory."""
    # one stepSimulation call per step, as a C partial: no Python frame in the timed loop
    step = functools.partial(engine().stepSimulation, physicsClientId=built["cid"])
    dim = built["dim"]

    def read() -> tuple[Any, Any]:
        positions, velocities = scene_state(built)
        return (in_scene_dim(dim, positions, "position"),
                in_scene_dim(dim, velocities, "velocity"))

    wall_s, records = step_and_record(step, read, built["steps"], built["record_every"], clock)
    return scene_answer(built["bodies"], built["gravity"], built["walls"], built["dt"],
                        built["steps"], read(), records, wall_s)


def idle_scene_clients() -> int:
    """How many emptied scene clients are kept for the next scenes."""
    return len(_SCENE_IDLE)


def drop_idle_scene_clients() -> None:
    """Disconnect every kept scene client (the next scene connects a new one)."""
    with quiet():
        while _SCENE_IDLE:
            engine().disconnect(physicsClientId=_SCENE_IDLE.pop()[1])


def release_scene(built: dict[str, Any]) -> None:
    """Empty the scene's client and keep it for a next scene of the same world settings, with
    gravity 0 and those settings set again (the least recently released past
    ``SCENE_IDLE_CLIENTS`` disconnected)."""
    bt, cid = engine(), built["cid"]
    with quiet():
        bt.resetSimulation(physicsClientId=cid)
        bt.setGravity(0.0, 0.0, 0.0, physicsClientId=cid)
        if built["key"]:
            bt.setPhysicsEngineParameter(**dict(built["key"]), physicsClientId=cid)
        _SCENE_IDLE.append((built["key"], cid))
        if len(_SCENE_IDLE) > SCENE_IDLE_CLIENTS:
            bt.disconnect(physicsClientId=_SCENE_IDLE.pop(0)[1])


@dataclass(frozen=True, slots=True)
class Shapes:
    """A detection pair of spheres as two cached collision shapes, no body: the client, the
    shape ids, the 3-D centres and the closest points' bound.  Nothing is out, so a later
    build may replace the client (:func:`recycle`): ask before building the next pair."""

    cid: int
    dim: int
    shapes: tuple[int, int]
    centres: tuple[Vec3, Vec3]
    bound: float


def sphere_shapes(world_name: str, settings: dict[str, float],
                  a: tuple[str, tuple[float, ...], float], b: tuple[str, tuple[float, ...], float],
                  a_center: Vec3, b_center: Vec3, dim: int) -> Shapes:
    """The shapes of ``a`` and ``b`` (``(geometry, size, mass)``, as :func:`pair` takes them;
    the mass unused) in the world ``world_name``, replaced first as :func:`pair` does."""
    w = world(world_name, settings)
    keys = ((a[0], a[1]), (b[0], b[1]))
    if not w.busy and len(w.shapes) + 2 > SHAPE_LIMIT and any(k not in w.shapes for k in keys):
        recycle(w)
    sids = (shape(w, *keys[0]), shape(w, *keys[1]))
    return Shapes(w.cid, dim, sids, (a_center, b_center),
                  1.0 + 2.0 * math.dist(a_center, b_center))


def closest(built: Shapes) -> Answer:
    """The deepest of ``getClosestPoints`` on the shapes (no body): its distance, its normal
    (flipped: A to B) and the verdict, distance <= 0 (Bullet's sphere-sphere algorithm adds a
    contact point exactly then, for closest points and contacts alike)."""
    (sa, sb), (pa, pb) = built.shapes, built.centres
    points = engine().getClosestPoints(
        -1, -1, built.bound, collisionShapeA=sa, collisionShapeB=sb,
        collisionShapePositionA=pa, collisionShapePositionB=pb, physicsClientId=built.cid)
    if not points:
        return {"hit": False}
    deepest = min(points, key=lambda point: point[8])
    normal = tuple(-float(x) for x in deepest[7][:built.dim])
    return {"hit": float(deepest[8]) <= 0.0, "distance": float(deepest[8]), "normal": normal}
