"""PyBullet 3.2.7 (Bullet, double precision) as an engine: ``pybullet`` and ``pybullet-default``.

Each variant has one DIRECT client per process (no GUI), connected lazily, gravity 0, no
ground plane; world settings are global to a client, so the variants never share one.  A
case becomes two base-only multibodies (``createMultiBody``; mass 1 for detection, as
static pairs are never tested; the case's masses for responses) on collision shapes cached
by (geometry, size): ``release`` removes the bodies, never the shapes
(``removeCollisionShape`` leaks shapes still in use).  The banner and ``b3Warning`` lines
go to the C-level stdout/stderr, so import, connect, ``prepare`` and ``release`` run with
file descriptors 1 and 2 on /dev/null (``query`` prints nothing; a redirect costs ~8 us).

Detection: ``hit`` is the engine's verdict, "contact points exist" after
``performCollisionDetection`` (stale until then); Bullet's sphere-sphere and box-box
algorithms only add points at distance <= 0 (measured), so the breaking threshold plays no
part.  ``distance`` and ``normal``: the deepest point of ``getClosestPoints(A, B,
1 + 2|cB - cA|)`` (a bound above any possible gap), normal flipped.  2-D: discs are spheres
at z = 0; a 2-D box gets the z half-width 2 x the case's largest half-width (1 if all are
0), both centred at z = 0, so the z overlap exceeds any x or y overlap: z is never the axis
of least overlap nor a gap, and the 3-D answers are the 2-D ones (returned as 2-tuples).
2 x, not more, keeps the box small (see the AABB limit below).

Response: ``query`` resets centres (``resetBasePositionAndOrientation``) and velocities
(``resetBaseVelocity``, no spin), then calls ``stepSimulation`` until the relative velocity
along the line of centres the step detected from no longer approaches (not above 1e-12 x
the case's largest speed), at most 64 steps; it returns ``getBaseVelocity`` and, as
``resolved_at``, the centres before that step (None if never resolved).  2-D runs at z = 0
with vz = 0; a result with vz != 0 raises.

Conventions, measured here (sources in ``SOURCES``):

- box extents half (``halfExtents``); ``contactNormalOnB`` points from B to A [quickstart
  guide], flipped here.
- touching is contact: touching spheres give a point at distance 0 (``len > r0 + r1`` is
  the only reject) [btSphereSphereCollisionAlgorithm], face-touching boxes four at -0.0.
  Edge/corner-touching boxes read 0.00083/0.00146 apart, no contact: a box's 0.001
  collision margin rounds its edges [btBoxShape.h].  Declared margin 0.002 (both boxes;
  at most 2 (sqrt 3 - 1) 0.001); spheres are exact.  rtol 2^-50: a 2^-40 gap reads exactly.
- restitution: the product of the bodies' values [btManifoldResult.cpp]; A gets the case's
  e, B 1.0.  Below ``restitutionVelocityThreshold`` (0.2 by default) of approach a bounce
  is inelastic [btContactSolverInfo.h].  Separating contacts get no impulse (clamped >= 0)
  [btMultiBodyConstraintSolver.cpp]: resolves_separating False.

Other facts measured: multibody damping defaults to 0.04 [btMultiBody.cpp];
``contactSlop`` (1e-5) keeps slop/dt of the approach (0.0024 at dt 1/240), so a default
impact finishes a step late; starting overlapped, contact ERP adds energy; radii 0,
negative or NaN raise ``pybullet.error`` (box half-widths 0 or negative are accepted);
coincident sphere centres get (1, 0, 0) on B; a dynamic body whose AABB diagonal reaches
1e6 is dropped from collision ("Overflow in AABB") [btCollisionWorld.cpp]; creating a body
costs ~0.6 ms, a reset ~0.5 us.

Variants: ``pybullet`` (tuned for accuracy): restitutionVelocityThreshold 0, contactSlop 0,
contactERP 0 (erp and frictionERP do not act: no joints, no friction), fixed time step
1/240 s set explicitly; per body lateral, rolling and spinning friction 0, linear and
angular damping 0; boxes keep the 0.001 margin (margin 0 makes GJK read 2^-40 gaps as 0).
``pybullet-default``: only the case's geometry, masses, velocities and restitution;
everything else as pybullet sets it (damping 0.04, lateral friction 0.5, threshold 0.2,
contactSlop 1e-5, default contact ERP, dt 1/240 s).  Both set restitution by the product.
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import os
import sys
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from typing import Any, ClassVar

from adapters.base import Adapter, Capability, Conventions, all_capabilities
from crosscheck.model import Kind, Observation
from crosscheck.schema import AabbCase, AnyCase, ResponseCase

Vec3 = tuple[float, float, float]
Spec = tuple[str, tuple[float, ...], float]
"""A body to build: geometry, size (radius or half-widths) and mass."""

GH = "https://github.com/bulletphysics/bullet3/blob/master/"
SOURCES = (
    "https://docs.google.com/document/d/10sXEhzFRSnvFcl3XxNGhnD4N2SedqwdAvK3dsihxVUA",
    GH + "examples/pybullet/pybullet.c",
    GH + "src/BulletCollision/CollisionDispatch/btSphereSphereCollisionAlgorithm.cpp",
    GH + "src/BulletCollision/CollisionDispatch/btBoxBoxDetector.cpp",
    GH + "src/BulletCollision/CollisionDispatch/btCollisionWorld.cpp",
    GH + "src/BulletCollision/CollisionShapes/btBoxShape.h",
    GH + "src/BulletCollision/CollisionDispatch/btManifoldResult.cpp",
    GH + "src/BulletDynamics/ConstraintSolver/btContactSolverInfo.h",
    GH + "src/BulletDynamics/Featherstone/btMultiBodyConstraintSolver.cpp",
    GH + "src/BulletDynamics/Featherstone/btMultiBody.cpp",
)
BOX_MARGIN = 0.001
MAX_STEPS = 64
APPROACH_RTOL = 1e-12

_MODULE: list[Any] = []
_CLIENTS: dict[str, int] = {}
_SHAPES: dict[tuple[int, str, tuple[float, ...]], int] = {}


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


def client(name: str, world: dict[str, float]) -> int:
    """The DIRECT client of variant ``name``, connected and configured once per process."""
    if name not in _CLIENTS:
        bt = engine()
        with quiet():
            cid = bt.connect(bt.DIRECT)
            bt.setGravity(0.0, 0.0, 0.0, physicsClientId=cid)
            if world:
                bt.setPhysicsEngineParameter(**world, physicsClientId=cid)
        _CLIENTS[name] = cid
    return _CLIENTS[name]


def shape(cid: int, geom: str, size: tuple[float, ...]) -> int:
    """A cached collision shape: a sphere of radius size[0] or a box of half-widths size."""
    key = (cid, geom, size)
    if key not in _SHAPES:
        bt = engine()
        if geom == "sphere":
            sid = bt.createCollisionShape(bt.GEOM_SPHERE, radius=size[0], physicsClientId=cid)
        else:
            sid = bt.createCollisionShape(bt.GEOM_BOX, halfExtents=size, physicsClientId=cid)
        _SHAPES[key] = sid
    return _SHAPES[key]


def to3(v: Sequence[float]) -> Vec3:
    """A 2- or 3-vector as a 3-vector (z = 0 for 2-D)."""
    return (v[0], v[1], v[2] if len(v) > 2 else 0.0)


def box_sizes(case: AabbCase) -> tuple[Vec3, Vec3]:
    """3-D half-widths of the two boxes; 2-D boxes get the z half-width of the embedding."""
    if case.dim == 3:
        return to3(case.a.half), to3(case.b.half)
    hz = 2.0 * max(abs(h) for h in (*case.a.half, *case.b.half)) or 1.0
    return (case.a.half[0], case.a.half[1], hz), (case.b.half[0], case.b.half[1], hz)


def body_specs(case: AnyCase) -> list[Spec]:
    """The two bodies of a case."""
    if isinstance(case, AabbCase):
        size_a, size_b = box_sizes(case)
        return [("box", size_a, 1.0), ("box", size_b, 1.0)]
    if isinstance(case, ResponseCase):
        return [("sphere", (case.a.radius,), case.a.mass),
                ("sphere", (case.b.radius,), case.b.mass)]
    return [("sphere", (case.a.radius,), 1.0), ("sphere", (case.b.radius,), 1.0)]


def approach(pa: Sequence[float], pb: Sequence[float], va: Sequence[float],
             vb: Sequence[float]) -> float:
    """Speed at which A and B approach along the line of centres (negative: separating)."""
    d = [y - x for x, y in zip(pa, pb, strict=True)]
    length = math.sqrt(sum(x * x for x in d))
    rel = [x - y for x, y in zip(va, vb, strict=True)]
    return sum(r * c for r, c in zip(rel, d, strict=True)) / length if length > 0 else 0.0


@dataclass(frozen=True, slots=True)
class Motion:
    """What a response query resets (3-D centres and velocities) and its approach tolerance."""

    pa: Vec3
    pb: Vec3
    va: Vec3
    vb: Vec3
    tol: float


@dataclass(frozen=True, slots=True)
class Pair:
    """A prepared case: the client, the two body ids and what the query needs."""

    cid: int
    dim: int
    a: int
    b: int
    bound: float
    motion: Motion | None = None


class PyBulletTuned(Adapter):
    """PyBullet tuned for accuracy (see the module docstring)."""

    name: ClassVar[str] = "pybullet"
    engine: ClassVar[str] = "pybullet"
    settings: ClassVar[str] = (
        "DIRECT, gravity 0, dt 1/240 s (explicit), restitutionVelocityThreshold 0, "
        "contactSlop 0, contactERP 0; per body lateral/rolling/spinning friction 0, "
        "linear/angular damping 0; restitution A = e, B = 1 (product); "
        "boxes keep the default 0.001 collision margin")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(*Kind)
    world: ClassVar[dict[str, float]] = {
        "fixedTimeStep": 1.0 / 240.0, "restitutionVelocityThreshold": 0.0,
        "contactSlop": 0.0, "contactERP": 0.0}
    body: ClassVar[dict[str, float]] = {
        "lateralFriction": 0.0, "rollingFriction": 0.0, "spinningFriction": 0.0,
        "linearDamping": 0.0, "angularDamping": 0.0}
    conventions: ClassVar[Conventions] = Conventions(
        box_extents="half",
        normal="B to A (contactNormalOnB of getClosestPoints); flipped by the adapter",
        touching={"sphere": True},
        margin=2 * BOX_MARGIN,
        rtol=2.0**-50,
        restitution="product of the bodies' restitutions; the adapter sets A = e, B = 1",
        restitution_threshold=0.0,
        resolves_separating=False,
        notes=("hit = contact points exist after performCollisionDetection (touching spheres "
               "and face-touching boxes are contacts); the 0.001 box margin rounds edges and "
               "corners: edge/corner-touching boxes read 0.00083/0.00146 apart; dynamic "
               "bodies with an AABB diagonal >= 1e6 make no contacts; 2-D at z = 0, 2-D boxes "
               "get z half-width 2x the largest half-width; responses stepped until no longer "
               "approaching, resolved_at = the centres the resolving step detected from"),
        sources=SOURCES,
    )

    def version(self) -> str:
        from importlib.metadata import version

        return version("pybullet")

    def available(self) -> str | None:
        try:
            engine()
        except ImportError as exc:
            return f"pybullet not importable: {exc}"
        return None

    def prepare(self, case: AnyCase) -> Pair:
        cid, specs = client(self.name, self.world), body_specs(case)
        ca, cb = to3(case.a.center), to3(case.b.center)
        made: list[int] = []
        with quiet():
            shapes = [shape(cid, geom, size) for geom, size, _ in specs]
            try:
                for (*_, mass), sid, centre in zip(specs, shapes, (ca, cb), strict=True):
                    made.append(self._body(cid, sid, mass, centre))
                pair = Pair(cid, case.dim, made[0], made[1], 1.0 + 2.0 * math.dist(ca, cb))
                if isinstance(case, ResponseCase):
                    pair = replace(pair, motion=self._motion(pair, case))
            except Exception:
                for body in made:
                    engine().removeBody(body, physicsClientId=cid)
                raise
        return pair

    @staticmethod
    def _body(cid: int, sid: int, mass: float, centre: Vec3) -> int:
        body: int = engine().createMultiBody(baseMass=mass, baseCollisionShapeIndex=sid,
                                             basePosition=centre, physicsClientId=cid)
        return body

    def _motion(self, pair: Pair, case: ResponseCase) -> Motion:
        for body, e in ((pair.a, case.restitution), (pair.b, 1.0)):
            engine().changeDynamics(body, -1, restitution=e, **self.body,
                                    physicsClientId=pair.cid)
        speeds = [abs(x) for x in (*case.a.velocity, *case.b.velocity)]
        return Motion(to3(case.a.center), to3(case.b.center), to3(case.a.velocity),
                      to3(case.b.velocity), APPROACH_RTOL * max(speeds, default=0.0))

    def query(self, prepared: Any) -> Observation:
        pair: Pair = prepared
        if pair.motion is None:
            return self._detect(pair)
        return self._respond(pair, pair.motion)

    @staticmethod
    def _detect(pair: Pair) -> Observation:
        bt, cid = engine(), pair.cid
        bt.performCollisionDetection(physicsClientId=cid)
        hit = len(bt.getContactPoints(pair.a, pair.b, physicsClientId=cid)) > 0
        points = bt.getClosestPoints(pair.a, pair.b, pair.bound, physicsClientId=cid)
        if not points:
            return Observation(hit=hit)
        deepest = min(points, key=lambda point: point[8])
        normal = tuple(-float(x) for x in deepest[7][:pair.dim])
        return Observation(hit=hit, distance=float(deepest[8]), normal=normal)

    @staticmethod
    def _respond(pair: Pair, m: Motion) -> Observation:
        bt, cid = engine(), pair.cid
        for body, p, v in ((pair.a, m.pa, m.va), (pair.b, m.pb, m.vb)):
            bt.resetBasePositionAndOrientation(body, p, (0.0, 0.0, 0.0, 1.0), physicsClientId=cid)
            bt.resetBaseVelocity(body, v, (0.0, 0.0, 0.0), physicsClientId=cid)
        resolved: tuple[Vec3, Vec3] | None = None
        for _ in range(MAX_STEPS):
            pa = bt.getBasePositionAndOrientation(pair.a, physicsClientId=cid)[0]
            pb = bt.getBasePositionAndOrientation(pair.b, physicsClientId=cid)[0]
            bt.stepSimulation(physicsClientId=cid)
            va = bt.getBaseVelocity(pair.a, physicsClientId=cid)[0]
            vb = bt.getBaseVelocity(pair.b, physicsClientId=cid)[0]
            if not approach(pa, pb, va, vb) > m.tol:
                resolved = (pa, pb)
                break
        return observed(pair.dim, va, vb, resolved)

    def release(self, prepared: Any) -> None:
        pair: Pair = prepared
        with quiet():
            engine().removeBody(pair.a, physicsClientId=pair.cid)
            engine().removeBody(pair.b, physicsClientId=pair.cid)


def observed(dim: int, va: Vec3, vb: Vec3, resolved: tuple[Vec3, Vec3] | None) -> Observation:
    """A response observation in ``dim`` dimensions; a 2-D result must stay in z = 0."""
    if dim == 3:
        return Observation(v1=tuple(va), v2=tuple(vb), resolved_at=resolved)
    if abs(va[2]) > 0.0 or abs(vb[2]) > 0.0:  # NaN passes through, as the engine gave it
        raise RuntimeError(f"2-D response left the plane z = 0: vz = {va[2]!r}, {vb[2]!r}")
    at = None if resolved is None else (tuple(resolved[0][:2]), tuple(resolved[1][:2]))
    return Observation(v1=tuple(va[:2]), v2=tuple(vb[:2]), resolved_at=at)


class PyBulletDefault(PyBulletTuned):
    """PyBullet as a user gets it: only geometry, masses, velocities and restitution are set."""

    name: ClassVar[str] = "pybullet-default"
    settings: ClassVar[str] = (
        "DIRECT, gravity 0; restitution A = e, B = 1 (product); everything else default "
        "(damping 0.04, lateral friction 0.5, restitutionVelocityThreshold 0.2, "
        "contactSlop 1e-5, default contact ERP, dt 1/240 s)")
    world: ClassVar[dict[str, float]] = {}
    body: ClassVar[dict[str, float]] = {}
    conventions: ClassVar[Conventions] = replace(
        PyBulletTuned.conventions,
        restitution_threshold=0.2,
        notes=PyBulletTuned.conventions.notes
        + "; default damping 0.04, friction 0.5 and contactSlop 1e-5 act on responses",
    )
