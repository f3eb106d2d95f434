"""The engine part of a repro script for Box2D (``box2d``, ``box2d-default``; pybox2d).

The statements make, for one case, the calls of ``adapters/box2d_engine.py``: detection is
Box2D's narrow phase on two shapes at two transforms (``b2CollidePolygons`` /
``b2CollideCircles`` into a manifold, else ``b2Distance``), with the variant's polygon
radius and ``useRadii``; a response is a ``b2World`` with two dynamic circle bodies (mass
set through ``massData``), reset as the adapter's query resets them, and stepped with the
variant's dt and iterations until the first step after which the contact is touching.  The
variant's settings are read from the adapter (``Box2dTuned.variant``).  Inputs the adapter
refuses (negative sizes, masses <= 0, non-finite detection input) are a guard.
"""

from __future__ import annotations

from string import Template

from adapters import box2d_engine
from adapters.box2d_engine import Box2dTuned
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase
from crosscheck.studies.repro.code import EngineCode, number, raising

DETECTION = Template("""\
$shapes
xa, xb = b2.b2Transform(), b2.b2Transform()  # at the case's centres, angle 0
xa.position = (A_CENTER[0], A_CENTER[1])
xa.angle = 0.0
xb.position = (B_CENTER[0], B_CENTER[1])
xb.angle = 0.0
manifold, world_manifold = b2.b2Manifold(), b2.b2WorldManifold()

b2.$collide(manifold, shape_a, xa, shape_b, xb)  # Box2D's narrow phase
if manifold.pointCount:
    world_manifold.Initialize(manifold, xa, shape_a.radius, xb, shape_b.radius)
    n = world_manifold.normal  # from A to B
    hit, distance, normal = True, None, (float(n[0]), float(n[1]))  # no penetration depth
else:
    out = b2.b2Distance(shapeA=shape_a, shapeB=shape_b, transformA=xa, transformB=xb,
                        useRadii=$use_radii)
    hit, distance = False, float(out.distance)
    # the unit vector from A's witness point to B's (float64), none when they coincide
    dx, dy = out.pointB[0] - out.pointA[0], out.pointB[1] - out.pointA[1]
    length = math.hypot(dx, dy)
    normal = (dx / length, dy / length) if length > 0 else None
""")
RESPONSE = Template("""\
MAX_STEPS = $max_steps
DT, VELOCITY_ITERATIONS, POSITION_ITERATIONS = $dt, $velocity_iterations, $position_iterations
world = b2.b2World(gravity=(0.0, 0.0))
world.SetAllowSleeping($sleep)  # (b2World(doSleep=...) only sets a Python attribute)
bodies = []
# Restitution mixes by max: A's fixture gets e, B's 0.
for centre, velocity, radius, mass, e in ((A_CENTER, A_VELOCITY, A_RADIUS, A_MASS, RESTITUTION),
                                          (B_CENTER, B_VELOCITY, B_RADIUS, B_MASS, 0.0)):
    body = world.CreateDynamicBody(position=(float(centre[0]), float(centre[1])),
                                   linearVelocity=(float(velocity[0]), float(velocity[1])),
                                   fixedRotation=$fixed_rotation)
    body.CreateCircleFixture(radius=radius, density=0.0, restitution=e$friction)
    moment = $moment
    body.massData = b2.b2MassData(mass=mass, center=(0.0, 0.0), I=moment)
    bodies.append(body)
a, b = bodies

# The query's reset: both deactivated (no contact nor cached impulse left), then back at
# the case's start.
b.active = False
a.active = False
for body, centre, velocity in ((a, A_CENTER, A_VELOCITY), (b, B_CENTER, B_VELOCITY)):
    body.active = True
    body.transform = ((float(centre[0]), float(centre[1])), 0.0)
    body.linearVelocity = (float(velocity[0]), float(velocity[1]))
    body.angularVelocity = 0.0
    body.awake = True


def approaching(a, b):
    # whether B moves towards A along their line of centres (False for NaN)
    (pa, pb), (va, vb) = (a.position, b.position), (a.linearVelocity, b.linearVelocity)
    return bool((vb[0] - va[0]) * (pb[0] - pa[0]) + (vb[1] - va[1]) * (pb[1] - pa[1]) < 0.0)


# Step until the first step after which the contact is touching (resolved there), or until
# the bodies no longer approach.
resolved_at = None  # the centres read before that step
for _ in range(MAX_STEPS):
    start = ((float(a.position[0]), float(a.position[1])),
             (float(b.position[0]), float(b.position[1])))
    world.Step(DT, VELOCITY_ITERATIONS, POSITION_ITERATIONS)
    if any(edge.contact.touching for edge in a.contacts):
        resolved_at = start
        break
    if not approaching(a, b):
        break
v1 = (float(a.linearVelocity[0]), float(a.linearVelocity[1]))
v2 = (float(b.linearVelocity[0]), float(b.linearVelocity[1]))
""")


def _shapes(case: PairCase, polygon_radius: float | None) -> str:
    if not isinstance(case, AabbCase):
        return ("shape_a = b2.b2CircleShape(radius=A_RADIUS)\n"
                "shape_b = b2.b2CircleShape(radius=B_RADIUS)")
    lines = ["shape_a = b2.b2PolygonShape(box=(A_HALF[0], A_HALF[1]))  # SetAsBox(hx, hy)",
             "shape_b = b2.b2PolygonShape(box=(B_HALF[0], B_HALF[1]))"]
    if polygon_radius is None:
        lines.append("# (polygon radius: Box2D's b2_polygonRadius skin, kept)")
    else:
        lines += [f"shape_a.radius = {number(polygon_radius)}  # the polygon skin",
                  f"shape_b.radius = {number(polygon_radius)}"]
    return "\n".join(lines)


def _response(adapter: Box2dTuned, case: ResponseCase) -> str:
    v = adapter.variant
    friction = "" if v.friction is None else f", friction={number(v.friction)}"
    return RESPONSE.substitute(
        max_steps=box2d_engine.MAX_STEPS, dt=number(v.dt),
        velocity_iterations=v.velocity_iterations, position_iterations=v.position_iterations,
        sleep=v.sleep, fixed_rotation=v.fixed_rotation, friction=friction,
        moment="0.0  # fixedRotation" if v.fixed_rotation
        else "0.5 * mass * radius**2  # a disc's moment")


def box2d_code(adapter: Box2dTuned, case: PairCase) -> EngineCode:
    """The calls of ``adapter`` (a Box2D variant) on the case."""
    v = adapter.variant
    if isinstance(case, ResponseCase):
        code = _response(adapter, case)
    else:
        circles = not isinstance(case, AabbCase)
        code = DETECTION.substitute(
            shapes=_shapes(case, v.polygon_radius), use_radii=v.use_radii or circles,
            collide="b2CollideCircles" if circles else "b2CollidePolygons")
    why = box2d_engine.refusal(case)
    if why:
        code = raising(ValueError(why), "Box2D", code)
    return EngineCode(("import math", "import Box2D as b2"), code,
                      ("Box2D is float32: every input is rounded to float32 by the binding.",),
                      resolved_at=isinstance(case, ResponseCase))
