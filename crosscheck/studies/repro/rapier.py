"""The engine part of a repro script for Rapier (``rapier``, ``rapier-default``; rapier3d).

The statements make, for one case, the calls of ``adapters/rapier_engine.py`` and
``adapters/rapier_response.py``.  Detection: two standalone colliders
(``ActiveCollisionTypes.all()``) at the case's centres, and two narrow-phase passes of one
``CollisionPipeline``, each over new sets: the verdict at the variant's prediction distance,
the signed distance and normal from the deepest contact point of a pass whose prediction
distance reaches past any gap.  Response: a new ``PhysicsWorld`` from the variant's body and
collider builders, stepped up to the first step whose solver pushed A and B apart.  The
variant's numbers (prediction distance, integration parameters, soft CCD, the stop rule)
are read from the adapter; the builder chains are the variant's (tuned or default).
Inputs the adapter refuses (NaN, infinite geometry, beyond float32) are a guard.
"""

from __future__ import annotations

import math
from string import Template

from adapters import rapier_engine, rapier_response
from adapters.rapier_engine import RapierDefault, RapierTuned
from crosscheck.core.geometry import to3
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase
from crosscheck.studies.repro.code import APPROACH, EngineCode, literal, number, raising

DETECTION = Template("""\
every = rp.ActiveCollisionTypes.all()  # standalone colliders are fixed: pair them anyway
$shapes
collider_a = (rp.Collider.new(shape_a).translation($centre_a)
              .active_collision_types(every).build())
collider_b = (rp.Collider.new(shape_b).translation($centre_b)
              .active_collision_types(every).build())
pipeline = rp.CollisionPipeline()
PREDICTION = $prediction  # the variant's prediction distance: the verdict
REACH = $reach  # 1 + 2 (|cb - ca| + the sizes), capped at float32's largest: past any gap


def narrow(prediction):
    # one collision-detection pass over new sets: the pair of A and B, and whether rapier
    # stored it as (B, A)
    colliders = rp.ColliderSet()
    ha, hb = colliders.insert(collider_a), colliders.insert(collider_b)
    narrow_phase = rp.NarrowPhase()
    pipeline.step(prediction, rp.IslandManager(), rp.BroadPhaseBvh(), narrow_phase,
                  rp.RigidBodySet(), colliders)
    pair = narrow_phase.contact_pair(ha, hb)
    return pair, pair is not None and pair.collider1 != ha


verdict, _ = narrow(PREDICTION)
hit = verdict is not None and bool(verdict.has_any_active_contact)
pair, flipped = narrow(REACH)
best = None  # the deepest contact point and its manifold's world normal
for manifold in pair.manifolds if pair is not None else ():
    for point in manifold.points:
        if best is None or point.dist < best[0]:
            best = (float(point.dist), manifold.data.normal.to_tuple())
if best is None:  # no contact point: crosscheck records both as undefined
    distance = normal = "undefined"
else:
    distance, n = best
    n = (-n[0], -n[1], -n[2]) if flipped else n  # from A to B
    normal = tuple(n[:$dim])
""")
RESPONSE = Template("""\
MAX_STEPS = $max_steps
PARAMETERS = $parameters  # IntegrationParameters overrides
bodies = [  # (in a 2-D case z translation is locked: no motion out of the plane z = 0)
$bodies
]
colliders = [
$colliders
]
$approach

# Stop when the bodies no longer approach (not above this tolerance) without a push.
TOL = $rtol * max((abs(x) for x in (*A_VELOCITY, *B_VELOCITY)), default=0.0)
world = rp.PhysicsWorld(gravity=(0.0, 0.0, 0.0))
params = world.integration_parameters
for key, value in PARAMETERS:
    setattr(params, key, value)
handles = [world.add_body(body, [collider])
           for body, collider in zip(bodies, colliders, strict=True)]
a, b = (world.rigid_bodies[h] for h in handles)
resolved_at = None  # the centres at the start of the step whose solver pushed A and B apart
for _ in range(MAX_STEPS):
    pa, pb = a.translation.to_tuple(), b.translation.to_tuple()
    world.step()
    va, vb = a.linvel.to_tuple(), b.linvel.to_tuple()
    if any(p.total_impulse_magnitude() > 0.0 for p in world.narrow_phase.contact_pairs()):
        resolved_at = (pa, pb)
        break
    if not approach_speed(pa, pb, va, vb) > TOL:  # NaN (coincident centres): stop
        break
if not world.quarantine.is_empty():
    raise FloatingPointError(f"rapier quarantined a body whose state became non-finite "
                             f"({world.quarantine})")
$result""")
RESULT_3D = "v1, v2 = va, vb\n"
RESULT_2D = """\
if abs(va[2]) > 0.0 or abs(vb[2]) > 0.0:  # crosscheck reports this as an error
    raise RuntimeError(f"2-D response left the plane z = 0: vz = {va[2]!r}, {vb[2]!r}")
v1, v2 = va[:2], vb[:2]
if resolved_at is not None:
    resolved_at = (resolved_at[0][:2], resolved_at[1][:2])
"""
TUNED_BODY = ("rp.RigidBody.dynamic().translation({c}).linvel({v}).can_sleep(False)\n"
              "        .soft_ccd_prediction({ccd}).locked_axes(rp.LockedAxes.ROTATION_LOCKED)\n"
              "        .linear_damping(0.0).angular_damping(0.0){z}")
