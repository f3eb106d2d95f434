"""The engine part of a repro script for a scene (``sphere_scene``): pybullet and pymunk.

A scene is N spheres (discs in 2-D) with one restitution, stepped ``round(duration / dt)``
times with a fixed step, with no gravity and no ground.  The statements build it as
``adapters/pybullet_scene.py`` or ``adapters/pymunk_scene.py`` does, with the variant's
``scene_tuning`` read from the adapter (each body's restitution or elasticity is sqrt(e),
so every pair gets e), step it, and leave the final ``positions`` and ``velocities`` and,
computed as the harness computes them (``crosscheck.truth.scenes.observation``: exact sums
with ``math.fsum``), the total ``momentum`` and kinetic ``energy``.  The script's inputs are
the scene's bodies, restitution, time step, step count and solver iterations.
"""

from __future__ import annotations

from string import Template

from adapters import pybullet_scene, scene
from adapters.pybullet_engine import PyBulletTuned
from adapters.pymunk_engine import PymunkTuned
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.studies.repro.code import EngineCode, literal, raising, vector

STATE = """\
# The harness's scene observation: total momentum and kinetic energy (exact sums).
masses = [mass for _, _, mass, _ in BODIES]
momentum = tuple(math.fsum(m * v[i] for m, v in zip(masses, velocities, strict=True))
                 for i in range(len(positions[0])))
energy = math.fsum(0.5 * m * math.fsum(x * x for x in v)
                   for m, v in zip(masses, velocities, strict=True))
"""
PYMUNK = Template("""\
space = pymunk.Space()
space.gravity = (0.0, 0.0)
space.damping = 1.0  # velocities kept
$settings
discs, shapes = [], []
for center, radius, mass, velocity in BODIES:
    disc = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0.0, radius))
    disc.position = (center[0], center[1])
    disc.velocity = (velocity[0], velocity[1])
    shape = pymunk.Circle(disc, radius)
    shape.elasticity = math.sqrt(RESTITUTION)  # elasticities combine as their product: e
$friction    discs.append(disc)
    shapes.append(shape)
space.add(*discs, *shapes)
for _ in range(STEPS):
    space.step(DT)
positions = tuple((float(d.position.x), float(d.position.y)) for d in discs)
velocities = tuple((float(d.velocity.x), float(d.velocity.y)) for d in discs)
""")

IN_PLANE = """\


def in_dim(vectors, what):
    # the scene's dimension; a 2-D scene must have stayed in the plane z = 0 exactly
    if $dim == 3:
        return tuple((float(v[0]), float(v[1]), float(v[2])) for v in vectors)
    off = [v[2] for v in vectors if v[2] != 0.0]
    if off:
        raise RuntimeError(f"2-D scene left the plane z = 0: {what} z = {off[0]!r}")
    return tuple((float(v[0]), float(v[1])) for v in vectors)


positions = in_dim(positions, "position")
velocities = in_dim(velocities, "velocity")
"""
"""The end of a script whose engine works in 3-D: its final state in the scene's dimension,
as ``adapters.scene.in_scene_dim`` reads it (a template: ``$dim``)."""

PYBULLET = Template("""\
cid = pybullet.connect(pybullet.DIRECT)  # no GUI
pybullet.setGravity(0.0, 0.0, 0.0, physicsClientId=cid)
pybullet.setPhysicsEngineParameter(**$settings, physicsClientId=cid)
BODY = $body  # changeDynamics settings of every sphere
shapes, ids = {}, []  # one collision shape per radius
for center, radius, mass, velocity in BODIES:
    if radius not in shapes:
        shapes[radius] = pybullet.createCollisionShape(pybullet.GEOM_SPHERE, radius=radius,
                                                       physicsClientId=cid)
    position = (center[0], center[1], center[2] if len(center) > 2 else 0.0)
    uid = pybullet.createMultiBody(baseMass=mass, baseCollisionShapeIndex=shapes[radius],
                                   basePosition=position,$maximal physicsClientId=cid)
    # restitution combines as the product of the bodies' values: sqrt(e) each gives e
    pybullet.changeDynamics(uid, -1, restitution=math.sqrt(RESTITUTION), **BODY,$ccd
                            physicsClientId=cid)
    speed = (velocity[0], velocity[1], velocity[2] if len(velocity) > 2 else 0.0)
    pybullet.resetBaseVelocity(uid, speed, (0.0, 0.0, 0.0), physicsClientId=cid)
    ids.append(uid)
for _ in range(STEPS):
    pybullet.stepSimulation(physicsClientId=cid)
positions = [pybullet.getBasePositionAndOrientation(u, physicsClientId=cid)[0] for u in ids]
velocities = [pybullet.getBaseVelocity(u, physicsClientId=cid)[0] for u in ids]
""" + IN_PLANE)


