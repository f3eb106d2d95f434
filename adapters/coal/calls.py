"""coal's calls (the ``coal`` and ``coal-default`` engines), plain data in and out.

Two geometries (a ``Box``, which takes full side lengths: 2 x the half-widths, or a
``Sphere``), their ``Transform3s`` (identity rotation, translation at the centre; a 2-D case
lies in the plane z = 0 and its boxes get the z half-width 2 x the largest half-width, 1 if
all are 0), a ``CollisionRequest`` and a ``DistanceRequest`` (with the GJK and EPA
``tolerance`` if one is given, else coal's defaults), and the ``ComputeCollision`` and
``ComputeDistance`` functors, which keep their solver.  The ask is the collision (verdict)
and the signed distance with its normal (from o1 to o2: A to B); a normal that is not
finite (EPA's failure) is no value.

Nothing is built per case once a process has asked one pair of each geometry (and of each
kind of request: coal's defaults, or a tolerance set): ``release`` puts the pair back in an
idle pool (``IDLE_LIMIT`` at most per key), and the next build of that key takes it and sets
the sizes (``Sphere.radius``, or ``Box.halfSide`` = the sides / 2, as the ``Box`` constructor
stores them), the translations (``setTranslation``; the rotation stays the identity) and the
tolerance.  The functors keep pointers to the pair's geometries, so they stay valid; the
default GJK guess makes each call independent of the one before (equivalence checked on the
whole suite).  A pair is built anew only when none is idle.
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


IDLE_LIMIT = 4
"""Idle pairs kept per key (a process asks one pair at a time)."""
_IDLE: dict[tuple[str, bool], list[dict[str, Any]]] = {}


def _new(geometry: str, sizes: tuple[Any, Any], a_center: Vec, b_center: Vec,
         tolerance: float | None) -> dict[str, Any]:
    make = coal.Box if geometry == "box" else coal.Sphere
    shape_a, shape_b = make(*sizes[0]), make(*sizes[1])
    collision, distance = _requests(tolerance)
    return {"collide": coal.ComputeCollision(shape_a, shape_b),
            "distance": coal.ComputeDistance(shape_a, shape_b),
            "ta": _transform(a_center), "tb": _transform(b_center),
            "collision_request": collision, "distance_request": distance,
            "shapes": (shape_a, shape_b), "dim": len(a_center),
            "key": (geometry, tolerance is None)}


def _reused(built: dict[str, Any], sizes: tuple[Any, Any], a_center: Vec, b_center: Vec,
            tolerance: float | None) -> dict[str, Any]:
    """An idle pair with the case's sizes, centres and tolerance (what a new pair has)."""
    for shape, size in zip(built["shapes"], sizes, strict=True):
        if built["key"][0] == "box":
            shape.halfSide = np.array(size, dtype=np.float64) / 2.0
        else:
            shape.radius = size[0]
    for name, centre in (("ta", a_center), ("tb", b_center)):
        built[name].setTranslation(np.array(to3(centre), dtype=np.float64))
    if tolerance is not None:
        for request in (built["collision_request"], built["distance_request"]):
            request.gjk_tolerance = tolerance
            request.epa_tolerance = tolerance
    built["dim"] = len(a_center)
    return built


def _pair(geometry: str, sizes: tuple[Any, Any], a_center: Vec, b_center: Vec,
          tolerance: float | None) -> dict[str, Any]:
    """The pair: an idle one of the same key reset to the case, else a new one."""
    idle = _IDLE.get((geometry, tolerance is None))
    if idle:
        return _reused(idle.pop(), sizes, a_center, b_center, tolerance)
    return _new(geometry, sizes, a_center, b_center, tolerance)


def boxes(a_center: Vec, a_half: Vec, b_center: Vec, b_half: Vec,
          tolerance: float | None) -> dict[str, Any]:
    """Two boxes (side lengths 2 x the half-widths; a 2-D pair gets a z extent)."""
    extra = (z_half(a_half, b_half),) if len(a_center) == 2 else ()
    sa, sb = ([2.0 * h for h in (*half, *extra)] for half in (a_half, b_half))
    return _pair("box", (sa, sb), a_center, b_center, tolerance)


def spheres(a_center: Vec, a_radius: float, b_center: Vec, b_radius: float,
            tolerance: float | None) -> dict[str, Any]:
    """Two spheres."""
    return _pair("sphere", ([a_radius], [b_radius]), a_center, b_center, tolerance)


def release(built: dict[str, Any]) -> None:
    """The pair back to its key's idle pool (dropped beyond ``IDLE_LIMIT``)."""
    idle = _IDLE.setdefault(built["key"], [])
    if len(idle) < IDLE_LIMIT and all(built is not other for other in idle):
        idle.append(built)


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
