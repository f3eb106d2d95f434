"""The engine part of a repro script for Rapier (``rapier``, ``rapier-default``), scenes included.

:func:`rapier_writer` is the script writer of both Rapier variants: a pair case gets the
statements of :mod:`crosscheck.studies.repro.rapier`, a time of impact (``sphere_toi``) those of
:mod:`crosscheck.studies.repro.toi`, a scene (``sphere_scene``) those made
here, which build it as ``adapters/rapier_scene.py`` does: a new ``PhysicsWorld`` (gravity 0)
with the variant's ``IntegrationParameters`` (``rapier_scene.parameters``: the scene's dt and
iterations), one dynamic body per sphere with the variant's body and collider builder chains
(those of the response scripts; restitution e on every collider, combined by Max in the tuned
variant and by rapier's default Average otherwise: e), z translation locked in 2-D; then step
it and leave the final ``positions`` and ``velocities`` and, as the harness computes them,
the total ``momentum`` and kinetic ``energy``.  Scenes the adapter refuses (``check_scene``,
numbers beyond float32) are a guard.
"""

from __future__ import annotations

from string import Template
from typing import Any

from adapters import rapier_response, rapier_scene, scene
from adapters.rapier_engine import RapierTuned
from crosscheck.core.schema import DEFAULT_DT, AnyCase, SceneCase, ToiCase
from crosscheck.studies.repro.code import EngineCode, number, raising
from crosscheck.studies.repro.rapier import (
    DEFAULT_BODY,
    DEFAULT_COLLIDER,
    NOTES,
    TUNED_BODY,
    TUNED_COLLIDER,
    rapier_code,
)
from crosscheck.studies.repro.scenes import IN_PLANE, NOTE, STATE, scene_inputs
from crosscheck.studies.repro.toi import rapier_toi_code

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
for _ in range(STEPS):
    world.step()
if not world.quarantine.is_empty():
    raise FloatingPointError(f"rapier quarantined a body whose state became non-finite "
                             f"({world.quarantine})")
positions = [world.rigid_bodies[h].translation.to_tuple() for h in handles]
velocities = [world.rigid_bodies[h].linvel.to_tuple() for h in handles]
""" + IN_PLANE)


def refusal(case: SceneCase) -> Exception | None:
    """What the adapter raises before building the scene (None: it builds it)."""
    bodies = [(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    try:
        scene.check_scene(bodies, case.dim, case.restitution, case.dt or DEFAULT_DT)
        rapier_scene.check_f32(bodies, case.restitution)
    except (ValueError, OverflowError) as exc:
        return exc
    return None


def rapier_scene_code(adapter: RapierTuned, case: SceneCase) -> EngineCode:
    """Rapier stepping the scene as ``adapters.rapier_scene`` does, with the variant's tuning."""
    tuning = adapter.scene_tuning
    params = rapier_scene.parameters(case.dt or DEFAULT_DT, case.iterations, tuning)
    if tuning is None:
        body, collider = DEFAULT_BODY, DEFAULT_COLLIDER
        rule = ""
    else:
        body, collider = TUNED_BODY, TUNED_COLLIDER
        rule = tuning.rule
    code = SCENE.substitute(
        parameters=repr(params),
        body=body.format(c="CENTRE", v="VELOCITY", ccd=number(rapier_response.SOFT_CCD), z=""),
        collider=collider.format(r="RADIUS", m="MASS", own="RESTITUTION", rule=rule),
        ccd=".ccd_enabled(True)" if tuning is not None and tuning.ccd else "",
        dim=case.dim) + STATE
    refused = refusal(case)
    if refused is not None:
        code = raising(refused, "rapier", code)
    return EngineCode(("import math", "import rapier3d as rp"), code, (*NOTES, NOTE),
                      inputs=scene_inputs(case, dt=False, iterations=False))


def rapier_writer(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    """The script writer of both Rapier variants: scenes here, pair cases in ``rapier``,
    times of impact in ``toi``."""
    if isinstance(case, SceneCase):
        return rapier_scene_code(adapter, case)
    if isinstance(case, ToiCase):
        return rapier_toi_code(case)
    return rapier_code(adapter, case)
