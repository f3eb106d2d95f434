"""PyBullet 3.2.7 stepping a scene of N spheres, for comparison with an exact event-driven run.

What it is for: the scene runners step a whole scene (N spheres, one restitution, in open
space or in :class:`adapters.scene.Surroundings`: gravity and static walls) with a fixed
``dt`` and return the final state (and, with ``record_every``, the trajectory), to be scored
against the exact reference; :mod:`adapters.pybullet` answers single pair cases
instead.  Types and input checks are shared with :mod:`adapters.pymunk_scene` in
:mod:`adapters.scene`.

Building (``prepare_scene``, untimed): a DIRECT client of its own per scene (``connect`` of
:mod:`adapters.pybullet.calls`, never the pooled clients of its pairs; the same
module's ``engine()`` and ``quiet()`` import pybullet and keep its C-level output off
stdout/stderr), gravity 0 (the scene's gravity, ``setGravity``, when it has one: open
space makes no extra call), ``setPhysicsEngineParameter`` with
``fixedTimeStep`` dt, ``numSubSteps`` 0 (one step advances exactly dt: a free sphere at
speed 1 is at 1.0000000000000007 after 1000 steps of 1e-3) and ``numSolverIterations`` if
given (else pybullet's 50, read back with ``getPhysicsEngineParameters``).  One base-only
multibody per sphere (``createCollisionShape(GEOM_SPHERE)``, shared per radius, and
``createMultiBody``), its velocity set with ``resetBaseVelocity`` (no spin); only the
declared bodies, and one static body per wall (below).  ``run_scene`` times only
``stepSimulation`` (a ``functools.partial``: no Python frame per step) through
``adapters.scene.step_and_record`` and reads ``getBasePositionAndOrientation`` /
``getBaseVelocity`` after it (and between recorded runs of steps, untimed);
``release_scene`` empties the client with ``resetSimulation`` (bodies and shapes go with it)
and keeps it for the next scene of the same world settings, which sets gravity 0 and those
settings again (:data:`IDLE_CLIENTS` kept in all, the least recently used disconnected: a
connect costs 30-50 ms here, and well over 200 ms once a process holds 16 clients; a reset
0.2 ms).  A scene runs bit for bit the same in a reset client as in a new one: the
scene suite's PyBullet rows were compared both ways when this was introduced.

Walls, as pybullet users model a ground (``plane.urdf`` is a plane): each wall is a
``createCollisionShape(GEOM_PLANE, planeNormal=n)`` (a ``btStaticPlaneShape``, plane constant
0: pybullet.c sends 0) on a mass-0 base at ``offset x n`` (``isFixedBase``: static, never
moved), in the spheres' coordinates (multibody; rigid in the CCD variant).  A plane is a
half-space, not a box: the sphere-plane distance is signed, so any depth is a contact and
nothing tunnels through it, with no size to choose and no float32 concern (Bullet is double
here).  A 2-D wall is the plane with the wall's in-plane normal (z component 0).  Static
bodies get StaticFilter, whose mask excludes static bodies: walls never collide with each
other.  The wall's restitution is sqrt(e), like every sphere's, so the product rule gives
the pair e; its friction is what the variant gives spheres (``wall_settings``: tuned
lateral/rolling/spinning 0, default pybullet's 0.5 lateral, no rolling or spinning), no
damping to set.  Margins, slop and sleeping stay the variant's:

- contact points: btConvexPlaneCollisionAlgorithm adds a sphere-plane point below the
  manifold's breaking threshold: a speculative contact.  That threshold is relative
  (btCollisionDispatcher's default ``CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD``): the
  smaller shape's ``getAngularMotionDisc() x contactBreakingThreshold`` (0.02,
  ``gContactBreakingThreshold`` in btPersistentManifold.cpp), for a sphere its AABB's
  half-diagonal, so 0.02 sqrt(3) r (bisected: 0.0034641 for r = 0.1, 0.034641 for r = 1, in
  every variant).  A sphere that starts a step farther out and crosses the wall in it lands
  a step's travel deep (tuned, 1 m drop, dt 1/240: 2.9e-4 from 0.2 m, up to 2.5e-3). The
  solver then allows the gap to close within the step (velocity error ``-distance / dt`` for
  a positive distance, btMultiBodyConstraintSolver.cpp ``setupMultiBodyContactConstraint``;
  btSequentialImpulseConstraintSolver.cpp for rigid bodies) with the bounce ``e |v_n|``
  already in its target, so a sphere seen within the band leaves the wall slower than e
  says, or stops short of it.
  Measured (2-D, one ball between walls 1.8 apart, zero gravity, e = 1, 10 s, tuned): dt
  1/60 keeps 0.3, 1 and 3 m/s exactly (the path to a wall, 0.9, is a whole number of
  steps: every step starts touching or outside the band); dt 1/240
  stops 0.3 m/s at 0.0012 from the wall and lets 1 m/s fall to 0.63 by the 6th hit; dt 1e-3
  stops all three at the first wall.  With ``contactBreakingThreshold`` 0 (not a variant's
  setting) all keep their speed. Sphere-sphere contacts are unaffected (points only from
  touching).
- rest, tuned (contactSlop 0, contactERP 0): the target distance is 0 and no depth is ever
  pushed out (a landing depth stays).  A sphere placed on the ground stays at gap 0 with e =
  0, but restitutionVelocityThreshold 0 bounces the step's own |g| dt, so with e > 0 it
  rests at the speculative target, e |g| dt^2 above the ground (2.7e-3 at dt 1/60, e = 1),
  still. A column of three spheres creeps into the ground at ~3e-4 m/s (the iterative
  solver's residual, uncorrected), and with e = 1 it hops.  Default: target distance
  -contactSlop, corrected with contact ERP 0.08: a sphere rests at -1e-5 exactly; a column's
  bottom at -4e-5 (dt 1/60) / -1.8e-5 (dt 1/240), its sphere-sphere gaps within -slop - 0.11
  |g| dt^2.
- the CCD variant's walls are rigid bodies like its spheres (``useMaximalCoordinates``), so
  sphere-wall contacts are solved by the rigid-body solver, which takes the bounce from the
  velocity before the step's gravity (``getVelocityInLocalPoint``; the multibody solver sees
  it after): a sphere rests on a wall at gap 0 whatever e.  Bullet's CCD sweeps against the
  static plane (a dropped sphere at up to 300 m/s, dt 1/60, stops within 0.01 of it) and its
  predictive contact has restitution 0, as between spheres.
- sleeping: none.  createMultiBody without ``URDF_ENABLE_SLEEPING`` builds a multibody that
  cannot sleep, or a rigid body forced to DISABLE_DEACTIVATION [URDF2Bullet.cpp]; measured:
  a free sphere at 0.1 m/s (below both sleep thresholds) keeps it for 5 s, tuned and CCD.
- 2-D: gravity and wall normals lie in the plane, so z stays 0 (measured with friction,
  default variant, 25 discs in a walled box under gravity for 20 s).

Measured outside the suite with throwaway scripts calling this module, e.g. the resting
sphere: ``p = prepare_scene([((0, 0, 0.1), 0.1, 1.0, (0, 0, 0))], 3, e, dt, None, tuning,
Surroundings((0, 0, -9.81), (Wall((0, 0, 1), 0.0),)))`` then ``run_scene(p, round(10 / dt),
record_every=1).samples`` (likewise the drop, a column, a ball between two walls, a gas).

Variants (``tuning``, passed in by the adapter: a :class:`Tuning` or None): tuned
(``pybullet``) passes ``Tuning(TUNED_WORLD, TUNED_BODY)`` of ``adapters.pybullet``, the world
settings of the pair adapter (restitutionVelocityThreshold 0, contactSlop 0, contactERP 0;
its fixed step replaced by dt) and its per-body settings (lateral, rolling and spinning
friction 0, linear and angular damping 0).  Default (``pybullet-default``) passes None and
sets only what the scene declares: dt, iterations if given, masses, restitution.
CCD (``pybullet-ccd``, :mod:`adapters.pybullet`) passes the tuned settings with
``maximal`` True and ``ccd`` 0.9: every sphere is a maximal-coordinates body
(``createMultiBody(useMaximalCoordinates=True)``: a ``btRigidBody``, not a ``btMultiBody``)
with ``changeDynamics(ccdSweptSphereRadius=0.9 r)``.  Both are needed: ``changeDynamics``
applies ``ccdSweptSphereRadius`` only to a rigid body (its multibody branch has no CCD
setting), and sets the motion threshold to half the swept radius itself
(``setCcdMotionThreshold(radius / 2)``) [PhysicsServerCommandProcessor.cpp]; Bullet's CCD
(a swept-sphere test of each rigid body moving more than the threshold in a step, a
predictive contact and a motion clamp at the first hit) runs over rigid bodies only
[btDiscreteDynamicsWorld.cpp, ``createPredictiveContactsInternal`` and
``integrateTransformsInternal``].

Conventions, measured with this module (sources as cited in ``adapters.pybullet.SOURCES``):

- restitution: Bullet combines the two bodies' restitutions by their product
  [btManifoldResult.cpp]; measured: bodies set to 0.5 and 0.8 bounce with 0.4 (not the
  min 0.5, mean 0.65 or max 0.8).  Every body gets sqrt(e), so every pair gets e (to an
  ulp; e = 0.25, 0.5, 0.81 measured exactly in the tuned variant).
- 2-D: spheres at z = 0 with vz = 0.  Contact normals between centres in the plane lie in
  it, so z and vz stay exactly 0 (measured over 3 s of 16 colliding spheres, oblique
  contacts, default friction 0.5 included); ``run_scene`` returns 2-tuples and raises if
  a 2-D scene ever leaves the plane.
- touching at the start (distance exactly 0) is a contact: collision detection runs on
  the positions at the start of a step, and touching spheres make a point at distance 0.
  Two touching balls, one moving at 1 into the other: velocities exchanged in step 1; a
  touching pair moving together gets no impulse (0.3 each for 100 steps, exact in tuned).
- simultaneous contacts are solved together: a chain of touching balls answers as one
  rigid block.  5-ball cradle (equal masses, e = 1, striker at 1 into 4 touching balls):
  striker -0.5998, the four +0.39996 each, as one elastic hit on a mass-4 block (-0.6,
  0.4); 3 balls: -1/3, 2/3, 2/3.  Momentum is conserved to rounding, kinetic energy loses
  3.3e-4 of its value; with 1 solver iteration the striker stops and each of the four gets
  0.25 (energy 1/4 of it).  Not the textbook cradle (only the last ball moving).
- energy at e = 1, tuned: isolated contacts keep kinetic energy and momentum to rounding
  (16 random spheres, 2-D and 3-D, 3 s at dt 1e-3: relative change <= 2e-16, momentum
  3e-15).  Default: multibody damping 0.04 acts as a drag dv/dt = -0.04 (1 + |v|) v
  (measured at |v| = 0.5, 2, 10) and drains ~40% of the energy in 3 s; momentum is not kept.
- default only: overlapping bodies are pushed apart at a relative speed of 0.08 x (depth -
  contactSlop 1e-5) / dt (measured at rest, depths 1e-4..1e-2, dt 1e-3 and 1e-2), so a
  bounce separates up to 8% of the closing speed faster than e says (0.5% to 4.7%
  measured, depending on the depth at which the contact is first seen); approaches slower
  than restitutionVelocityThreshold 0.2 are inelastic [btContactSolverInfo.h].
- impacts are seen a step late: the first step that starts overlapped resolves them, so
  centres lag the exact run by up to the closing speed x dt (0.002 measured, dt 1e-3).
- contacts are sampled at step starts (tuned and default): a multibody has no CCD, and the
  sphere-sphere algorithm adds a point only at distance <= 0.  Two balls r = 0.05, m = 1,
  e = 1, head-on at +-v from 0.6 apart: at dt 1/240 they pass through each other from v = 20
  (step travel |vb - va| dt / 2(ra + rb) = 0.83: the step that finds them overlapping starts
  with the centres already crossed) and at dt 1/60 from v = 5 (travel 0.83).
- speed cap: a multibody's velocity coordinates are clamped to +-100 (``btMultiBody``
  ``m_maxCoordinateVelocity`` 100, in ``applyDeltaVeeMultiDof``, every step): a free ball at
  200 or 1000 ends at 100, per axis, not by the norm; changeDynamics ``maxJointVelocity``
  sets it.  Not declared as ``max_speed`` (see ``adapters.pybullet``).
- CCD variant (maximal-coordinates bodies, swept sphere 0.9 r), the same pair: no speed cap
  (1000 stays 1000); no pass-through at any v measured (5 to 1000, dt 1/240 and 1/60), but
  the bounce is lost: the predictive contact has restitution 0 (``m_combinedRestitution =
  0`` in ``createPredictiveContactsInternal``), so the solver stops the approach at the
  swept hit and only what is left of it bounces (dt 1/240: v = 20 ends at -0.6, v = 50 at
  -10.6, v = 200 and 1000 at -60.6; dt 1/60: v = 5 at -0.15, 50 to 1000 at -15.15).  Where
  the sweep clamps one ball and the next step starts with the pair overlapping, the ordinary
  contact bounces in full (dt 1/60, v = 20: -20 and 20, but B's centre 0.16 further out than
  A's mirror: only A was clamped).  Bodies are clamped one after another, each swept against
  the others' positions at the step's start.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from adapters.scene import (
    Body,
    SceneRun,
    Surroundings,
    Wall,
    check_scene,
    check_surroundings,
    in_scene_dim,
    step_and_record,
)
from adapters.shared.pybullet import connect, engine, quiet
from crosscheck.core.geometry import Vec3, to3

__all__ = ["Body", "SceneRun", "Tuning", "body_settings", "drop_idle_clients", "idle_clients",
           "prepare_scene", "release_scene", "run_scene", "wall_settings"]

ZERO: Vec3 = (0.0, 0.0, 0.0)

IDLE_CLIENTS = 6
"""Emptied clients kept for the next scenes, whatever their settings (the suite's scenes use
a dozen settings per variant; two of them are most scenes')."""

Settings = tuple[tuple[str, float], ...]
_IDLE: list[tuple[Settings, int]] = []
"""Emptied clients and their world settings, least recently released first."""


@dataclass(frozen=True)
class Tuning:
    """Settings a variant adds to a scene; ``None`` instead of a Tuning: engine defaults.

    ``world``: ``setPhysicsEngineParameter`` arguments (``fixedTimeStep`` and
    ``numSubSteps`` are replaced by the scene's); ``body``: ``changeDynamics`` arguments
    for every sphere.  ``maximal``: bodies in maximal coordinates (``btRigidBody``; else
    Bullet multibodies, pybullet's default); ``ccd``: each sphere's
    ``ccdSweptSphereRadius`` as a fraction of its radius (0: not set; acts on maximal
    bodies only, see the module docstring).
    """

    world: Mapping[str, float]
    body: Mapping[str, float]
    maximal: bool = False
    ccd: float = 0.0


def body_settings(radius: float, tuning: Tuning | None) -> dict[str, float]:
    """The ``changeDynamics`` settings of a sphere of ``radius`` (restitution apart).

    >>> body_settings(0.5, Tuning({}, {"linearDamping": 0.0}, maximal=True, ccd=0.9))
    {'linearDamping': 0.0, 'ccdSweptSphereRadius': 0.45}
    >>> body_settings(0.5, None)
    {}
    """
    settings: dict[str, float] = dict(tuning.body) if tuning is not None else {}
    if tuning is not None and tuning.ccd > 0.0:
        settings["ccdSweptSphereRadius"] = tuning.ccd * radius
    return settings


def wall_settings(tuning: Tuning | None) -> dict[str, float]:
    """The ``changeDynamics`` settings of a wall (restitution apart): the variant's
    friction settings (tuned: 0; default: pybullet's own), nothing else (a static body
    has no damping or CCD to set).

    >>> wall_settings(Tuning({}, {"lateralFriction": 0.0, "linearDamping": 0.0}))
    {'lateralFriction': 0.0}
    >>> wall_settings(None)
    {}
    """
    body = tuning.body if tuning is not None else {}
    return {key: value for key, value in body.items() if key.endswith("Friction")}


@dataclass(frozen=True, eq=False)
class Prepared:
    """A built scene: its own DIRECT client, the body ids (scene order), the dimension
    and the static walls' body ids."""

    cid: int
    dim: int
    bodies: tuple[int, ...]
    walls: tuple[int, ...] = ()
    settings: Settings = ()
    """The client's world settings (its ``setPhysicsEngineParameter`` arguments)."""


def _client(settings: dict[str, float]) -> int:
    """The most recently emptied client of these world settings, or a new one."""
    key = tuple(sorted(settings.items()))
    for k in range(len(_IDLE) - 1, -1, -1):
        if _IDLE[k][0] == key:
            return _IDLE.pop(k)[1]
    return connect(settings)


def world_settings(dt: float, iterations: int | None,
                   tuning: Tuning | None) -> dict[str, float]:
    """The ``setPhysicsEngineParameter`` arguments of a scene.

    >>> world_settings(1e-3, None, None)
    {'fixedTimeStep': 0.001, 'numSubSteps': 0}
    >>> from adapters.pybullet import TUNED_BODY, TUNED_WORLD
    >>> tuned = world_settings(1e-3, 20, Tuning(TUNED_WORLD, TUNED_BODY))
    >>> sorted(tuned)  # doctest: +NORMALIZE_WHITESPACE
    ['contactERP', 'contactSlop', 'fixedTimeStep', 'numSolverIterations', 'numSubSteps',
     'restitutionVelocityThreshold']
    >>> tuned["fixedTimeStep"], TUNED_WORLD["fixedTimeStep"] == 1 / 240
    (0.001, True)
    """
    settings: dict[str, float] = dict(tuning.world) if tuning is not None else {}
    settings.update(fixedTimeStep=dt, numSubSteps=0)
    if iterations is not None:
        settings["numSolverIterations"] = iterations
    return settings


def add_sphere(cid: int, shapes: dict[float, int], body: Body, restitution: float,
               tuning: Tuning | None) -> int:
    """One sphere of the scene with its velocity, restitution sqrt(e) and variant settings."""
    bt = engine()
    center, radius, mass, velocity = body
    extra = body_settings(radius, tuning)
    maximal = tuning is not None and tuning.maximal
    with quiet():
        if radius not in shapes:
            shapes[radius] = bt.createCollisionShape(bt.GEOM_SPHERE, radius=radius,
                                                     physicsClientId=cid)
        uid: int = bt.createMultiBody(baseMass=mass, baseCollisionShapeIndex=shapes[radius],
                                      basePosition=to3(center), useMaximalCoordinates=maximal,
                                      physicsClientId=cid)
        bt.changeDynamics(uid, -1, restitution=math.sqrt(restitution), **extra,
                          physicsClientId=cid)
    bt.resetBaseVelocity(uid, to3(velocity), ZERO, physicsClientId=cid)
    return uid


def add_wall(cid: int, wall: Wall, restitution: float, tuning: Tuning | None) -> int:
    """One static wall: a ``GEOM_PLANE`` (``btStaticPlaneShape``, plane constant 0) with the
    wall's normal, on a mass-0 base at ``offset x normal``, restitution sqrt(e)."""
    bt = engine()
    normal = to3(wall.normal)
    maximal = tuning is not None and tuning.maximal
    with quiet():
        shape = bt.createCollisionShape(bt.GEOM_PLANE, planeNormal=normal, physicsClientId=cid)
        uid: int = bt.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=shape,
                                      basePosition=tuple(wall.offset * n for n in normal),
                                      useMaximalCoordinates=maximal, physicsClientId=cid)
        bt.changeDynamics(uid, -1, restitution=math.sqrt(restitution),
                          **wall_settings(tuning), physicsClientId=cid)
    return uid


