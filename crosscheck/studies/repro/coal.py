"""The engine part of a repro script for coal (``coal``, ``coal-default``).

The statements make, for one case, the calls of ``adapters/coal_engine.py``: two geometries
(``Box`` with full side lengths, or ``Sphere``), their ``Transform3s`` (identity rotation,
the case's centre), a ``CollisionRequest`` and a ``DistanceRequest`` (the tuned variant sets
its GJK/EPA tolerance, computed by the adapter for the case), the ``ComputeCollision`` and
``ComputeDistance`` functors of the pair, and one call of each with a fresh result.  A
non-finite input is a guard: the adapter records every quantity as undefined.
"""

from __future__ import annotations

from string import Template

from adapters import coal_engine
from adapters.coal_engine import CoalTuned
from crosscheck.core.model import quantities_of
from crosscheck.core.schema import AabbCase, PairCase
from crosscheck.studies.repro.code import EngineCode, literal, undefined

QUERY = Template("""\
$shapes
collision_request, distance_request = coal.CollisionRequest(), coal.DistanceRequest()
$tolerance
# Identity rotation, translation at the case's centre$embedding.
ta = coal.Transform3s(np.eye(3), np.array($centre_a, dtype=np.float64))
tb = coal.Transform3s(np.eye(3), np.array($centre_b, dtype=np.float64))
collide = coal.ComputeCollision(shape_a, shape_b)  # functors that keep their solver
distance_of = coal.ComputeDistance(shape_a, shape_b)

hits = coal.CollisionResult()
collide(ta, tb, collision_request, hits)
near = coal.DistanceResult()
distance = float(distance_of(ta, tb, distance_request, near))  # signed: gap positive
hit = bool(hits.isCollision())
normal = tuple(float(x) for x in near.normal)  # from o1 to o2: A to B
if not all(math.isfinite(x) for x in normal):  # EPA's failure: crosscheck records undefined
    print("# coal gives no finite normal:", normal, "with distance", distance)
    normal = "undefined"
else:
    normal = normal[:$dim]
""")
TUNED = """\
# The coal variant's GJK and EPA tolerance for this case: min(max(1e-12 x M, 1e-12), 1e-3),
# M the case's largest |cb_i - ca_i| + |ha_i| + |hb_i| (spheres |cb - ca| + |ra| + |rb|).
TOLERANCE = {value}
for request in (collision_request, distance_request):
    request.gjk_tolerance = TOLERANCE
    request.epa_tolerance = TOLERANCE"""
DEFAULT = "# (CollisionRequest() and DistanceRequest() unchanged: coal's tolerances 1e-6)"


def _shapes(case: PairCase) -> str:
    if not isinstance(case, AabbCase):
        return "shape_a = coal.Sphere(A_RADIUS)\nshape_b = coal.Sphere(B_RADIUS)"
    lines = ["# coal.Box takes full side lengths: 2 x the half-widths (exact in binary)."]
    if case.dim == 2:
        lines += ["# A 2-D case lies in the plane z = 0: both boxes get the z half-width 2 x the",
                  "# largest half-width (1 if all are 0), so z is never the axis of least overlap.",
                  "Z_HALF = 2.0 * max(abs(h) for half in (A_HALF, B_HALF) for h in half) or 1.0",
                  "shape_a = coal.Box(*[2.0 * h for h in (*A_HALF, Z_HALF)])",
                  "shape_b = coal.Box(*[2.0 * h for h in (*B_HALF, Z_HALF)])"]
    else:
        lines += ["shape_a = coal.Box(*[2.0 * h for h in A_HALF])",
                  "shape_b = coal.Box(*[2.0 * h for h in B_HALF])"]
    return "\n".join(lines)


def coal_code(adapter: CoalTuned, case: PairCase) -> EngineCode:
    """The calls of ``adapter`` (a coal variant) on the case."""
    flat = case.dim == 2
    bad = coal_engine.non_finite(case)
    tolerance = None if bad else adapter.tolerance(case)
    code = QUERY.substitute(
        shapes=_shapes(case), dim=case.dim, embedding=" (2-D: z = 0)" if flat else "",
        tolerance=DEFAULT if tolerance is None else TUNED.format(value=literal(tolerance)),
        centre_a="[A_CENTER[0], A_CENTER[1], 0.0]" if flat else "list(A_CENTER)",
        centre_b="[B_CENTER[0], B_CENTER[1], 0.0]" if flat else "list(B_CENTER)")
    if bad:
        code = undefined(f"coal answers non-finite input wrongly without complaint ({bad})",
                         quantities_of(case.kind_enum), "coal", code)
    return EngineCode(("import math", "import numpy as np", "import coal"), code)
