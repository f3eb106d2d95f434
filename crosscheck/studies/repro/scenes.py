"""The engine part of a repro script for a scene (``sphere_scene``): pybullet and pymunk.

A scene is N spheres (discs in 2-D) with one restitution, stepped ``round(duration / dt)``
times with a fixed step, in open space or with gravity and static walls.  The statements
build it as ``adapters/pybullet_scene.py`` or ``adapters/pymunk_scene.py`` does, with the
variant's ``scene_tuning`` read from the adapter (each body's restitution or elasticity is
sqrt(e), so every pair gets e), its gravity and its walls (PyBullet: static planes, after the
gravity and before the spheres; pymunk: the adapter's thick ``Poly`` boxes,
:mod:`adapters.wall_boxes`, their corners as exact literals), step it (recording the states
as the adapter does when it has gravity or walls: :mod:`~crosscheck.studies.repro.measures`)
and leave the final ``positions`` and ``velocities``, the total ``momentum`` and kinetic
``energy`` as the harness computes them (``crosscheck.truth.scenes.observation``: exact sums
with ``math.fsum``), and the measures.  The script's inputs are the scene's bodies,
restitution, time step, step count, solver iterations, gravity, walls and recording stride.
The other engines' scene parts (``scenes_box2d``, ``scenes_mujoco``, ``scenes_rapier``) use
:func:`scene_inputs`, :func:`scene_code` and :func:`refusal` from here.
"""
from __future__ import annotations

from collections.abc import Sequence
from string import Template

from adapters import pybullet_scene, scene, stepping
from adapters import wall_boxes as wall_boxes_of
from adapters.pybullet import PyBulletTuned
from adapters.pymunk import PymunkTuned
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.studies.repro import measures
from crosscheck.studies.repro.code import EngineCode, literal, raising, vector

Input = tuple[str, str, str, str]

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
space.gravity = (GRAVITY[0], GRAVITY[1])
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
$walls
space.add(*discs, *shapes$added)


def read():
    return (tuple((float(d.position.x), float(d.position.y)) for d in discs),
            tuple((float(d.velocity.x), float(d.velocity.y)) for d in discs))


$stepping
positions, velocities = read()
""")
PYMUNK_WALLS = Template("""\
# Each wall a thick static box (a Poly of radius 0 on the space's static body), sized as the
# adapter sizes it (adapters/wall_boxes.py: $thickness x the largest radius thick on the solid
# side, $sideways x the scene's extent sideways): its corners (lowest, highest), exact floats.
WALL_BOXES = $boxes
walls = []
for (x0, y0), (x1, y1) in WALL_BOXES:
    wall = pymunk.Poly(space.static_body, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)], radius=0.0)
    wall.elasticity = math.sqrt(RESTITUTION)  # like every disc's: e for a disc-wall contact
$friction    walls.append(wall)""")

IN_DIM = """\


def in_dim(vectors, what):
    # the scene's dimension; a 2-D scene must have stayed in the plane z = 0 exactly
    if $dim == 3:
        return tuple((float(v[0]), float(v[1]), float(v[2])) for v in vectors)
    off = [v[2] for v in vectors if v[2] != 0.0]
    if off:
        raise RuntimeError(f"2-D scene left the plane z = 0: {what} z = {off[0]!r}")
    return tuple((float(v[0]), float(v[1])) for v in vectors)
"""
"""A script's reading of a 3-D engine's vectors in the scene's dimension, as
``adapters.scene.in_scene_dim`` reads them (a template: ``$dim``)."""

PYBULLET = Template("""\
cid = pybullet.connect(pybullet.DIRECT)  # no GUI
pybullet.setGravity(0.0, 0.0, 0.0, physicsClientId=cid)
pybullet.setPhysicsEngineParameter(**$settings, physicsClientId=cid)
if any(GRAVITY):  # the scene's gravity (open space: none, no call)
    pybullet.setGravity(*GRAVITY, *(0.0,) * (3 - len(GRAVITY)), physicsClientId=cid)
$walls
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
""" + IN_DIM + """

def read():
    return (in_dim([pybullet.getBasePositionAndOrientation(u, physicsClientId=cid)[0]
                    for u in ids], "position"),
            in_dim([pybullet.getBaseVelocity(u, physicsClientId=cid)[0] for u in ids],
                   "velocity"))


