"""FCL's calls through python-fcl (the ``fcl`` engine and its CCD variants), plain data in and
out.

Detection: two ``CollisionObject`` s (a ``Box``, which takes full side lengths: 2 x the
half-widths, or a ``Sphere``) at the centres, identity rotation; a 2-D case lies in the
plane z = 0 and its boxes get the z half-width 2 x the largest half-width (1 if all are 0),
so z is never the axis of least overlap nor a gap; normals come back without z.  The ask
is ``collide`` (verdict; in collision the contact's normal, A to B) and the signed
``distance`` (without a collision and with a distance > 0, the normal is the unit vector
from A's nearest point to B's; else none).  ``collide_only`` leaves the distance out (it
hangs on coincident sphere centres).

Nothing is built per case once a process has asked one pair of each geometry: ``release``
puts the pair (two geometries, their objects, the requests) back in an idle pool per
geometry (``IDLE_LIMIT`` at most), and the next build of that geometry takes it and
sets the sizes (``Sphere.radius``, ``Box.side``; then ``computeLocalAABB``, as FCL's
``CollisionObject`` constructor does) and the translations (``setTranslation``, which
recomputes the world AABB; the rotation stays the identity): the same state a new pair has
(equivalence checked on the whole suite).  A pair is built anew only when none is idle.

Time of impact: ``continuousCollide`` of the two spheres from their start to their end
centres (``center + velocity x duration``) with the solver asked; FCL's time is normalised
to [0, 1] (toi = time_of_contact x duration) and the binding gives no contact normal, so
the normal is the unit vector between the centres at that time.  A fresh result object
per ask: python-fcl keeps the minimum time already in one.
"""

import math
from typing import Any

import fcl
import numpy as np

from adapters.shared import centre_normal, end_centres, no_contact, to3, z_half

Answer = dict[str, Any]
Vec = tuple[float, ...]


IDLE_LIMIT = 4
"""Idle pairs kept per geometry (a process asks one pair at a time)."""
_IDLE: dict[str, list[dict[str, Any]]] = {"box": [], "sphere": []}


def _new(geometry: str, sizes: tuple[Any, Any], a_center: Vec, b_center: Vec) -> dict[str, Any]:
    make = fcl.Box if geometry == "box" else fcl.Sphere
    ga, gb = make(*sizes[0]), make(*sizes[1])
    return {"geometry": geometry, "shapes": (ga, gb),
            "a": fcl.CollisionObject(ga, fcl.Transform(list(to3(a_center)))),
            "b": fcl.CollisionObject(gb, fcl.Transform(list(to3(b_center)))),
            "collision": fcl.CollisionRequest(num_max_contacts=1, enable_contact=True),
            "distance": fcl.DistanceRequest(enable_nearest_points=True,
                                            enable_signed_distance=True),
            "dim": len(a_center)}


def _reused(built: dict[str, Any], sizes: tuple[Any, Any], a_center: Vec,
            b_center: Vec) -> dict[str, Any]:
    """An idle pair with the case's sizes and centres (what a new pair's constructors set)."""
    for shape, size, obj, centre in zip(built["shapes"], sizes, (built["a"], built["b"]),
                                        (a_center, b_center), strict=True):
        if built["geometry"] == "box":
            shape.side = size
        else:
            shape.radius = size[0]
        shape.computeLocalAABB()
        obj.setTranslation(np.array(to3(centre), dtype=np.float64))
    built["dim"] = len(a_center)
    return built


def _objects(geometry: str, sizes: tuple[Any, Any], a_center: Vec,
             b_center: Vec) -> dict[str, Any]:
    """The pair: an idle one of ``geometry`` reset to the case, else a new one."""
    idle = _IDLE[geometry]
    if idle:
        return _reused(idle.pop(), sizes, a_center, b_center)
    return _new(geometry, sizes, a_center, b_center)


def boxes(a_center: Vec, a_half: Vec, b_center: Vec, b_half: Vec) -> dict[str, Any]:
    """Two boxes (side lengths 2 x the half-widths; a 2-D pair gets a z extent)."""
    extra = (z_half(a_half, b_half),) if len(a_center) == 2 else ()
    sa, sb = ([2.0 * h for h in (*half, *extra)] for half in (a_half, b_half))
    return _objects("box", (sa, sb), a_center, b_center)


