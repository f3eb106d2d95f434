"""The engine part of a repro script for FCL, pymunk and the textbook formula.

Each function here writes the Python statements that make, for one case, exactly the
calls the engine's adapter makes (``adapters/fcl_engine.py``, ``adapters/pymunk_engine.py``,
``adapters/reference.py`` with ``reference_impl/formulas.py``), with the adapter's own
settings read from its class, and that leave the engine's answer in the variables named
after the case's quantities (``hit``, ``distance``, ``normal``; ``v1``, ``v2``).  The
script around them (inputs, printing) is :mod:`crosscheck.studies.repro.script`'s; the other
engines' parts have a module each (:mod:`crosscheck.studies.repro.code` lists them).

The statements use the script's input constants: ``A_CENTER``, ``B_CENTER`` and ``A_HALF``,
``B_HALF`` (boxes) or ``A_RADIUS``, ``B_RADIUS`` (spheres), plus ``A_MASS``, ``B_MASS``,
``A_VELOCITY``, ``B_VELOCITY`` and ``RESTITUTION`` (responses).
"""

from __future__ import annotations

from string import Template

from adapters import pymunk_engine
from adapters.pymunk_engine import PymunkTuned
from adapters.reference import ReferenceF64
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase
from crosscheck.studies.repro.code import EngineCode

FCL_BOXES_2D = """\
# fcl.Box takes full side lengths: the adapter passes 2 x the half-widths (exact in binary).
# A 2-D case lies in the plane z = 0: both boxes get the z half-width 2 x the largest
# half-width (1 if all are 0), so z is never the axis of least overlap nor a gap.
Z_HALF = 2.0 * max(abs(h) for half in (A_HALF, B_HALF) for h in half) or 1.0
shape_a = fcl.Box(*[2.0 * h for h in (*A_HALF, Z_HALF)])
shape_b = fcl.Box(*[2.0 * h for h in (*B_HALF, Z_HALF)])
"""
FCL_BOXES_3D = """\
# fcl.Box takes full side lengths: the adapter passes 2 x the half-widths (exact in binary).
shape_a = fcl.Box(*[2.0 * h for h in A_HALF])
shape_b = fcl.Box(*[2.0 * h for h in B_HALF])
"""
FCL_SPHERES = """\
shape_a = fcl.Sphere(A_RADIUS)
shape_b = fcl.Sphere(B_RADIUS)
"""
FCL_OBJECTS = Template("""\
# Two collision objects at the case's centres (identity rotation)$embedding.
a = fcl.CollisionObject(shape_a, fcl.Transform($centre_a))
b = fcl.CollisionObject(shape_b, fcl.Transform($centre_b))
collision_request = fcl.CollisionRequest(num_max_contacts=1, enable_contact=True)
distance_request = fcl.DistanceRequest(enable_nearest_points=True,
                                       enable_signed_distance=True)

hits = fcl.CollisionResult()
fcl.collide(a, b, collision_request, hits)
hit = bool(hits.is_collision)
""")
FCL_DISTANCE = """\
near = fcl.DistanceResult()
distance = float(fcl.distance(a, b, distance_request, near))
# normal: the contact's normal in collision (FCL: from o1 to o2, i.e. A to B), else the
# unit vector from A's nearest point to B's when the distance is > 0, else none.
normal = None
if hits.is_collision:
    normal = tuple(float(x) for x in hits.contacts[0].normal)
else:
    pa, pb = near.nearest_points
    if distance > 0 and pa is not None and pb is not None:
        v = [y - x for x, y in zip(pa, pb, strict=True)]
        length = math.sqrt(math.fsum(x * x for x in v))
        normal = tuple(float(x) / length for x in v) if length > 0 else None
"""
FCL_WITHOUT_DISTANCE = """\
# The signed distance hangs on these inputs (the run recorded its timeout): crosscheck
# asks collide alone first, so the normal is the contact's normal (A to B), if any.
distance = None
normal = tuple(float(x) for x in hits.contacts[0].normal) if hits.is_collision else None
"""
FCL_HANG = """\
print("# now the signed distance, which the run recorded as hanging on these inputs ...")
sys.stdout.flush()
near = fcl.DistanceResult()
print("# the signed distance returned", fcl.distance(a, b, distance_request, near))
"""


