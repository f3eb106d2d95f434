"""The engines' continuous-collision switches as variants: ``pybullet-ccd``, ``box2d-bullet``,
``rapier-ccd``.

Each is its engine's tuned variant with the engine's own CCD switch turned on for every body,
and runs scenes only (``sphere_scene``, in the dimensions its base steps them): the switch
is what fast-body scenes (two spheres crossing at a per-step travel ``|vb - va| dt / 2(ra +
rb)`` above 1) exercise, where a missed impact, the bodies passing through each other, is a
named failure.  The scene runners build the switch (:mod:`adapters.pybullet_scene`,
:mod:`adapters.box2d_world`, :mod:`adapters.rapier_scene`), whose docstrings hold what was
measured; the repro scripts write it (``crosscheck.studies.repro.scenes``,
``scenes_box2d``, ``scenes_rapier``).

- ``pybullet-ccd``: ``ccdSweptSphereRadius`` 0.9 r on every sphere, which Bullet reads only on
  a rigid body: the spheres are maximal-coordinates bodies (``createMultiBody(...,
  useMaximalCoordinates=True)``, a ``btRigidBody``), since ``changeDynamics`` sets no CCD on a
  multibody (pybullet's default, the tuned variant's) and Bullet's CCD runs over rigid bodies
  only.  pybullet sets the motion threshold itself (half the swept radius).  Sources:
  PhysicsServerCommandProcessor.cpp (``processChangeDynamicsInfoCommand``),
  btDiscreteDynamicsWorld.cpp (``createPredictiveContactsInternal``,
  ``integrateTransformsInternal``).  It catches every impact measured, but a caught impact
  is solved first by a predictive contact of restitution 0, so most of the bounce is lost.
- ``box2d-bullet``: every disc a bullet (``bullet=True``): Box2D's time of impact acts
  between two dynamic bodies only if one is a bullet (b2World.cpp ``SolveTOI``).  The speed
  cap stays (``b2_maxTranslation``, 2 m a step, declared as the tuned variant's).
- ``rapier-ccd``: every body ``ccd_enabled``, on the tuned variant, whose soft CCD already
  catches every impact measured; the switch itself acts between a bullet and fixed or
  non-bullet bodies only ("a bullet never sweeps another bullet", rigid_body.rs).

Conventions: each declares ``sampled_contacts`` False (contacts are swept or predicted, not
only found at step starts), the rest as its tuned base; ``pybullet-ccd`` also declares
``restitution_model`` "predictive" (a caught impact is first met with restitution 0) and no
speed cap (a rigid body has no multibody clamp).
"""

from __future__ import annotations

from dataclasses import replace
from typing import ClassVar

from adapters import box2d_engine, pybullet_engine, rapier_engine
from adapters.box2d_engine import Box2dTuned
from adapters.box2d_world import Variant
from adapters.pybullet_engine import PyBulletTuned
from adapters.pybullet_scene import Tuning as PyBulletTuning
from adapters.pybullet_setup import TUNED_BODY, TUNED_WORLD
from adapters.rapier_engine import RapierTuned
from adapters.rapier_scene import Tuning as RapierTuning
from crosscheck.core.contract import Capability, Conventions, all_capabilities
from crosscheck.core.model import Kind

CCD_FRACTION = 0.9
"""pybullet-ccd: each sphere's ``ccdSweptSphereRadius`` as a fraction of its radius."""

PYBULLET_CCD_SOURCES = (
    pybullet_engine.GH + "examples/SharedMemory/PhysicsServerCommandProcessor.cpp",
    pybullet_engine.GH + "src/BulletDynamics/Dynamics/btDiscreteDynamicsWorld.cpp",
)
BOX2D_BULLET_SOURCES = (
    box2d_engine.B2 + "Dynamics/b2World.cpp",  # SolveTOI: collideA = IsBullet() || not dynamic
    box2d_engine.B2 + "Dynamics/b2Body.h",  # b2BodyDef.bullet
)
RAPIER_CCD_SOURCES = (
    rapier_engine.RAPIER + "src/dynamics/rigid_body.rs",  # enable_ccd: bullets
    rapier_engine.RAPIER + "src/dynamics/ccd/ccd_solver.rs",  # pass 1 fixed, pass 2 bullets
)


