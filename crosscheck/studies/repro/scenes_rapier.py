"""The engine part of a repro script for Rapier's scenes (``rapier``, ``rapier-default``,
``rapier-ccd``; their pairs and times of impact are calls of :mod:`adapters.rapier.calls`).

:func:`rapier_writer` writes a scene's (``sphere_scene``) statements, which build it as
``adapters/rapier_scene.py`` does: a new ``PhysicsWorld`` (gravity 0)
with the variant's ``IntegrationParameters`` (``rapier_scene.parameters``: the scene's dt and
iterations), one dynamic body per sphere with the variant's body and collider builder chains
(those of the response scripts; restitution e on every collider, combined by Max in the tuned
variant and by rapier's default Average otherwise: e), z translation locked in 2-D; then the
scene's gravity and walls (one fixed body with a half-space collider per wall, the variant's
material: :mod:`adapters.rapier_walls`); then step it (recording the states as the adapter
does when it has gravity or walls) and leave the final ``positions`` and ``velocities``, as
the harness computes them the total ``momentum`` and kinetic ``energy``, and the measures
(:mod:`~crosscheck.studies.repro.measures`).  Scenes the adapter refuses (``check_scene``,
``check_surroundings``, numbers beyond float32) are a guard.
"""

from __future__ import annotations

from string import Template
from typing import Any

from adapters import rapier_scene, rapier_walls, scene, stepping
from adapters.rapier import RapierTuned
from adapters.shared import rapier as rapier_response
from crosscheck.core.schema import DEFAULT_DT, AnyCase, SceneCase
from crosscheck.studies.repro import measures
from crosscheck.studies.repro.code import EngineCode, number, raising
from crosscheck.studies.repro.scenes import IN_DIM, NOTE, scene_code, scene_inputs
from crosscheck.studies.repro.scenes import refusal as scene_refusal

TUNED_BODY = ("rp.RigidBody.dynamic().translation({c}).linvel({v}).can_sleep(False)\n"
              "        .soft_ccd_prediction({ccd}).locked_axes(rp.LockedAxes.ROTATION_LOCKED)\n"
              "        .linear_damping(0.0).angular_damping(0.0){z}")
DEFAULT_BODY = "rp.RigidBody.dynamic().translation({c}).linvel({v}){z}"
TUNED_COLLIDER = ("rp.Collider.ball({r}).mass({m}).friction(0.0).restitution({own})\n"
                  "        .restitution_combine_rule(rp.CoefficientCombineRule.{rule})")
DEFAULT_COLLIDER = "rp.Collider.ball({r}).mass({m}).restitution(RESTITUTION)"
NOTES = ("rapier3d is float32 (Real = f32): every input is rounded to float32 by the binding.",)

SCENE = Template("""\
world = rp.PhysicsWorld(gravity=(0.0, 0.0, 0.0))
params = world.integration_parameters
for key, value in $parameters:  # IntegrationParameters: the variant's, dt, iterations
    setattr(params, key, value)
handles = []
for center, RADIUS, MASS, velocity in BODIES:
    CENTRE = (center[0], center[1], center[2] if len(center) > 2 else 0.0)
    VELOCITY = (velocity[0], velocity[1], velocity[2] if len(velocity) > 2 else 0.0)
    body = ($body)$ccd
    if len(center) == 2:  # a 2-D scene keeps to the plane z = 0
        body = body.enabled_translations((True, True, False))
    collider = ($collider)
    handles.append(world.add_body(body, [collider]))
if any(GRAVITY):  # the scene's gravity (open space: none)
    world.gravity = rp.Vec3(*GRAVITY, *(0.0,) * (3 - len(GRAVITY)))
$walls""" + IN_DIM + """

def read():
    if not world.quarantine.is_empty():
        raise FloatingPointError(f"rapier quarantined a body whose state became non-finite "
                                 f"({world.quarantine})")
    bodies = [world.rigid_bodies[h] for h in handles]
    return (in_dim([b.translation.to_tuple() for b in bodies], "position"),
            in_dim([b.linvel.to_tuple() for b in bodies], "velocity"))


$stepping
positions, velocities = read()
""")
WALL_COLLIDERS = Template("""\
# The walls: one fixed body carrying a half-space collider per wall (solid where normal . x
# <= 0 in its frame), translated to offset x normal, with the variant's material.
colliders = []
for normal, offset in WALLS:
    n = (normal[0], normal[1], normal[2] if len(normal) > 2 else 0.0)
    colliders.append(rp.Collider.halfspace(n).translation(
        (offset * n[0], offset * n[1], offset * n[2])).restitution(RESTITUTION)$material)
world.add_body(rp.RigidBody.fixed(), colliders)
""")


def refusal(case: SceneCase) -> Exception | None:
    """What the adapter raises before building the scene (None: it builds it)."""
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    refused = scene_refusal(case)
    if refused is not None:
        return refused
    around = stepping.surroundings(case) or scene.Surroundings.none(case.dim)
    try:
        rapier_scene.check_f32(bodies, case.restitution)
        rapier_walls.check_f32(around, rapier_scene.F32_MAX)
        if case.iterations is not None and case.iterations < 1:
            raise ValueError(f"iterations must be >= 1, got {case.iterations}")
    except (ValueError, OverflowError) as exc:
        return exc
    return None


def rapier_scene_code(adapter: RapierTuned, case: SceneCase) -> EngineCode:
    """Rapier stepping the scene as ``adapters.rapier_scene`` does, with the variant's tuning,
    its gravity and its walls (half-spaces, :mod:`adapters.rapier_walls`)."""
    tuning = adapter.scene_tuning
    params = rapier_scene.parameters(case.dt or DEFAULT_DT, case.iterations, tuning)
    if tuning is None:
        body, collider = DEFAULT_BODY, DEFAULT_COLLIDER
        rule = ""
        material = ""
    else:
        body, collider = TUNED_BODY, TUNED_COLLIDER
        rule = tuning.rule
        material = (f".friction(0.0)\n        .restitution_combine_rule("
                    f"rp.CoefficientCombineRule.{rule})")
    code = SCENE.substitute(
        parameters=repr(params),
        body=body.format(c="CENTRE", v="VELOCITY", ccd=number(rapier_response.SOFT_CCD), z=""),
        collider=collider.format(r="RADIUS", m="MASS", own="RESTITUTION", rule=rule),
        ccd=".ccd_enabled(True)" if tuning is not None and tuning.ccd else "",
        walls=WALL_COLLIDERS.substitute(material=material) if case.walls else "",
        dim=case.dim,
        stepping=measures.stepping("world.step()", "read"))
    code = scene_code(code)
    refused = refusal(case)
    if refused is not None:
        code = raising(refused, "rapier", code)
    return EngineCode(("import math", "import rapier3d as rp"), code, (*NOTES, NOTE),
                      inputs=scene_inputs(case, iterations=False))


def rapier_writer(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    """The script writer of the Rapier variants' scenes (their pairs and times of impact are
    calls of :mod:`adapters.rapier.calls`)."""
    assert isinstance(case, SceneCase), "rapier's pairs are calls of adapters.rapier.calls"
    return rapier_scene_code(adapter, case)
