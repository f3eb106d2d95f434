"""The engine part of a repro script for PyBullet (``pybullet``, ``pybullet-default``).

The statements make, for one case, exactly the calls ``adapters/pybullet_engine.py`` makes
on a new DIRECT client: the variant's world settings, the collision shapes (one shape when
A and B share geometry and size, as the adapter's cache gives), two new multibodies
(the adapter's body pool promises a reused body answers bit for bit as a new one), the
variant's per-body dynamics, then detection (``performCollisionDetection``, contact points,
the deepest closest point) or the response loop (reset, ``stepSimulation`` until the bodies
no longer approach along the line of centres the step detected from).  Masses, world and
body settings and the loop's limits are read from the adapter, so the script follows it.
"""

from __future__ import annotations

from string import Template

from adapters import pybullet_engine
from adapters.pybullet_engine import PyBulletTuned
from crosscheck.core.geometry import to3
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase
from crosscheck.studies.repro.code import APPROACH, EngineCode

CLIENT = Template("""\
cid = pybullet.connect(pybullet.DIRECT)  # no GUI
pybullet.setGravity(0.0, 0.0, 0.0, physicsClientId=cid)
$settings
$sizes
shape_a = $shape_a
shape_b = $shape_b
CENTRE_A, CENTRE_B = $centres
# Two base-only multibodies ($masses).
a = pybullet.createMultiBody(baseMass=$mass_a, baseCollisionShapeIndex=shape_a,
                             basePosition=CENTRE_A, physicsClientId=cid)
$filter_a
b = pybullet.createMultiBody(baseMass=$mass_b, baseCollisionShapeIndex=shape_b,
                             basePosition=CENTRE_B, physicsClientId=cid)
$filter_b
""")
FILTER = ("pybullet.setCollisionFilterGroupMask({0}, -1, {1!r}, {2!r}, physicsClientId=cid)"
          "  # as a dynamic base's")
FILTER_NOTE = ("# (a static base's own collision filter excludes static-static pairs: the "
               "adapter gives\n# a detection body the filter createMultiBody gives a dynamic "
               "base)\n")
DETECTION = Template("""\
pybullet.performCollisionDetection(physicsClientId=cid)
hit = len(pybullet.getContactPoints(a, b, physicsClientId=cid)) > 0
# The deepest closest point within a bound above any possible gap; contactNormalOnB
# points from B to A, so it is flipped.
bound = 1.0 + 2.0 * math.dist(CENTRE_A, CENTRE_B)
points = pybullet.getClosestPoints(a, b, bound, physicsClientId=cid)
if not points:
    distance, normal = None, None
else:
    deepest = min(points, key=lambda point: point[8])
    normal = tuple(-float(x) for x in deepest[7][:$dim])
    distance = float(deepest[8])
""")
RESPONSE = Template("""\
MAX_STEPS = $max_steps
# Restitution combines as the product of the bodies' values: A gets e, B 1.0.
for body, mass, e in ((a, A_MASS, RESTITUTION), (b, B_MASS, 1.0)):
    pybullet.changeDynamics(body, -1, restitution=e, $dynamics
                            physicsClientId=cid)
# Stop when the relative velocity along the line of centres the step detected from no
# longer approaches (not above this tolerance).
TOL = $rtol * max((abs(x) for x in (*A_VELOCITY, *B_VELOCITY)), default=0.0)
MOTION = ((a, CENTRE_A, $velocity_a), (b, CENTRE_B, $velocity_b))


$approach

for body, p, v in MOTION:
    pybullet.resetBasePositionAndOrientation(body, p, (0.0, 0.0, 0.0, 1.0), physicsClientId=cid)
    pybullet.resetBaseVelocity(body, v, (0.0, 0.0, 0.0), physicsClientId=cid)
resolved_at = None  # the centres at the start of the first step that reported the contact
for _ in range(MAX_STEPS):
    pa = pybullet.getBasePositionAndOrientation(a, physicsClientId=cid)[0]
    pb = pybullet.getBasePositionAndOrientation(b, physicsClientId=cid)[0]
    pybullet.stepSimulation(physicsClientId=cid)
    if resolved_at is None and pybullet.getContactPoints(a, b, physicsClientId=cid):
        resolved_at = (pa, pb)
    va = pybullet.getBaseVelocity(a, physicsClientId=cid)[0]
    vb = pybullet.getBaseVelocity(b, physicsClientId=cid)[0]
    if not approach_speed(pa, pb, va, vb) > TOL:  # NaN (coincident): stop
        break
$result""")
RESULT_3D = "v1, v2 = tuple(va), tuple(vb)\n"
RESULT_2D = """\
if abs(va[2]) > 0.0 or abs(vb[2]) > 0.0:  # crosscheck reports this as an error
    raise RuntimeError(f"2-D response left the plane z = 0: vz = {va[2]!r}, {vb[2]!r}")
v1, v2 = tuple(va[:2]), tuple(vb[:2])
if resolved_at is not None:
    resolved_at = (tuple(resolved_at[0][:2]), tuple(resolved_at[1][:2]))
"""