def fcl_code(case: PairCase, hung: frozenset[str] = frozenset()) -> EngineCode:
    """FCL's ``collide`` and signed ``distance`` on the case (``adapters.fcl_engine.Fcl``).

    ``hung``: the quantities the run recorded as a declared hang (``distance``); the script
    then answers without the distance call (as the runner asks the adapter), prints, and
    makes the hanging call last.
    """
    if isinstance(case, AabbCase):
        shapes = FCL_BOXES_2D if case.dim == 2 else FCL_BOXES_3D
    else:
        shapes = FCL_SPHERES
    flat = case.dim == 2
    objects = FCL_OBJECTS.substitute(
        embedding=", 2-D at z = 0" if flat else "",
        centre_a="[A_CENTER[0], A_CENTER[1], 0.0]" if flat else "list(A_CENTER)",
        centre_b="[B_CENTER[0], B_CENTER[1], 0.0]" if flat else "list(B_CENTER)")
    cut = ("if normal is not None:  # a 2-D case: the normal without z\n"
           "    normal = normal[:2]\n" if flat else "")
    if "distance" in hung:
        return EngineCode(("import math", "import fcl"),
                          shapes + objects + FCL_WITHOUT_DISTANCE + cut, tail=FCL_HANG)
    return EngineCode(("import math", "import fcl"), shapes + objects + FCL_DISTANCE + cut)


PYMUNK_DETECTION = Template("""\
# Two static bodies at the case's centres, each with a $what; shapes outside a Space
# keep stale positions until cache_bb().
body_a = pymunk.Body(body_type=pymunk.Body.STATIC)
body_a.position = (A_CENTER[0], A_CENTER[1])
shape_a = $shape_a
shape_a.cache_bb()
body_b = pymunk.Body(body_type=pymunk.Body.STATIC)
body_b.position = (B_CENTER[0], B_CENTER[1])
shape_b = $shape_b
shape_b.cache_bb()

try:
    points = shape_a.shapes_collide(shape_b)
except AssertionError:  # pymunk 7's signal for "no contact": a ContactPointSet with no points
    points = None
if points is None or not points.points:  # pymunk 6 returns the empty ContactPointSet
    hit, distance, normal = False, None, None  # pymunk gives no separation distance
else:
    hit = True
    distance = min(float(p.distance) for p in points.points)
    normal = (float(points.normal.x), float(points.normal.y))  # from shape_a to shape_b
""")
PYMUNK_RESPONSE = Template("""\
MAX_STEPS = $max_steps
DT = $dt
# Two dynamic discs; elasticities combine as their product, so A gets e and B 1.0.
bodies, shapes = [], []
for mass, radius, elasticity in ((A_MASS, A_RADIUS, RESTITUTION), (B_MASS, B_RADIUS, 1.0)):
    body = pymunk.Body(mass, $moment)
    shape = pymunk.Circle(body, radius)
    shape.elasticity = elasticity
$friction    bodies.append(body)
    shapes.append(shape)
space = pymunk.Space()
space.gravity = (0.0, 0.0)
space.damping = 1.0
$space_settings
space.add(*bodies, *shapes)
a, b = bodies
contact = []


def pre_solve(arbiter, space, data):
    # the centres where the solver first handles the contact (crosscheck's resolved_at)
    if not contact:
        contact.append(((float(a.position.x), float(a.position.y)),
                        (float(b.position.x), float(b.position.y))))
    return True  # pymunk 6 reads it (keep the contact); pymunk 7 ignores it


if hasattr(space, "on_collision"):  # pymunk >= 7
    space.on_collision(pre_solve=pre_solve)
else:  # pymunk 6
    space.add_default_collision_handler().pre_solve = pre_solve

# The query: shapes removed and re-added (no cached arbiter), the bias velocity of any
# earlier solve zeroed, then the case's centres and velocities.
space.remove(*shapes)
for body, centre, velocity in ((a, A_CENTER, A_VELOCITY), (b, B_CENTER, B_VELOCITY)):
    pymunk.Body.update_position(body, 0.0)
    body.angle = 0.0
    body.angular_velocity = 0.0
    body.position = (centre[0], centre[1])
    body.velocity = (velocity[0], velocity[1])
space.add(*shapes)
# Step until the first step in which the solver handled the contact, or until the
# bodies no longer approach, or MAX_STEPS.
for _ in range(MAX_STEPS):
    space.step(DT)
    if contact or not bool((b.velocity - a.velocity).dot(b.position - a.position) < 0.0):
        break
v1 = (float(a.velocity.x), float(a.velocity.y))
v2 = (float(b.velocity.x), float(b.velocity.y))
resolved_at = contact[0] if contact else None
""")


