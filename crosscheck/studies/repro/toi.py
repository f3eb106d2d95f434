"""The engine part of a repro script for a time of impact (``sphere_toi``): FCL, Box2D, Rapier.

The statements make the calls of :mod:`adapters.fcl_toi` (``continuousCollide`` with the
variant's ``CCDSolverType``), :mod:`adapters.box2d_toi` (``b2TimeOfImpact`` on two circle
sweeps, ``b2Distance`` at its time) and :mod:`adapters.rapier_toi` (``QueryPipeline.
cast_shape`` of A's ball with the relative velocity against B's), and leave the answer in
``hit``, ``toi`` and ``normal`` (``"undefined"`` without a contact).  The inputs are the
case's centres, radii, velocities and ``DURATION`` (:func:`toi_inputs`); inputs the
adapters refuse (:func:`adapters.sphere_toi.refusal`) are a guard.
"""

from __future__ import annotations

from string import Template

from adapters import fcl_toi
from adapters.sphere_toi import refusal
from crosscheck.core.schema import ToiCase
from crosscheck.studies.repro.code import EngineCode, literal, raising, vector
from crosscheck.studies.repro.engines import REFERENCE_HELPERS

Input = tuple[str, str, str, str]

END = """\
# End centres: center + velocity x duration (float64), as the adapter computes them.
A_END = tuple(c + v * DURATION for c, v in zip(A_CENTER, A_VELOCITY, strict=True))
B_END = tuple(c + v * DURATION for c, v in zip(B_CENTER, B_VELOCITY, strict=True))
"""
CENTRE_NORMAL = """\


def centre_normal(t):
    # the unit vector from A's centre to B's at time t (float64), from the case's motion
    d = [(cb - ca) + (vb - va) * t
         for ca, cb, va, vb in zip(A_CENTER, B_CENTER, A_VELOCITY, B_VELOCITY, strict=True)]
    length = math.sqrt(math.fsum(x * x for x in d))
    return tuple(x / length for x in d) if length > 0 else "undefined"


"""
FCL = Template(END + CENTRE_NORMAL + """\
def at3(v):  # 2-D cases lie in the plane z = 0
    return [v[0], v[1], v[2] if len(v) > 2 else 0.0]


a = fcl.CollisionObject(fcl.Sphere(A_RADIUS), fcl.Transform(at3(A_CENTER)))
b = fcl.CollisionObject(fcl.Sphere(B_RADIUS), fcl.Transform(at3(B_CENTER)))
end_a, end_b = fcl.Transform(at3(A_END)), fcl.Transform(at3(B_END))
request = fcl.ContinuousCollisionRequest(ccd_solver_type=fcl.CCDSolverType.$solver)
result = fcl.ContinuousCollisionResult()  # fresh: python-fcl keeps the minimum time in it
returned = fcl.continuousCollide(a, end_a, b, end_b, request, result)
print("# continuousCollide returned", returned, "is_collide", result.is_collide,
      "time_of_contact", result.time_of_contact)
if returned == -1.0:  # FCL's "not computed" (ray shooting; the polynomial solver on spheres)
    hit = toi = normal = "undefined"
elif result.is_collide:
    # FCL's time is normalised to [0, 1]; the binding gives no contact normal
    hit, toi = True, float(result.time_of_contact) * DURATION
    normal = centre_normal(toi)
    if normal != "undefined":
        normal = normal[:len(A_CENTER)]
else:
    hit, toi, normal = False, "undefined", "undefined"
""")
BOX2D = END + """\
shape_a = b2.b2CircleShape(radius=A_RADIUS)
shape_b = b2.b2CircleShape(radius=B_RADIUS)
sweeps = []
for start, end in ((A_CENTER, A_END), (B_CENTER, B_END)):
    sweep = b2.b2Sweep()  # (1 - t) c0 + t c over Box2D's t in [0, 1]
    sweep.localCenter = (0.0, 0.0)
    sweep.c0 = (start[0], start[1])
    sweep.c = (end[0], end[1])
    sweep.a0 = sweep.a = sweep.alpha0 = 0.0
    sweeps.append(sweep)
sweep_a, sweep_b = sweeps
state, t = b2.b2TimeOfImpact(shapeA=shape_a, shapeB=shape_b, sweepA=sweep_a, sweepB=sweep_b,
                             tMax=1.0)
states = {getattr(b2.b2TOIOutput, n): n for n in dir(b2.b2TOIOutput) if n.startswith("e_")}
print("# b2TimeOfImpact:", states.get(state, state), "t =", t)
if state == b2.b2TOIOutput.e_separated:
    hit, toi, normal = False, "undefined", "undefined"
elif state in (b2.b2TOIOutput.e_touching, b2.b2TOIOutput.e_overlapped):
    t = float(t)
    near = b2.b2Distance(shapeA=shape_a, shapeB=shape_b, transformA=sweep_a.GetTransform(t),
                         transformB=sweep_b.GetTransform(t), useRadii=False)
    dx, dy = near.pointB[0] - near.pointA[0], near.pointB[1] - near.pointA[1]
    length = math.hypot(dx, dy)
    hit, toi = True, t * DURATION
    normal = (dx / length, dy / length) if length > 0 else "undefined"
else:
    raise RuntimeError(f"b2TimeOfImpact ended in state {states.get(state, state)}")
"""
RAPIER = """\
def at3(v):  # 2-D cases lie in the plane z = 0
    return (v[0], v[1], v[2] if len(v) > 2 else 0.0)


# Cast in B's frame of motion: B's ball at rest, A's ball with velocity va - vb.
colliders = rp.ColliderSet()
colliders.insert(rp.Collider.new(rp.SharedShape.ball(B_RADIUS)).translation(at3(B_CENTER))
                 .build())
bodies = rp.RigidBodySet()
pipeline = rp.QueryPipeline(rp.BroadPhaseBvh(), rp.NarrowPhase(), bodies, colliders)
pipeline.update(bodies, colliders)
velocity = at3(tuple(a - b for a, b in zip(A_VELOCITY, B_VELOCITY, strict=True)))
options = rp.ShapeCastOptions(max_time_of_impact=DURATION, target_distance=0.0,
                              stop_at_penetration=True,
                              compute_impact_geometry_on_penetration=True)
found = pipeline.cast_shape(rp.Isometry3(at3(A_CENTER)), velocity, rp.SharedShape.ball(A_RADIUS),
                            options)
if found is None:
    hit, toi, normal = False, "undefined", "undefined"
else:
    cast = found[1]
    print("# ShapeCastHit:", cast.status, "normal1", cast.normal1, "witness1", cast.witness1)
    # normal1: B's outward normal (world space), pointing to A; A to B is its opposite
    hit, toi = True, float(cast.time_of_impact)
    normal = tuple(-float(x) for x in cast.normal1.to_tuple()[:len(A_CENTER)])
"""


