"""Box2D's calls through pybox2d (the ``box2d``, ``box2d-default`` and ``box2d-bullet`` pairs and
times of impact), plain data in and out.  Box2D is float32: the binding rounds every input.

Detection: two shapes (``b2PolygonShape(box=(hx, hy))``, half-widths, with the variant's
``polygon_radius`` if given, else Box2D's skin; or ``b2CircleShape``) at two transforms
(identity rotation).  The ask collides them into a manifold (``b2CollidePolygons`` or
``b2CollideCircles``): with points, a hit and the world manifold's normal (A to B); without,
``b2Distance`` (``useRadii`` for circles, or as the variant says for boxes) gives the
distance and the unit vector between its witness points.

Response: a world (gravity 0, sleeping as the variant says) with two dynamic discs (their
mass set with ``massData``: moment 0 with ``fixedRotation``, else the disc's), restitution
A = e and B = 0 (Box2D takes the larger).  Each ask deactivates both bodies (dropping the
contact and its impulses), puts back the case's centres and velocities, and steps until the
first step after which A touches something (the centres at its start are ``resolved_at``)
or the bodies no longer approach, or ``max_steps``.

Time of impact: ``b2TimeOfImpact`` on two circle sweeps over Box2D's [0, 1] from the start to
the end centres (toi = t x duration); the normal from ``b2Distance``'s witness points at the
sweeps' transforms at t.  ``e_failed`` and ``e_unknown`` raise.
"""

import math
from collections.abc import Sequence
from typing import Any

from adapters.shared import end_centres, no_contact
from adapters.shared.box2d import disc, engine, new_world, xy

Answer = dict[str, Any]
Vec = tuple[float, ...]


def _transform(center: Vec) -> Any:
    xf = engine().b2Transform()
    xf.position = (center[0], center[1])
    xf.angle = 0.0
    return xf


def _pair(shape_a: Any, shape_b: Any, a_center: Vec, b_center: Vec, circles: bool,
          use_radii: bool) -> dict[str, Any]:
    b2 = engine()
    return {"a": shape_a, "b": shape_b, "xa": _transform(a_center), "xb": _transform(b_center),
            "circles": circles, "use_radii": use_radii, "manifold": b2.b2Manifold(),
            "world_manifold": b2.b2WorldManifold()}


def boxes(a_center: Vec, a_half: Vec, b_center: Vec, b_half: Vec, polygon_radius: float | None,
          use_radii: bool) -> dict[str, Any]:
    """Two boxes (half-widths), with ``polygon_radius`` (None: Box2D's skin)."""
    b2 = engine()
    shapes = []
    for half in (a_half, b_half):
        shape = b2.b2PolygonShape(box=(half[0], half[1]))
        if polygon_radius is not None:
            shape.radius = polygon_radius
        shapes.append(shape)
    return _pair(shapes[0], shapes[1], a_center, b_center, False, use_radii)


def circles(a_center: Vec, a_radius: float, b_center: Vec, b_radius: float) -> dict[str, Any]:
    """Two circles."""
    b2 = engine()
    return _pair(b2.b2CircleShape(radius=a_radius), b2.b2CircleShape(radius=b_radius),
                 a_center, b_center, True, True)


def _direction(pa: Sequence[float], pb: Sequence[float]) -> Vec | None:
    """The unit vector from ``pa`` to ``pb`` (float64), or None when they coincide."""
    dx, dy = pb[0] - pa[0], pb[1] - pa[1]
    length = math.hypot(dx, dy)
    return (dx / length, dy / length) if length > 0 else None


def collide(p: dict[str, Any]) -> Answer:
    """The manifold (hit, its normal), else ``b2Distance`` (distance, normal)."""
    b2 = engine()
    collide_ = b2.b2CollideCircles if p["circles"] else b2.b2CollidePolygons
    collide_(p["manifold"], p["a"], p["xa"], p["b"], p["xb"])
    if p["manifold"].pointCount:
        p["world_manifold"].Initialize(p["manifold"], p["xa"], p["a"].radius, p["xb"],
                                       p["b"].radius)
        n = p["world_manifold"].normal
        return {"hit": True, "normal": (float(n[0]), float(n[1]))}
    out = b2.b2Distance(shapeA=p["a"], shapeB=p["b"], transformA=p["xa"], transformB=p["xb"],
                        useRadii=p["use_radii"] or p["circles"])
    return {"hit": False, "distance": float(out.distance),
            "normal": _direction(out.pointA, out.pointB)}


