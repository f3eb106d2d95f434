"""coal's calls (the ``coal`` and ``coal-default`` engines), plain data in and out.

Two geometries (a ``Box``, which takes full side lengths: 2 x the half-widths, or a
``Sphere``), their ``Transform3s`` (identity rotation, translation at the centre; a 2-D case
lies in the plane z = 0 and its boxes get the z half-width 2 x the largest half-width, 1 if
all are 0), a ``CollisionRequest`` and a ``DistanceRequest`` (with the GJK and EPA
``tolerance`` if one is given, else coal's defaults), and the ``ComputeCollision`` and
``ComputeDistance`` functors, which keep their solver.  The ask is the collision (verdict)
and the signed distance with its normal (from o1 to o2: A to B); a normal that is not
finite (EPA's failure) is no value.
"""

import math
from typing import Any

import coal  # type: ignore[import-untyped]
import numpy as np

from adapters.shared import to3, z_half

Answer = dict[str, Any]
Vec = tuple[float, ...]


def _requests(tolerance: float | None) -> tuple[Any, Any]:
    collision, distance = coal.CollisionRequest(), coal.DistanceRequest()
    if tolerance is not None:
        for request in (collision, distance):
            request.gjk_tolerance = tolerance
            request.epa_tolerance = tolerance
    return collision, distance


def _transform(centre: Vec) -> Any:
    return coal.Transform3s(np.eye(3), np.array(to3(centre), dtype=np.float64))


def _pair(shape_a: Any, shape_b: Any, a_center: Vec, b_center: Vec,
          tolerance: float | None) -> dict[str, Any]:
    collision, distance = _requests(tolerance)
    return {"collide": coal.ComputeCollision(shape_a, shape_b),
            "distance": coal.ComputeDistance(shape_a, shape_b),
            "ta": _transform(a_center), "tb": _transform(b_center),
            "collision_request": collision, "distance_request": distance,
            "shapes": (shape_a, shape_b), "dim": len(a_center)}


def boxes(a_center: Vec, a_half: Vec, b_center: Vec, b_half: Vec,
          tolerance: float | None) -> dict[str, Any]:
    """Two boxes (side lengths 2 x the half-widths; a 2-D pair gets a z extent)."""
    extra = (z_half(a_half, b_half),) if len(a_center) == 2 else ()
    sa, sb = ([2.0 * h for h in (*half, *extra)] for half in (a_half, b_half))
    return _pair(coal.Box(*sa), coal.Box(*sb), a_center, b_center, tolerance)


def spheres(a_center: Vec, a_radius: float, b_center: Vec, b_radius: float,
            tolerance: float | None) -> dict[str, Any]:
    """Two spheres."""
    return _pair(coal.Sphere(a_radius), coal.Sphere(b_radius), a_center, b_center, tolerance)


def collide_and_distance(built: dict[str, Any]) -> Answer:
    """The collision's verdict, the signed distance and its normal (A to B)."""
    hits = coal.CollisionResult()
    built["collide"](built["ta"], built["tb"], built["collision_request"], hits)
    near = coal.DistanceResult()
    distance = float(built["distance"](built["ta"], built["tb"], built["distance_request"],
                                       near))
    values = tuple(float(x) for x in near.normal)
    normal: Vec | str = values[:built["dim"]]
    if not all(math.isfinite(x) for x in values):
        normal = (f"coal gives no finite normal ({', '.join(f'{x:g}' for x in values)}) "
                  f"with distance {distance:.3g}")
    return {"hit": bool(hits.isCollision()), "distance": distance, "normal": normal}
