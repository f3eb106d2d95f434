"""The engine part of a repro script for a scene (``sphere_scene``) on MuJoCo.

The statements build the scene as ``adapters/mujoco_scene.py`` does: the model compiled from the
very MJCF text the adapter compiles (``adapters.shared.mujoco.scene_mjcf``, embedded), the
scene's time step and iterations, and for the tuned variant the stiff contact (RK4, solver
tolerance, margin, flat solimp, the direct solref that gives e over one scene step, the sub-
steps); the centres and velocities go into ``qpos`` / ``qvel``; with gravity or walls the walls
are the MJCF's plane geoms (:mod:`adapters.mujoco_walls`), ``opt.gravity`` the scene's, and each
scene step is one ``mj_step`` call of the variant's sub-steps with the states recorded as the
adapter records them (:mod:`~crosscheck.studies.repro.measures`); in open space one ``mj_step``
call takes every step. A 2-D scene's z noise is checked as ``mujoco_scene.read_state`` checks
it.
They leave the final ``positions`` and ``velocities``, as the harness computes them
(``STATE`` of :mod:`~crosscheck.studies.repro.scenes`) the total ``momentum`` and kinetic
``energy``, and the measures.
"""

from __future__ import annotations

import math
from string import Template
from typing import Any

from adapters import mujoco_response, mujoco_scene, stepping
from adapters.mujoco import MujocoDefault
from adapters.mujoco_response import PLANE
from adapters.mujoco_scene import WALLED_PLANE
from adapters.mujoco_walls import plane_of
from adapters.shared.mujoco import Mass, scene_mjcf
from crosscheck.core.schema import DEFAULT_DT, AnyCase, SceneCase
from crosscheck.studies.repro.code import EngineCode, literal, number, raising, vector
from crosscheck.studies.repro.scenes import NOTE, refusal, scene_code, scene_inputs
from crosscheck.truth import scene_measures

MUJOCO = Template('''\
MJCF = """$mjcf"""
model = mujoco.MjModel.from_xml_string(MJCF)
if ITERATIONS is not None:
    model.opt.iterations = ITERATIONS
$settings
model.opt.gravity[:] = (*GRAVITY, 0.0, 0.0)[:3]  # the scene's (open space: 0, as the MJCF's)
data = mujoco.MjData(model)
for i, (center, radius, mass, velocity) in enumerate(BODIES):
    pad = (0.0,) * (3 - len(center))  # 2-D: the plane z = 0
    data.qpos[7 * i:7 * i + 7] = (*center, *pad, 1.0, 0.0, 0.0, 0.0)
    data.qvel[6 * i:6 * i + 6] = (*velocity, *pad, 0.0, 0.0, 0.0)
mujoco.mj_forward(model, data)
# A 2-D scene's z noise is dropped within PLANE x the scales: the start's largest |coordinate|
# + radius and largest speed (or |g| dt), or the current state's in-plane ones if larger.
SCALES = ($reach, $speed)
PLANE = $plane  # 2**-40 in open space, 2**-30 with gravity or walls
RADIUS = $radius  # the largest radius


def in_dim(rows, what, scale):
    if $dim == 2:
        off = [float(r[2]) for r in rows if not abs(r[2]) <= PLANE * scale]
        if off:
            raise RuntimeError(f"2-D scene left the plane z = 0: {what} z = {off[0]!r}")
    return tuple(tuple(float(x) for x in r[:$dim]) for r in rows)


def read():
    qpos = data.qpos.reshape(len(BODIES), 7)[:, :3]
    qvel = data.qvel.reshape(len(BODIES), 6)[:, :3]
    reach, speed = SCALES
    if $dim == 2 and len(BODIES):
        reach = max(reach, float(np.abs(qpos[:, :2]).max()) + RADIUS)
        speed = max(speed, float(np.abs(qvel[:, :2]).max()))
    return in_dim(qpos, "position", reach), in_dim(qvel, "velocity", speed)


if RECORD_EVERY:  # record the states every RECORD_EVERY steps, as the adapter
    TRAJECTORY = record(lambda: mujoco.mj_step(model, data, $substeps), read)
else:  # open space: no trajectory, and the whole run is one call
    TRAJECTORY = None
    if STEPS:
        mujoco.mj_step(model, data, STEPS * $substeps)  # $substeps MuJoCo step(s) per scene step
if data.warning.number.any():
    raise RuntimeError("MuJoCo warned while stepping, and a bad value resets the state")
positions, velocities = read()
''')