class PyBulletCcd(PyBulletTuned):
    """PyBullet tuned, spheres as rigid bodies with a swept sphere of 0.9 r (scenes only)."""

    name: ClassVar[str] = "pybullet-ccd"
    settings: ClassVar[str] = (
        "the pybullet variant's settings; scenes only: every sphere a maximal-coordinates "
        "body (createMultiBody useMaximalCoordinates=True, a btRigidBody) with "
        f"changeDynamics ccdSweptSphereRadius = {CCD_FRACTION} x its radius (pybullet sets "
        "ccdMotionThreshold to half of it)")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE_SCENE)
    scene_tuning: ClassVar[PyBulletTuning | None] = PyBulletTuning(
        TUNED_WORLD, TUNED_BODY, maximal=True, ccd=CCD_FRACTION)
    conventions: ClassVar[Conventions] = replace(
        PyBulletTuned.conventions,
        sampled_contacts=False,
        max_speed=None, max_speed_at="",
        restitution_model="predictive",
        notes=("Scenes only.  Bullet CCD on rigid (maximal-coordinates) bodies: a sphere "
               "moving more than half its swept radius (0.9 r) in a step is swept against "
               "the others; a hit makes a predictive contact (restitution 0: m_combinedRestitution "
               "= 0 in createPredictiveContactsInternal, declared restitution_model "
               "predictive) and clamps the motion to the hit (btDiscreteDynamicsWorld.cpp), "
               "so no pass-through was measured but a caught impact keeps only part of its "
               "bounce, between none and e of it.  Rigid bodies "
               "have no multibody speed clamp (100 m/s per coordinate).  Measured in "
               "adapters/pybullet_scene.py"),
        sources=pybullet_engine.SOURCES + PYBULLET_CCD_SOURCES,
    )


class Box2dBullet(Box2dTuned):
    """Box2D tuned with every disc a bullet: continuous collision between dynamic bodies."""

    name: ClassVar[str] = "box2d-bullet"
    variant: ClassVar[Variant] = replace(Box2dTuned.variant, bullet=True)
    settings: ClassVar[str] = (
        "the box2d variant's settings (scenes: the scene's dt and iterations, friction 0, "
        "fixedRotation, sleeping off); every disc a bullet (b2BodyDef bullet=True)")
    capabilities: ClassVar[frozenset[Capability]] = frozenset({(Kind.SPHERE_SCENE, 2)})
    scene_tuning: ClassVar[Variant | None] = variant
    conventions: ClassVar[Conventions] = replace(
        Box2dTuned.conventions,
        sampled_contacts=False,
        notes=("Scenes only (2-D).  Every disc a bullet: b2World::SolveTOI finds the time of "
               "impact of a contact between two dynamic bodies when one is a bullet, moves "
               "the pair there and solves it with restitution.  The speed cap stays: "
               "b2_maxTranslation, 2 m a step (declared max_speed 2 / dt at the declared "
               "time step: 2 m per step at any dt).  Walls as the box2d variant's (no skin, "
               "rest band -b2_linearSlop to 0, no sleeping); every variant's discs are swept "
               "against static walls, bullets or not.  Measured in adapters/box2d_scene.py"),
        sources=Box2dTuned.conventions.sources + BOX2D_BULLET_SOURCES,
    )


class RapierCcd(RapierTuned):
    """Rapier tuned with every body ``ccd_enabled`` (scenes only)."""

    name: ClassVar[str] = "rapier-ccd"
    settings: ClassVar[str] = (
        "the rapier variant's settings (soft_ccd_prediction 1e30 among them); every body "
        "ccd_enabled(True)")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE_SCENE)
    scene_tuning: ClassVar[RapierTuning | None] = RapierTuning(RapierTuned.parameters, ccd=True)
    conventions: ClassVar[Conventions] = replace(
        RapierTuned.conventions,
        sampled_contacts=False,
        notes=("Scenes only.  Every body ccd_enabled (a bullet: swept against fixed and "
               "non-bullet bodies, never against another bullet, rigid_body.rs), on the "
               "tuned variant's soft CCD (predictive contacts whatever the travel).  "
               "Measured in adapters/rapier_scene.py: ccd_enabled changes no fast-body "
               "result; soft CCD catches them.  Gravity and walls as the tuned variant's "
               "(half-spaces; resting gap and elastic drops measured equal to it, "
               "adapters/rapier_walls.py)"),
        sources=RapierTuned.conventions.sources + RAPIER_CCD_SOURCES,
    )
