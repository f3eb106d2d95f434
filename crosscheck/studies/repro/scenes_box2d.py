"""The engine part of a repro script for a scene (``sphere_scene``) on Box2D (pybox2d 2.3.10).

The statements build the scene as ``adapters/box2d_scene.py`` does (worlds, walls and discs
as ``adapters/box2d_world.py`` makes them), with the variant's ``scene_tuning`` read from the
adapter (every fixture's restitution is e: Box2D mixes by max, so every pair gets e), the
scene's gravity and its walls (the adapter's static boxes, :mod:`adapters.wall_boxes`, made
before the discs, their anchors, centres and half sizes as exact literals), step it, and
leave the final ``positions`` and ``velocities``, as the harness computes them the total
``momentum`` and kinetic ``energy`` (``STATE`` of :mod:`~crosscheck.studies.repro.scenes`),
and the measures (:mod:`~crosscheck.studies.repro.measures`).  The script's inputs are those
of pybullet's and pymunk's scenes.  :func:`box2d_writer` is the script writer of the Box2D
variants' scenes (their pairs and times of impact are calls of :mod:`adapters.box2d.calls`).
"""

from __future__ import annotations

from string import Template
from typing import Any

from adapters import box2d_scene
from adapters import wall_boxes as wall_boxes_of
from adapters.box2d import Box2dTuned
from crosscheck.core.schema import DEFAULT_DT, AnyCase, SceneCase
from crosscheck.studies.repro import measures
from crosscheck.studies.repro.code import EngineCode, number, raising
from crosscheck.studies.repro.scenes import (
    NOTE,
    box_literal,
    refusal,
    scene_code,
    scene_inputs,
    wall_boxes,
)

BOX2D = Template("""\
VELOCITY_ITERATIONS = ITERATIONS if ITERATIONS is not None else $velocity_iterations
POSITION_ITERATIONS = $position_iterations
world = b2.b2World(gravity=(GRAVITY[0], GRAVITY[1]))
world.SetAllowSleeping($sleep)  # (b2World(doSleep=...) only sets a Python attribute)
$walls
discs = []
for center, radius, mass, velocity in BODIES:
    disc = world.CreateDynamicBody(position=(float(center[0]), float(center[1])),
                                   linearVelocity=(float(velocity[0]), float(velocity[1])),
                                   fixedRotation=$fixed_rotation$bullet)
    # restitution mixes by max: e on every fixture gives e for every pair
    disc.CreateCircleFixture(radius=radius, density=0.0, restitution=RESTITUTION$friction)
    moment = $moment
    disc.massData = b2.b2MassData(mass=mass, center=(0.0, 0.0), I=moment)
    discs.append(disc)


def read():
    return (tuple((float(d.position[0]), float(d.position[1])) for d in discs),
            tuple((float(d.linearVelocity[0]), float(d.linearVelocity[1])) for d in discs))


$stepping
positions, velocities = read()
""")
WALLS_BOX2D = Template("""\
# Each wall a static body with one box fixture, sized as the adapter sizes it
# (adapters/wall_boxes.py: $thickness x the largest radius thick on the solid side, $sideways x
# the scene's extent sideways); the body sits on the wall's surface (its anchor) and the box
# is SetAsBox(hx, hy, centre, 0) in its frame, so the face a disc touches is exactly 0 there.
# (anchor, centre, half sizes) per wall, exact floats; walls come before the discs.
WALL_BOXES = $boxes
for anchor, centre, half in WALL_BOXES:
    wall = world.CreateStaticBody(position=anchor)
    box = b2.b2PolygonShape()
    box.SetAsBox(half[0], half[1], centre, 0.0)
$radius    wall.CreateFixture(shape=box, restitution=RESTITUTION$friction)""")


def box2d_scene_code(adapter: Box2dTuned, case: SceneCase) -> EngineCode:
    """Box2D stepping the scene as ``adapters.box2d_scene`` does, with the variant's tuning,
    its gravity and its walls (the adapter's static boxes)."""
    v = box2d_scene.scene_variant(case.dt or DEFAULT_DT, None, adapter.scene_tuning)
    friction = "" if v.friction is None else f", friction={number(v.friction)}"
    walls = ""
    if case.walls and case.dim == 2:
        radius = "" if v.polygon_radius is None else (
            f"    box.radius = {number(v.polygon_radius)}  # the variant's polygon radius\n")
        walls = WALLS_BOX2D.substitute(
            thickness=wall_boxes_of.THICKNESS, sideways=wall_boxes_of.SIDEWAYS,
            boxes=box_literal([(s.anchor, s.centre, s.half) for s in wall_boxes(case)]),
            radius=radius, friction=friction)
    code = BOX2D.substitute(
        velocity_iterations=v.velocity_iterations, position_iterations=v.position_iterations,
        sleep=v.sleep, fixed_rotation=v.fixed_rotation, friction=friction, walls=walls,
        bullet=", bullet=True" if v.bullet else "",
        moment="0.0  # fixedRotation" if v.fixed_rotation
        else "0.5 * mass * radius**2  # a disc's moment",
        stepping=measures.stepping("world.Step(DT, VELOCITY_ITERATIONS, POSITION_ITERATIONS)",
                                   "read"))
    code = scene_code(code)
    refused = ValueError(f"box2d is a 2-D engine: no {case.dim}-D scenes") if case.dim != 2 \
        else refusal(case)
    if refused is not None:
        code = raising(refused, "Box2D", code)
    return EngineCode(("import math", "import Box2D as b2"), code,
                      (NOTE, "Box2D is float32: every input is rounded to float32."),
                      inputs=scene_inputs(case))


def box2d_writer(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    """The script writer of the Box2D variants' scenes (their pairs and times of impact are
    calls of :mod:`adapters.box2d.calls`)."""
    assert isinstance(case, SceneCase), "box2d's pairs are calls of adapters.box2d.calls"
    return box2d_scene_code(adapter, case)