def _settings(case: SceneCase, tuning: mujoco_scene.Tuning | None) -> str:
    dt = case.dt or DEFAULT_DT
    if tuning is None:
        return f"model.opt.timestep = {number(dt)}  # MuJoCo's defaults otherwise"
    solimp = (mujoco_response.MAXIMP, mujoco_response.MAXIMP, 0.001, 0.5, 2.0)
    solref = mujoco_scene.stiff_solref(case.restitution, dt)
    return "\n".join([
        "# stiff frictionless contact: RK4, tight solver, touching contacts active, flat",
        "# solimp, direct solref (-k, -b) whose spring-dashpot gives e over one scene step",
        f"model.opt.timestep = {number(dt)} / {tuning.substeps}",
        "model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4",
        f"model.opt.tolerance = {number(mujoco_response.TOLERANCE)}",
        f"model.geom_margin[:] = {number(mujoco_response.MARGIN)}",
        f"model.geom_solimp[:] = {tuple(solimp)!r}",
        f"model.geom_solref[:] = {vector(solref)}"])


def _spheres(case: SceneCase, tuned: bool) -> list[tuple[float, Mass]]:
    """(radius, (mass, inertia)) per body: inertia = mass (tuned) or a solid sphere's, in the
    adapter's order of operations (``mujoco_scene.model_of``: 0.4 m r r, not 0.4 m r**2)."""
    return [(b.radius, (b.mass, (b.mass if tuned else 0.4 * b.mass * b.radius * b.radius,)
                        * 3)) for b in case.bodies]


def mujoco_scene_code(adapter: MujocoDefault, case: SceneCase) -> EngineCode:
    """MuJoCo stepping the scene as ``adapters.mujoco_scene`` does, with the variant's tuning,
    its gravity and its walls (plane geoms of the world body, :mod:`adapters.mujoco_walls`)."""
    tuning = adapter.scene_tuning
    dt = case.dt or DEFAULT_DT
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    reach = max((abs(x) + r for c, r, _, _ in bodies for x in c), default=0.0)
    speed = max((abs(x) for _, _, _, v in bodies for x in v), default=0.0)
    speed = max(speed, math.hypot(*scene_measures.gravity(case)) * dt)  # as prepare_scene
    failure = refusal(case)
    try:
        settings = _settings(case, tuning) if failure is None else ""
    except ValueError as exc:
        settings, failure = "", exc
    around = stepping.surroundings(case)
    planes = [plane_of(w) for w in around.walls] if around is not None and failure is None \
        else []
    extra = ' condim="1"' if tuning is not None else ""
    code = MUJOCO.substitute(
        mjcf=scene_mjcf(_spheres(case, tuning is not None), extra, planes, extra),
        settings=settings, substeps=tuning.substeps if tuning is not None else 1,
        reach=literal(reach), speed=literal(speed), dim=case.dim,
        radius=literal(max((b.radius for b in case.bodies), default=0.0)),
        plane=literal(WALLED_PLANE if around is not None else PLANE))
    code = scene_code(code)
    if failure is not None:
        code = raising(failure, "mujoco", code)
    return EngineCode(("import math", "import mujoco", "import numpy as np"), code, (NOTE,),
                      inputs=scene_inputs(case))


def mujoco_writer(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    """The script writer of the MuJoCo variants' scenes (their pairs and responses are calls of
    :mod:`adapters.mujoco.calls`)."""
    assert isinstance(case, SceneCase), "mujoco's pairs are calls of adapters.mujoco.calls"
    return mujoco_scene_code(adapter, case)