NOTE = ("A scene is built as the adapter's scene runner builds it: the scene's time step and "
        "iterations apply, and of the settings above only the variant's scene tuning.")


def scene_inputs(case: SceneCase, *, dt: bool = True,
                 iterations: bool = True) -> tuple[tuple[str, str, str, str], ...]:
    """A scene script's inputs: its bodies, restitution, step count and (unless the engine's
    settings already hold them) its time step and solver iterations."""
    bodies = "[\n" + "".join(
        f"    ({vector(b.center)}, {literal(b.radius)}, {literal(b.mass)},\n"
        f"     {vector(b.velocity)}),\n" for b in case.bodies) + "]"
    step = case.dt or DEFAULT_DT
    return (("BODIES", bodies, "bodies (centre, radius, mass, velocity)",
             f"{len(case.bodies)} bodies"),
            ("RESTITUTION", literal(case.restitution), "restitution", repr(case.restitution)),
            *((("DT", literal(step), "dt", repr(step)),) if dt else ()),
            ("STEPS", repr(case.step_count), "steps", f"round({case.duration!r} / dt)"),
            *((("ITERATIONS", repr(case.iterations), "iterations",
                "solver iterations (None: the engine's default)"),) if iterations else ()))


def _guarded(case: SceneCase, engine: str, code: str) -> str:
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    try:
        scene.check_scene(bodies, case.dim, case.restitution, case.dt or DEFAULT_DT)
    except ValueError as exc:
        return raising(exc, engine, code)
    return code


def pymunk_scene_code(adapter: PymunkTuned, case: SceneCase) -> EngineCode:
    """pymunk stepping the scene as ``adapters.pymunk_scene`` does, with the variant's tuning."""
    tuning = adapter.scene_tuning
    settings = ["if ITERATIONS is not None:", "    space.iterations = ITERATIONS"]
    if tuning is not None and tuning.slop is not None:
        settings.append(f"space.collision_slop = {tuning.slop!r}")
    if tuning is not None and tuning.bias is not None:
        settings.append(f"space.collision_bias = {tuning.bias!r}")
    friction = "" if tuning is None or tuning.friction is None else (
        f"    shape.friction = {tuning.friction!r}\n")
    code = PYMUNK.substitute(settings="\n".join(settings), friction=friction) + STATE
    if case.dim != 2:
        code = raising(ValueError(f"pymunk is a 2-D engine: no {case.dim}-D scenes"),
                       "pymunk", code)
    return EngineCode(("import math", "import pymunk"), _guarded(case, "pymunk", code),
                      (NOTE,), inputs=scene_inputs(case))


def pybullet_scene_code(adapter: PyBulletTuned, case: SceneCase) -> EngineCode:
    """pybullet stepping the scene as ``adapters.pybullet_scene`` does, with the variant's
    tuning (world settings of the scene's dt and iterations, per-body settings)."""
    tuning = adapter.scene_tuning
    settings = pybullet_scene.world_settings(case.dt or DEFAULT_DT, case.iterations, tuning)
    body = dict(tuning.body) if tuning is not None else {}
    maximal = ccd = ""
    if tuning is not None and tuning.maximal:  # a btRigidBody, not a btMultiBody
        maximal = "\n                                   useMaximalCoordinates=True,"
    if tuning is not None and tuning.ccd > 0.0:  # CCD: a swept sphere of this x the radius
        ccd = f"\n                            ccdSweptSphereRadius={tuning.ccd!r} * radius,"
    code = PYBULLET.substitute(settings=repr(settings), body=repr(body), dim=case.dim,
                               maximal=maximal, ccd=ccd) + STATE
    return EngineCode(("import math", "import pybullet"), _guarded(case, "pybullet", code),
                      (NOTE,), inputs=scene_inputs(case))