def toi_inputs(case: ToiCase) -> tuple[Input, ...]:
    """Centres, radii and velocities of A and B, and the interval's ``DURATION``."""
    out: list[Input] = []
    for which in ("a", "b"):
        body = getattr(case, which)
        up = which.upper()
        out += [(f"{up}_CENTER", vector(body.center), f"{which}.center", repr(body.center)),
                (f"{up}_RADIUS", literal(body.radius), f"{which}.radius", repr(body.radius)),
                (f"{up}_VELOCITY", vector(body.velocity), f"{which}.velocity",
                 repr(body.velocity))]
    return (*out, ("DURATION", literal(case.duration), "duration", repr(case.duration)))


def _guarded(case: ToiCase, engine: str, code: str) -> str:
    why = refusal(case)
    return raising(ValueError(why), engine, code) if why else code


def fcl_toi_code(solver: str, case: ToiCase) -> EngineCode:
    """FCL's ``continuousCollide`` with the solver of :data:`adapters.fcl_toi.SOLVERS`."""
    code = FCL.substitute(solver=fcl_toi.SOLVERS[solver])
    return EngineCode(("import math", "import fcl"), _guarded(case, "FCL", code),
                      ("FCL's time is normalised to [0, 1]: toi = time_of_contact x DURATION.",),
                      inputs=toi_inputs(case))


def box2d_toi_code(case: ToiCase) -> EngineCode:
    """Box2D's ``b2TimeOfImpact`` on two circle sweeps (both variants alike)."""
    code = BOX2D
    if case.dim != 2:
        code = raising(ValueError(f"box2d is a 2-D engine: no {case.dim}-D cases"), "Box2D",
                       code)
    return EngineCode(("import math", "import Box2D as b2"), _guarded(case, "Box2D", code),
                      ("Box2D is float32: every input is rounded to float32 by the binding.",),
                      inputs=toi_inputs(case))


REFERENCE = """\
# The textbook's discrete sphere test at the interval's two ends (the reference variants'
# time of impact): centres c + v t in float64, then the formula in F.
hit, toi, normal = False, "undefined", "undefined"
for t in (0.0, DURATION):
    ca = [c + v * t for c, v in zip(A_CENTER, A_VELOCITY, strict=True)]
    cb = [c + v * t for c, v in zip(B_CENTER, B_VELOCITY, strict=True)]
    p1, p2 = [F(x) for x in ca], [F(x) for x in cb]
    d = [a - b for a, b in zip(p1, p2, strict=True)]  # d = s1.pos - s2.pos
    length = np.sqrt(dot(d, d))
    if length < F(A_RADIUS) + F(B_RADIUS):  # touching is not a hit
        hit, toi = True, t
        normal = ("undefined" if all(a == b for a, b in zip(p1, p2, strict=True))
                  else tuple(float(-x / length) for x in d))  # from A to B
        break
"""


def reference_toi_code(precision: str, case: ToiCase) -> EngineCode:
    """The reference variants' discrete baseline (:func:`crosscheck.truth.oracle.sampled_impact`)
    in numpy scalars of the variant's precision."""
    dtype = {"f64": "float64", "f32": "float32"}[precision]
    return EngineCode(("import numpy as np",),
                      REFERENCE_HELPERS.substitute(dtype=dtype) + REFERENCE,
                      (f"The textbook's sphere test in numpy {dtype} at t = 0 and t = DURATION "
                       "only: a contact between the two samples is not seen.",),
                      inputs=toi_inputs(case))


def rapier_toi_code(case: ToiCase) -> EngineCode:
    """Rapier's ``QueryPipeline.cast_shape`` of A's ball against B's (both variants alike)."""
    return EngineCode(("import math", "import rapier3d as rp"),
                      _guarded(case, "rapier", RAPIER),
                      ("Rapier is float32 (Real = f32): inputs are rounded by the binding.",),
                      inputs=toi_inputs(case))
