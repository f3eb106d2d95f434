"""The engine part of a repro script for a scene (``sphere_scene``) on Box2D (pybox2d 2.3.10).

The statements build the scene as ``adapters/box2d_scene.py`` does (worlds and discs as
``adapters/box2d_world.py`` makes them), with the variant's ``scene_tuning`` read from the
adapter (every fixture's restitution is e: Box2D mixes by max, so every pair gets e), step
it, and leave the final ``positions`` and ``velocities`` and, as the harness computes them,
the total ``momentum`` and kinetic ``energy`` (``STATE`` of
:mod:`~crosscheck.studies.repro.scenes`).  The script's inputs are the scene's bodies,
restitution, time step, step count and solver iterations, as for pybullet's and pymunk's
scenes.  :func:`box2d_writer` is the script writer of both Box2D variants: scenes here, pair
cases in :mod:`~crosscheck.studies.repro.box2d`, times of impact in
:mod:`~crosscheck.studies.repro.toi`.
"""

from __future__ import annotations

from string import Template
from typing import Any

from adapters import box2d_scene, scene
from adapters.box2d_engine import Box2dTuned
from crosscheck.core.schema import DEFAULT_DT, AnyCase, SceneCase, ToiCase
from crosscheck.studies.repro.box2d import box2d_code
from crosscheck.studies.repro.code import EngineCode, number, raising
from crosscheck.studies.repro.scenes import NOTE, STATE, scene_inputs
from crosscheck.studies.repro.toi import box2d_toi_code

BOX2D = Template("""\
VELOCITY_ITERATIONS = ITERATIONS if ITERATIONS is not None else $velocity_iterations
POSITION_ITERATIONS = $position_iterations
world = b2.b2World(gravity=(0.0, 0.0))
world.SetAllowSleeping($sleep)  # (b2World(doSleep=...) only sets a Python attribute)
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
for _ in range(STEPS):
    world.Step(DT, VELOCITY_ITERATIONS, POSITION_ITERATIONS)
positions = tuple((float(d.position[0]), float(d.position[1])) for d in discs)
velocities = tuple((float(d.linearVelocity[0]), float(d.linearVelocity[1])) for d in discs)
""")


def box2d_scene_code(adapter: Box2dTuned, case: SceneCase) -> EngineCode:
    """Box2D stepping the scene as ``adapters.box2d_scene`` does, with the variant's tuning."""
    v = box2d_scene.scene_variant(case.dt or DEFAULT_DT, None, adapter.scene_tuning)
    friction = "" if v.friction is None else f", friction={number(v.friction)}"
    code = BOX2D.substitute(
        velocity_iterations=v.velocity_iterations, position_iterations=v.position_iterations,
        sleep=v.sleep, fixed_rotation=v.fixed_rotation, friction=friction,
        bullet=", bullet=True" if v.bullet else "",
        moment="0.0  # fixedRotation" if v.fixed_rotation
        else "0.5 * mass * radius**2  # a disc's moment") + STATE
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    try:
        if case.dim != 2:
            raise ValueError(f"box2d is a 2-D engine: no {case.dim}-D scenes")
        scene.check_scene(bodies, case.dim, case.restitution, case.dt or DEFAULT_DT)
    except ValueError as exc:
        code = raising(exc, "Box2D", code)
    return EngineCode(("import math", "import Box2D as b2"), code,
                      (NOTE, "Box2D is float32: every input is rounded to float32."),
                      inputs=scene_inputs(case))


def box2d_writer(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    """The script writer of the Box2D variants: scenes here, pair cases in ``repro.box2d``,
    times of impact in ``repro.toi``."""
    if isinstance(case, SceneCase):
        return box2d_scene_code(adapter, case)
    if isinstance(case, ToiCase):
        return box2d_toi_code(case)
    return box2d_code(adapter, case)