def world(a_center: Vec, a_radius: float, a_mass: float, a_velocity: Vec, b_center: Vec,
          b_radius: float, b_mass: float, b_velocity: Vec, restitution: float, dt: float,
          velocity_iterations: int, position_iterations: int, friction: float | None,
          fixed_rotation: bool, sleep: bool, bullet: bool, max_steps: int) -> dict[str, Any]:
    """A world with the two discs (A's restitution e, B's 0)."""
    w = new_world(sleep)
    a, b = (disc(w, center, velocity, radius, mass, e, friction, fixed_rotation, bullet)
            for center, velocity, radius, mass, e in (
                (a_center, a_velocity, a_radius, a_mass, restitution),
                (b_center, b_velocity, b_radius, b_mass, 0.0)))
    return {"world": w, "a": a, "b": b, "start": ((a_center, a_velocity), (b_center, b_velocity)),
            "step": (dt, velocity_iterations, position_iterations), "max_steps": max_steps}


def _reset(p: dict[str, Any]) -> None:
    """A and B back at the case's start, with no contact (nor its impulses) left over."""
    p["b"].active = False  # destroys the contact and the broad-phase proxies
    p["a"].active = False
    for body, (center, velocity) in zip((p["a"], p["b"]), p["start"], strict=True):
        body.active = True
        body.transform = (xy(center), 0.0)  # also finds the new contact
        body.linearVelocity = xy(velocity)
        body.angularVelocity = 0.0
        body.awake = True


def respond(p: dict[str, Any]) -> Answer:
    """Step until A touches or the bodies no longer approach: the velocities, and the
    centres at the start of the step that made the contact."""
    _reset(p)
    a, b = p["a"], p["b"]
    resolved = None
    for _ in range(p["max_steps"]):
        start = (xy(a.position), xy(b.position))
        p["world"].Step(*p["step"])
        if any(edge.contact.touching for edge in a.contacts):
            resolved = start
            break
        (pa, pb), (va, vb) = (a.position, b.position), (a.linearVelocity, b.linearVelocity)
        if not bool((vb[0] - va[0]) * (pb[0] - pa[0]) + (vb[1] - va[1]) * (pb[1] - pa[1]) < 0.0):
            break
    return {"v1": xy(a.linearVelocity), "v2": xy(b.linearVelocity), "resolved_at": resolved}


def _sweep(start: Sequence[float], end: Sequence[float]) -> Any:
    sweep = engine().b2Sweep()
    sweep.localCenter = (0.0, 0.0)
    sweep.c0 = (start[0], start[1])
    sweep.c = (end[0], end[1])
    sweep.a0 = 0.0
    sweep.a = 0.0
    sweep.alpha0 = 0.0
    return sweep


def sweeps(a_center: Vec, a_radius: float, a_velocity: Vec, b_center: Vec, b_radius: float,
           b_velocity: Vec, duration: float) -> dict[str, Any]:
    """Two circle shapes and their sweeps over Box2D's [0, 1]."""
    b2 = engine()
    end_a, end_b = end_centres(a_center, a_velocity, b_center, b_velocity, duration)
    return {"a": b2.b2CircleShape(radius=a_radius), "b": b2.b2CircleShape(radius=b_radius),
            "sweep_a": _sweep(a_center, end_a), "sweep_b": _sweep(b_center, end_b),
            "duration": duration}


def time_of_impact(p: dict[str, Any]) -> Answer:
    """``b2TimeOfImpact``, and ``b2Distance`` at its time for the normal."""
    b2 = engine()
    state, t = b2.b2TimeOfImpact(shapeA=p["a"], shapeB=p["b"], sweepA=p["sweep_a"],
                                 sweepB=p["sweep_b"], tMax=1.0)
    out = b2.b2TOIOutput
    if state == out.e_separated:
        return no_contact()
    if state not in (out.e_touching, out.e_overlapped):
        names = {out.e_failed: "e_failed", out.e_unknown: "e_unknown"}
        raise RuntimeError(f"b2TimeOfImpact ended in state {names.get(state, state)} "
                           f"(t = {float(t)!r} of [0, 1]): no time of impact")
    t = float(t)
    near = b2.b2Distance(shapeA=p["a"], shapeB=p["b"], transformA=p["sweep_a"].GetTransform(t),
                         transformB=p["sweep_b"].GetTransform(t), useRadii=False)
    dx, dy = near.pointB[0] - near.pointA[0], near.pointB[1] - near.pointA[1]
    length = math.hypot(dx, dy)
    normal = ((dx / length, dy / length) if length > 0
              else "b2Distance's witness points coincide at the reported time")
    return {"hit": True, "toi": t * p["duration"], "normal": normal}