def _moment(moment: float) -> str:
    if moment == float("inf"):
        return 'float("inf")'
    return repr(moment)


def pymunk_code(adapter: PymunkTuned, case: PairCase) -> EngineCode:
    """pymunk's ``shapes_collide`` or stepped response, with ``adapter``'s Space settings."""
    notes = ("Run it without python -O: pymunk signals 'no contact' with an assert.",)
    if not isinstance(case, ResponseCase):
        box = isinstance(case, AabbCase)
        make = ("pymunk.Poly.create_box(body_{0}, (2.0 * {1}_HALF[0], 2.0 * {1}_HALF[1]))"
                if box else "pymunk.Circle(body_{0}, {1}_RADIUS)")
        code = PYMUNK_DETECTION.substitute(
            what="box (create_box takes full width and height: 2 x the half-widths)"
            if box else "circle",
            shape_a=make.format("a", "A"), shape_b=make.format("b", "B"))
        return EngineCode(("import pymunk",), code, notes)
    settings = [f"space.{name} = {value!r}" for name, value in (
        ("collision_slop", adapter.slop), ("collision_bias", adapter.bias),
        ("iterations", adapter.iterations)) if value is not None]
    code = PYMUNK_RESPONSE.substitute(
        max_steps=repr(pymunk_engine.MAX_STEPS), dt=repr(adapter.dt),
        space_settings="\n".join(settings) or "# (collision_slop, collision_bias and "
                                              "iterations at pymunk's defaults)",
        moment=_moment(pymunk_engine.MOMENT),
        friction="" if adapter.friction is None
        else f"    shape.friction = {adapter.friction!r}\n")
    return EngineCode(("import pymunk",), code, notes, resolved_at=True)