def _settings(adapter: PyBulletTuned) -> str:
    if not adapter.world:
        return "# (every physics engine parameter at pybullet's default)"
    lines = "".join(f"\n    {name}={value!r}," for name, value in adapter.world.items())
    return f"pybullet.setPhysicsEngineParameter({lines}\n    physicsClientId=cid)"


def _sizes(case: PairCase) -> str:
    if not isinstance(case, AabbCase):
        return "SIZE_A, SIZE_B = (A_RADIUS,), (B_RADIUS,)"
    if case.dim == 3:
        return "SIZE_A, SIZE_B = A_HALF, B_HALF  # halfExtents: half-widths"
    return ("# A 2-D case lies in the plane z = 0: both boxes get the z half-width 2 x the\n"
            "# largest half-width (1 if all are 0), so z is never the axis of least overlap.\n"
            "Z_HALF = 2.0 * max(abs(h) for half in (A_HALF, B_HALF) for h in half) or 1.0\n"
            "SIZE_A = (A_HALF[0], A_HALF[1], Z_HALF)  # halfExtents: half-widths\n"
            "SIZE_B = (B_HALF[0], B_HALF[1], Z_HALF)")


def _shapes(case: PairCase) -> tuple[str, str]:
    """The two shape expressions; B reuses A's shape when the adapter's cache would."""
    if isinstance(case, AabbCase):
        make = "pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=SIZE_{0}, " \
               "physicsClientId=cid)"
    else:
        make = "pybullet.createCollisionShape(pybullet.GEOM_SPHERE, radius=SIZE_{0}[0], " \
               "physicsClientId=cid)"
    (geom_a, size_a, _), (geom_b, size_b, _) = pybullet_engine.body_specs(case)
    cache = {(geom_a, size_a): "A"}
    shared = (geom_b, size_b) in cache
    return make.format("A"), ("shape_a  # same geometry and size: one cached shape"
                              if shared else make.format("B"))


def _masses(case: PairCase) -> tuple[str, str, str]:
    (_, _, mass_a), (_, _, mass_b) = pybullet_engine.body_specs(case)
    if isinstance(case, ResponseCase):
        return "A_MASS", "B_MASS", "the case's masses"
    kind = "static" if mass_a == mass_b == 0.0 else "detection"
    return repr(mass_a), repr(mass_b), f"{kind} bodies: masses {mass_a!r}, {mass_b!r}"


def _dynamics(adapter: PyBulletTuned, case: ResponseCase) -> str:
    specs = pybullet_engine.body_specs(case)
    # the adapter sets the mass again on bodies it may pool (a reused body keeps its last)
    pooled = pybullet_engine.ordinary(case, to3(case.a.center), to3(case.b.center), specs)
    words = (["mass=mass"] if pooled else []) + [f"{k}={v!r}" for k, v in adapter.body.items()]
    return "".join(word + ", " for word in words)


def pybullet_code(adapter: PyBulletTuned, case: PairCase) -> EngineCode:
    """The calls of ``adapter`` (a PyBullet variant) on the case, on a new client."""
    flat = case.dim == 2
    shape_a, shape_b = _shapes(case)
    mass_a, mass_b, masses = _masses(case)
    response = isinstance(case, ResponseCase)
    filters = ["", ""] if response else [
        FILTER.format(body, pybullet_engine.GROUP, pybullet_engine.MASK) for body in "ab"]
    code = CLIENT.substitute(
        settings=_settings(adapter), sizes=_sizes(case), shape_a=shape_a, shape_b=shape_b,
        centres="(A_CENTER[0], A_CENTER[1], 0.0), (B_CENTER[0], B_CENTER[1], 0.0)"
        if flat else "A_CENTER, B_CENTER", mass_a=mass_a, mass_b=mass_b, masses=masses,
        filter_a=filters[0] if response else FILTER_NOTE + filters[0], filter_b=filters[1])
    if isinstance(case, ResponseCase):
        code += RESPONSE.substitute(
            approach=APPROACH,
            max_steps=repr(pybullet_engine.MAX_STEPS), rtol=repr(pybullet_engine.APPROACH_RTOL),
            dynamics=_dynamics(adapter, case),
            velocity_a="(A_VELOCITY[0], A_VELOCITY[1], 0.0)" if flat else "A_VELOCITY",
            velocity_b="(B_VELOCITY[0], B_VELOCITY[1], 0.0)" if flat else "B_VELOCITY",
            result=RESULT_2D if flat else RESULT_3D)
    else:
        code += DETECTION.substitute(dim=case.dim)
    return EngineCode(("import math", "import pybullet"), code,
                      resolved_at=isinstance(case, ResponseCase))