DEFAULT_BODY = "rp.RigidBody.dynamic().translation({c}).linvel({v}){z}"
TUNED_COLLIDER = ("rp.Collider.ball({r}).mass({m}).friction(0.0).restitution({own})\n"
                  "        .restitution_combine_rule(rp.CoefficientCombineRule.{rule})")
DEFAULT_COLLIDER = "rp.Collider.ball({r}).mass({m}).restitution(RESTITUTION)"


def _shapes(case: PairCase) -> str:
    if not isinstance(case, AabbCase):
        return ("shape_a = rp.SharedShape.ball(A_RADIUS)\n"
                "shape_b = rp.SharedShape.ball(B_RADIUS)")
    if case.dim == 3:
        return ("shape_a = rp.SharedShape.cuboid(*A_HALF)  # half-extents\n"
                "shape_b = rp.SharedShape.cuboid(*B_HALF)")
    return ("# A 2-D case lies in the plane z = 0: both boxes get the z half-width 2 x the\n"
            "# largest half-width (1 if all are 0), so z is never the axis of least overlap.\n"
            "Z_HALF = 2.0 * max(abs(h) for half in (A_HALF, B_HALF) for h in half) or 1.0\n"
            "shape_a = rp.SharedShape.cuboid(*A_HALF, Z_HALF)  # half-extents\n"
            "shape_b = rp.SharedShape.cuboid(*B_HALF, Z_HALF)")


def _centre(which: str, dim: int) -> str:
    return f"({which}_CENTER[0], {which}_CENTER[1], 0.0)" if dim == 2 else f"{which}_CENTER"


def reach(case: PairCase) -> float:
    """The adapter's prediction distance for the distance pass: ``1 + 2 (|cb - ca| + the sum of
    the sizes)``, capped at float32's largest (rapier_engine's formula, in its order)."""
    sizes = [*case.a.half, *case.b.half] if isinstance(case, AabbCase) else [
        case.a.radius, case.b.radius]
    return min(rapier_engine.F32_MAX, 1.0 + 2.0 * (
        math.dist(to3(case.a.center), to3(case.b.center)) + sum(abs(x) for x in sizes)))


def _detection(adapter: RapierTuned, case: PairCase) -> str:
    return DETECTION.substitute(
        shapes=_shapes(case), centre_a=_centre("A", case.dim), centre_b=_centre("B", case.dim),
        prediction=literal(adapter.prediction), reach=literal(reach(case)), dim=case.dim)


def _response(adapter: RapierTuned, case: ResponseCase) -> str:
    tuned = type(adapter) is not RapierDefault
    body, collider = (TUNED_BODY, TUNED_COLLIDER) if tuned else (DEFAULT_BODY, DEFAULT_COLLIDER)
    z = "\n        .enabled_translations((True, True, False))" if case.dim == 2 else ""
    velocity = "({0}_VELOCITY[0], {0}_VELOCITY[1], 0.0)" if case.dim == 2 else "{0}_VELOCITY"
    bodies = ",\n".join(
        "    (" + body.format(c=_centre(w, case.dim), v=velocity.format(w),
                              ccd=number(rapier_response.SOFT_CCD), z=z) + ")" for w in "AB")
    colliders = ",\n".join(
        "    (" + collider.format(r=f"{w}_RADIUS", m=f"{w}_MASS", own=own, rule="MULTIPLY") + ")"
        for w, own in (("A", "RESTITUTION"), ("B", "1.0")))
    return RESPONSE.substitute(
        max_steps=rapier_response.MAX_STEPS, parameters=repr(adapter.parameters),
        bodies=bodies, colliders=colliders, approach=APPROACH,
        rtol=number(rapier_response.APPROACH_RTOL),
        result=RESULT_2D if case.dim == 2 else RESULT_3D)


NOTES = ("rapier3d is float32 (Real = f32): every input is rounded to float32 by the binding.",)


def rapier_code(adapter: RapierTuned, case: PairCase) -> EngineCode:
    """The calls of ``adapter`` (a Rapier variant) on the case."""
    response = isinstance(case, ResponseCase)
    code = _response(adapter, case) if isinstance(case, ResponseCase) else _detection(adapter, case)
    try:
        rapier_engine.check_inputs(case)
    except (ValueError, OverflowError) as exc:
        code = raising(exc, "rapier", code)
    return EngineCode(("import math", "import rapier3d as rp"), code, NOTES,
                      resolved_at=response)