def spheres(a_center: Vec, a_radius: float, b_center: Vec, b_radius: float) -> dict[str, Any]:
    """Two spheres."""
    return _objects("sphere", ([a_radius], [b_radius]), a_center, b_center)


def release(built: dict[str, Any]) -> None:
    """The pair back to its geometry's idle pool (dropped beyond ``IDLE_LIMIT``)."""
    idle = _IDLE[built["geometry"]]
    if len(idle) < IDLE_LIMIT and all(built is not other for other in idle):
        idle.append(built)


def _unit(v: list[float]) -> Vec | None:
    length = math.sqrt(math.fsum(x * x for x in v))
    return tuple(float(x) / length for x in v) if length > 0 else None


def _normal(hits: Any, near: Any, distance: float) -> Vec | None:
    """The contact's normal in collision, else the direction between the nearest points
    (none without a collision and a distance <= 0, or without nearest points)."""
    if hits.is_collision:
        return tuple(float(x) for x in hits.contacts[0].normal)
    if near is None:
        return None
    pa, pb = near.nearest_points
    if distance > 0 and pa is not None and pb is not None:
        return _unit([y - x for x, y in zip(pa, pb, strict=True)])
    return None


def _answer(built: dict[str, Any], with_distance: bool) -> Answer:
    hits = fcl.CollisionResult()
    fcl.collide(built["a"], built["b"], built["collision"], hits)
    distance = None
    if with_distance:
        near = fcl.DistanceResult()
        distance = float(fcl.distance(built["a"], built["b"], built["distance"], near))
        normal = _normal(hits, near, distance)
    else:
        normal = _normal(hits, None, math.nan)
    if normal is not None and built["dim"] == 2:
        normal = normal[:2]
    return {"hit": bool(hits.is_collision), "distance": distance, "normal": normal}


def collide_and_distance(built: dict[str, Any]) -> Answer:
    """``collide``, then the signed ``distance``."""
    return _answer(built, True)


def collide_only(built: dict[str, Any]) -> Answer:
    """``collide`` alone: the verdict, and the contact's normal if they collide."""
    return _answer(built, False)


def sweep(a_center: Vec, a_radius: float, a_velocity: Vec, b_center: Vec, b_radius: float,
          b_velocity: Vec, duration: float, solver: str) -> dict[str, Any]:
    """Two spheres at their start, their end transforms and the request with ``solver`` (a
    ``CCDSolverType`` member's name)."""
    end_a, end_b = end_centres(a_center, a_velocity, b_center, b_velocity, duration)
    request = fcl.ContinuousCollisionRequest(ccd_solver_type=getattr(fcl.CCDSolverType, solver))
    return {"a": fcl.CollisionObject(fcl.Sphere(a_radius), fcl.Transform(list(to3(a_center)))),
            "b": fcl.CollisionObject(fcl.Sphere(b_radius), fcl.Transform(list(to3(b_center)))),
            "end_a": fcl.Transform(list(to3(end_a))), "end_b": fcl.Transform(list(to3(end_b))),
            "request": request, "solver": solver, "duration": duration,
            "motion": (a_center, a_velocity, b_center, b_velocity)}


def continuous(built: dict[str, Any]) -> Answer:
    """The one ``continuousCollide`` call."""
    result = fcl.ContinuousCollisionResult()
    returned = fcl.continuousCollide(built["a"], built["end_a"], built["b"], built["end_b"],
                                     built["request"], result)
    if returned == -1.0:
        why = (f"fcl.continuousCollide returned -1 with {built['solver']}: FCL 0.7.0 does not "
               "compute it for two sphere geometries (ray shooting: not implemented; "
               "polynomial solver: BVH meshes only), and leaves the result at is_collide False")
        return {"hit": why, "toi": why, "normal": why}
    if not result.is_collide:
        return no_contact()
    toi = float(result.time_of_contact) * built["duration"]
    a_center, a_velocity, b_center, b_velocity = built["motion"]
    return {"hit": True, "toi": toi,
            "normal": centre_normal(a_center, a_velocity, b_center, b_velocity, toi)}
