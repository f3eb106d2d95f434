"""PyBullet 3.2.7 stepping a scene of N spheres: the variants' settings, and what was measured.

What it is for: a scene (N spheres, one restitution, in open space or with gravity and static
walls) is stepped with a fixed ``dt`` by the scene calls of :mod:`adapters.pybullet.calls`
(``scene``, ``step_scene``, ``release_scene``), which return the final state (and the
trajectory), to be scored against the exact reference.  Here: each variant's
:class:`Tuning` and the inputs it gives the calls (:func:`scene_settings`), and the
conventions as measured with those calls.  Checks and recording are shared
(:mod:`adapters.shared.scene`).

Building (``scene``, untimed): a DIRECT client of its own per scene (``connect`` of
:mod:`adapters.pybullet.calls`, never the pooled clients of its pairs; the same
module's ``engine()`` and ``quiet()`` import pybullet and keep its C-level output off
stdout/stderr), gravity 0 (the scene's gravity, ``setGravity``, when it has one: open
space makes no extra call), ``setPhysicsEngineParameter`` with
``fixedTimeStep`` dt, ``numSubSteps`` 0 (one step advances exactly dt: a free sphere at
speed 1 is at 1.0000000000000007 after 1000 steps of 1e-3) and ``numSolverIterations`` if
given (else pybullet's 50, read back with ``getPhysicsEngineParameters``).  One base-only
multibody per sphere (``createCollisionShape(GEOM_SPHERE)``, shared per radius, and
``createMultiBody``), its velocity set with ``resetBaseVelocity`` (no spin); only the
declared bodies, and one static body per wall (below).  ``step_scene`` times only
``stepSimulation`` (a ``functools.partial``: no Python frame per step) through
``adapters.shared.scene.step_and_record`` and reads ``getBasePositionAndOrientation`` /
``getBaseVelocity`` after it (and between recorded runs of steps, untimed);
``release_scene`` empties the client with ``resetSimulation`` (bodies and shapes go with it)
and keeps it for the next scene of the same world settings, which sets gravity 0 and those
settings again (``SCENE_IDLE_CLIENTS`` kept in all, the least recently used disconnected: a
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
the pair e; its friction is what the variant gives spheres (the friction keys of ``body``: tuned
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

Measured outside the suite with throwaway scripts stepping the scene as these calls do, e.g.
the resting sphere (radius 0.1 on the ground z = 0, gravity -9.81, 10 s, every step recorded;
likewise the drop, a column, a ball between two walls, a gas).

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

Conventions, measured with the scene calls (sources as cited in ``adapters.pybullet.SOURCES``):

- restitution: Bullet combines the two bodies' restitutions by their product
  [btManifoldResult.cpp]; measured: bodies set to 0.5 and 0.8 bounce with 0.4 (not the
  min 0.5, mean 0.65 or max 0.8).  Every body gets sqrt(e), so every pair gets e (to an
  ulp; e = 0.25, 0.5, 0.81 measured exactly in the tuned variant).
- 2-D: spheres at z = 0 with vz = 0.  Contact normals between centres in the plane lie in
  it, so z and vz stay exactly 0 (measured over 3 s of 16 colliding spheres, oblique
  contacts, default friction 0.5 included); ``step_scene`` returns 2-tuples and raises if
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

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any


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


def scene_settings(tuning: Tuning | None) -> dict[str, Any]:
    """A variant's inputs to the scene calls besides the scene: its ``world`` settings
    (``world_settings``), per-sphere ``body`` settings, ``maximal`` and ``ccd`` (None: engine
    defaults, nothing set).

    >>> scene_settings(Tuning({"contactSlop": 0.0}, {"linearDamping": 0.0}, ccd=0.9))["ccd"]
    0.9
    >>> scene_settings(None)
    {'world_settings': {}, 'body': {}, 'maximal': False, 'ccd': 0.0}
    """
    if tuning is None:
        return {"world_settings": {}, "body": {}, "maximal": False, "ccd": 0.0}
    return {"world_settings": dict(tuning.world), "body": dict(tuning.body),
            "maximal": tuning.maximal, "ccd": tuning.ccd}