REFERENCE_HELPERS = Template("""\
F = np.$dtype  # the textbook's arithmetic: every input rounded to it, every operation in it
np.seterr(all="ignore")  # IEEE results (inf, nan), no warnings


def total(terms):
    # left-to-right sum, as the textbook's a.x + a.y + a.z
    acc = terms[0]
    for t in terms[1:]:
        acc = acc + t
    return acc


def dot(a, b):
    return total([x * y for x, y in zip(a, b, strict=True)])


""")
# The textbook formulas of reference_impl/formulas.py, written out as script text on purpose:
# a reproduction script must run with numpy alone, without this package.  The repro test
# (tests/studies/test_repro.py) runs them and checks they print the recorded values bit for bit,
# so the two cannot drift apart unnoticed.
REFERENCE_AABB = """\
def overlap_normal(overlaps, dc):
    # unit normal along the axis of least overlap, signed by cb - ca (undefined on a tie)
    smallest = min(overlaps)
    axes = [i for i, o in enumerate(overlaps) if o == smallest]
    if len(axes) > 1 or dc[axes[0]] == 0:
        return "undefined"
    sign = 1.0 if dc[axes[0]] > 0 else -1.0
    return tuple(sign if i == axes[0] else 0.0 for i in range(len(dc)))


n = len(A_CENTER)
dc = [F(B_CENTER[i]) - F(A_CENTER[i]) for i in range(n)]
s = [F(A_HALF[i]) + F(B_HALF[i]) for i in range(n)]
if not any(abs(dc[i]) > s[i] for i in range(n)):  # touching overlaps
    hit = True
    overlaps = [float(si - abs(d)) for d, si in zip(dc, s, strict=True)]
    if any(np.isnan(overlaps)):
        distance, normal = float("nan"), tuple(float("nan") for _ in dc)
    else:
        distance = 0.0 - min(overlaps)  # 0.0 - x, not -x: touching gives +0.0
        normal = overlap_normal(overlaps, [float(x) for x in dc])
else:
    hit = False
    gaps = [np.maximum(F(0), abs(d) - si) for d, si in zip(dc, s, strict=True)]
    signed = [g * np.sign(d) for g, d in zip(gaps, dc, strict=True)]
    length = np.sqrt(dot(signed, signed))
    normal = tuple(float(g / length) for g in signed)
    if not any(signed):
        normal = "undefined"  # coincident centres
    distance = float(np.sqrt(dot(gaps, gaps)))
"""
REFERENCE_SPHERE = """\
p1, p2 = [F(x) for x in A_CENTER], [F(x) for x in B_CENTER]
d = [a - b for a, b in zip(p1, p2, strict=True)]  # d = s1.pos - s2.pos
length = np.sqrt(dot(d, d))
sumradius = F(A_RADIUS) + F(B_RADIUS)
normal = tuple(float(-x / length) for x in d)  # from A to B
if all(a == b for a, b in zip(p1, p2, strict=True)):
    normal = "undefined"  # coincident centres
hit = bool(length < sumradius)  # touching is not a hit
distance = float(length - sumradius)
"""
REFERENCE_RESPONSE = """\
p1, v1, p2, v2 = ([F(x) for x in vec] for vec in (A_CENTER, A_VELOCITY, B_CENTER, B_VELOCITY))
m1, m2, e, one = F(A_MASS), F(B_MASS), F(RESTITUTION), F(1)
if all(a == b for a, b in zip(p1, p2, strict=True)):
    v1 = v2 = "undefined"  # coincident centres
elif m1 + m2 == 0:
    v1 = v2 = "undefined"  # zero total mass
else:
    x = [a - b for a, b in zip(p1, p2, strict=True)]
    length = np.sqrt(dot(x, x))
    x = [c / length for c in x]  # x.normalize()
    x1 = dot(x, v1)
    v1x = [c * x1 for c in x]
    v1y = [a - b for a, b in zip(v1, v1x, strict=True)]
    x = [-c for c in x]  # x = x * -1
    x2 = dot(x, v2)
    v2x = [c * x2 for c in x]
    v2y = [a - b for a, b in zip(v2, v2x, strict=True)]
    c11, c12 = (m1 - e * m2) / (m1 + m2), ((one + e) * m2) / (m1 + m2)
    c21, c22 = ((one + e) * m1) / (m1 + m2), (m2 - e * m1) / (m1 + m2)
    v1 = tuple(float(a * c11 + b * c12 + c) for a, b, c in zip(v1x, v2x, v1y, strict=True))
    v2 = tuple(float(a * c21 + b * c22 + c) for a, b, c in zip(v1x, v2x, v2y, strict=True))
"""


def reference_code(adapter: ReferenceF64, case: PairCase) -> EngineCode:
    """The textbook formula in ``adapter``'s precision, as ``reference_impl.formulas``."""
    dtype = {"f64": "float64", "f32": "float32"}[adapter.precision]
    if isinstance(case, AabbCase):
        body = REFERENCE_AABB
    elif isinstance(case, ResponseCase):
        body = REFERENCE_RESPONSE
    else:
        body = REFERENCE_SPHERE
    notes = (f"The textbook formula in numpy {dtype} scalars, operation by operation "
             "(a quantity with no defined value prints as undefined).",)
    return EngineCode(("import numpy as np",), REFERENCE_HELPERS.substitute(dtype=dtype) + body,
                      notes)