def prepare_scene(bodies: Sequence[Body], dim: int, restitution: float, dt: float,
                  iterations: int | None, tuning: Tuning | None,
                  surroundings: Surroundings | None = None) -> Any:
    """Build the scene in a new DIRECT client (untimed); ``release_scene`` disconnects it.

    ``tuning``: the variant's settings (see :class:`Tuning`), or None for engine defaults;
    ``surroundings``: gravity and static walls (None: open space, gravity 0, no walls).
    """
    check_scene(bodies, dim, restitution, dt)
    around = check_surroundings(surroundings, dim)
    settings = world_settings(dt, iterations, tuning)
    cid = _client(settings)
    key = tuple(sorted(settings.items()))
    shapes: dict[float, int] = {}
    try:
        if any(around.gravity):
            engine().setGravity(*to3(around.gravity), physicsClientId=cid)
        walls = tuple(add_wall(cid, wall, restitution, tuning) for wall in around.walls)
        ids = tuple(add_sphere(cid, shapes, body, restitution, tuning) for body in bodies)
    except Exception:
        release_scene(Prepared(cid, dim, (), settings=key))
        raise
    return Prepared(cid, dim, ids, walls, key)


def state(prepared: Any) -> tuple[list[Vec3], list[Vec3]]:
    """The 3-D centres and linear velocities of the scene's bodies, in scene order."""
    scene: Prepared = prepared
    bt, cid = engine(), scene.cid
    positions = [bt.getBasePositionAndOrientation(b, physicsClientId=cid)[0]
                 for b in scene.bodies]
    velocities = [bt.getBaseVelocity(b, physicsClientId=cid)[0] for b in scene.bodies]
    return positions, velocities