$stepping
positions, velocities = read()
""")
PYBULLET_WALLS = Template("""\
# Each wall a static plane (GEOM_PLANE, a half-space) with the wall's normal, on a mass-0 base
# at offset x normal, restitution sqrt(e) like every sphere, the variant's friction.
WALL = $wall  # changeDynamics settings of every wall
walls = []
for normal, offset in WALLS:
    normal = (normal[0], normal[1], normal[2] if len(normal) > 2 else 0.0)
    plane = pybullet.createCollisionShape(pybullet.GEOM_PLANE, planeNormal=normal,
                                          physicsClientId=cid)
    uid = pybullet.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=plane,
                                   basePosition=tuple(offset * n for n in normal),$maximal
                                   physicsClientId=cid)
    pybullet.changeDynamics(uid, -1, restitution=math.sqrt(RESTITUTION), **WALL,
                            physicsClientId=cid)
    walls.append(uid)""")


NOTE = ("A scene is built as the adapter's scene runner builds it: the scene's time step and "
        "iterations apply, and of the settings above only the variant's scene tuning.")


def scene_inputs(case: SceneCase, *, iterations: bool = True) -> tuple[Input, ...]:
    """A scene script's inputs: its bodies, restitution, time step, step count, (unless the
    engine's settings already hold them) solver iterations, and gravity, walls and the
    recording stride (:func:`crosscheck.studies.repro.measures.inputs`)."""
    bodies = "[\n" + "".join(
        f"    ({vector(b.center)}, {literal(b.radius)}, {literal(b.mass)},\n"
        f"     {vector(b.velocity)}),\n" for b in case.bodies) + "]"
    step = case.dt or DEFAULT_DT
    return (("BODIES", bodies, "bodies (centre, radius, mass, velocity)",
             f"{len(case.bodies)} bodies"),
            ("RESTITUTION", literal(case.restitution), "restitution", repr(case.restitution)),
            ("DT", literal(step), "dt", repr(step)),
            ("STEPS", repr(case.step_count), "steps", f"round({case.duration!r} / dt)"),
            *((("ITERATIONS", repr(case.iterations), "iterations",
                "solver iterations (None: the engine's default)"),) if iterations else ()),
            *measures.inputs(case))


def refusal(case: SceneCase) -> ValueError | None:
    """What every scene adapter raises before building the scene (None: it builds it): a
    scene or surroundings ``adapters.scene`` refuses."""
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    try:
        scene.check_scene(bodies, case.dim, case.restitution, case.dt or DEFAULT_DT)
        scene.check_surroundings(stepping.surroundings(case), case.dim)
    except ValueError as exc:
        return exc
    return None


def _guarded(case: SceneCase, engine: str, code: str) -> str:
    refused = refusal(case)
    return code if refused is None else raising(refused, engine, code)


def scene_code(code: str) -> str:
    """An engine part's statements between the measures' functions (first, for ``record``) and
    the observation and measures (last)."""
    return measures.FUNCTIONS + "\n\n" + code + STATE + measures.FINISH


def wall_boxes(case: SceneCase) -> tuple[wall_boxes_of.Slab, ...]:
    """The walls as the 2-D adapters' thick boxes (:func:`adapters.wall_boxes.slabs`)."""
    around = stepping.surroundings(case)
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    return wall_boxes_of.slabs(bodies, around.walls) if around is not None else ()


def box_literal(rows: Sequence[Sequence[Sequence[float]]]) -> str:
    """Python source of a list of tuples of exact vectors (one wall's box a row)."""
    return "[" + "".join("\n    (" + ", ".join(vector(v) for v in row) + ")," for row in rows) + (
        "\n]" if rows else "]")


def pymunk_scene_code(adapter: PymunkTuned, case: SceneCase) -> EngineCode:
    """pymunk stepping the scene as ``adapters.pymunk_scene`` does, with the variant's tuning,
    and its walls as the adapter's boxes."""
    tuning = adapter.scene_tuning
    settings = ["if ITERATIONS is not None:", "    space.iterations = ITERATIONS"]
    if tuning is not None and tuning.slop is not None:
        settings.append(f"space.collision_slop = {tuning.slop!r}")
    if tuning is not None and tuning.bias is not None:
        settings.append(f"space.collision_bias = {tuning.bias!r}")
    friction = "" if tuning is None or tuning.friction is None else (
        f"    shape.friction = {tuning.friction!r}\n")
    walls = ""
    if case.walls and case.dim == 2:
        walls = PYMUNK_WALLS.substitute(
            thickness=wall_boxes_of.THICKNESS, sideways=wall_boxes_of.SIDEWAYS,
            boxes=box_literal([s.corners() for s in wall_boxes(case)]),
            friction=friction.replace("shape.", "wall."))
    code = PYMUNK.substitute(settings="\n".join(settings), friction=friction, walls=walls,
                             added=", *walls" if walls else "",
                             stepping=measures.stepping("space.step(DT)", "read"))
    code = scene_code(code)
    if case.dim != 2:
        code = raising(ValueError(f"pymunk is a 2-D engine: no {case.dim}-D scenes"),
                       "pymunk", code)
    return EngineCode(("import math", "import pymunk"), _guarded(case, "pymunk", code),
                      (NOTE,), inputs=scene_inputs(case))


def pybullet_scene_code(adapter: PyBulletTuned, case: SceneCase) -> EngineCode:
    """pybullet stepping the scene as ``adapters.pybullet_scene`` does, with the variant's
    tuning (world settings of the scene's dt and iterations, per-body settings), its gravity
    and its walls (static planes)."""
    tuning = adapter.scene_tuning
    settings = pybullet_scene.world_settings(case.dt or DEFAULT_DT, case.iterations, tuning)
    body = dict(tuning.body) if tuning is not None else {}
    maximal = ccd = ""
    if tuning is not None and tuning.maximal:  # a btRigidBody, not a btMultiBody
        maximal = "\n                                   useMaximalCoordinates=True,"
    if tuning is not None and tuning.ccd > 0.0:  # CCD: a swept sphere of this x the radius
        ccd = f"\n                            ccdSweptSphereRadius={tuning.ccd!r} * radius,"
    walls = "" if not case.walls else PYBULLET_WALLS.substitute(
        wall=repr(pybullet_scene.wall_settings(tuning)), maximal=maximal)
    code = PYBULLET.substitute(settings=repr(settings), body=repr(body), dim=case.dim,
                               maximal=maximal, ccd=ccd, walls=walls,
                               stepping=measures.stepping(
                                   "pybullet.stepSimulation(physicsClientId=cid)", "read"))
    return EngineCode(("import math", "import pybullet"),
                      _guarded(case, "pybullet", scene_code(code)), (NOTE,),
                      inputs=scene_inputs(case))