def run_scene(prepared: Any, steps: int, clock: Callable[[], float] = time.perf_counter,
              record_every: int = 0) -> SceneRun:
    """Step the scene ``steps`` times (only the stepping is timed, read from ``clock``
    around each run of steps) and read its final state; with ``record_every > 0`` also
    the state at the start and every ``record_every`` steps (``SceneRun.samples``)."""
    scene: Prepared = prepared
    # one stepSimulation call per step, as a C partial: no Python frame in the timed loop
    step = functools.partial(engine().stepSimulation, physicsClientId=scene.cid)

    def read() -> tuple[tuple[tuple[float, ...], ...], tuple[tuple[float, ...], ...]]:
        positions, velocities = state(scene)
        return (in_scene_dim(scene.dim, positions, "position"),
                in_scene_dim(scene.dim, velocities, "velocity"))

    wall, samples = step_and_record(step, read, steps, record_every, clock)
    positions, velocities = read()
    return SceneRun(positions, velocities, wall, steps, samples)


def idle_clients() -> int:
    """How many emptied clients are kept for the next scenes."""
    return len(_IDLE)


def drop_idle_clients() -> None:
    """Disconnect every kept client (the next scene connects a new one)."""
    with quiet():
        while _IDLE:
            engine().disconnect(physicsClientId=_IDLE.pop()[1])


def release_scene(prepared: Any) -> None:
    """Empty the scene's client (its bodies and shapes go with it) and keep it for a next
    scene of the same settings, with gravity 0 and those settings set again; past
    :data:`IDLE_CLIENTS` kept, the least recently released is disconnected."""
    scene: Prepared = prepared
    bt, cid = engine(), scene.cid
    with quiet():
        bt.resetSimulation(physicsClientId=cid)
        bt.setGravity(0.0, 0.0, 0.0, physicsClientId=cid)
        if scene.settings:
            bt.setPhysicsEngineParameter(**dict(scene.settings), physicsClientId=cid)
        _IDLE.append((scene.settings, cid))
        if len(_IDLE) > IDLE_CLIENTS:
            bt.disconnect(physicsClientId=_IDLE.pop(0)[1])
