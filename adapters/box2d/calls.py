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

Scene (2-D; a 3-D scene raises): a new world (the scene's gravity, sleeping as the variant
says); per wall a static body at the wall box's anchor with one box fixture (``SetAsBox`` in the
body's frame: the surface at 0 there, exactly; :mod:`adapters.shared.wall_boxes`), restitution
e, the variant's friction and polygon radius (None: Box2D's skin); per disc a dynamic body of
restitution e (Box2D takes the larger: e).  The ask times only ``world.Step(dt,
velocity_iterations, position_iterations)`` (velocity iterations: the scene's if given) and
reads ``position`` / ``linearVelocity`` (float32, widened).  What was measured:
:mod:`adapters.box2d.scene`.

What the pairs, responses and scenes share:
A world has gravity 0 (a scene's gravity if it has one) and sleeping set with
``SetAllowSleeping`` (pybox2d's ``b2World(doSleep=...)`` only sets a Python attribute); a disc
is a dynamic body with one circle fixture of density 0 whose mass is then set exactly through
``massData`` (centre 0; moment ``m r^2 / 2`` when rotation is free, else 0 with
``fixedRotation``).
"""

import math
import time
from collections.abc import Sequence
from functools import partial
from typing import Any

from adapters.shared import end_centres, no_contact
from adapters.shared.scene import check_scene, check_surroundings, scene_answer, step_and_record
from adapters.shared.wall_boxes import slabs


def engine() -> Any:
    """The ``Box2D`` module (pybox2d), imported on first use."""
    import Box2D  # type: ignore[import-untyped]

    return Box2D


def xy(v: Sequence[float]) -> tuple[float, float]:
    """The first two components of ``v`` as floats (a ``b2Vec2`` or a tuple)."""
    return (float(v[0]), float(v[1]))


def new_world(sleep: bool, gravity: Sequence[float] = (0.0, 0.0)) -> Any:
    """A ``b2World`` with ``gravity`` (none by default); sleeping on or off in Box2D itself."""
    world = engine().b2World(gravity=xy(gravity))
    world.SetAllowSleeping(sleep)  # not doSleep=: it only sets a Python attribute
    return world


def disc(world: Any, center: Sequence[float], velocity: Sequence[float], radius: float,
         mass: float, restitution: float, friction: float | None, fixed_rotation: bool,
         bullet: bool) -> Any:
    """A dynamic body at ``center`` with ``velocity`` and ``mass``, with one circle fixture
    (``friction`` None: Box2D's default)."""
    b2 = engine()
    body = world.CreateDynamicBody(position=xy(center), linearVelocity=xy(velocity),
                                   fixedRotation=fixed_rotation, bullet=bullet)
    extra = {} if friction is None else {"friction": friction}
    body.CreateCircleFixture(radius=radius, density=0.0, restitution=restitution, **extra)
    moment = 0.0 if fixed_rotation else 0.5 * mass * radius**2
    body.massData = b2.b2MassData(mass=mass, center=(0.0, 0.0), I=moment)
    return body


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


def _wall(world: Any, slab: Any, restitution: float, polygon_radius: float | None,
          friction: float | None) -> Any:
    anchor, centre, half = slab
    body = world.CreateStaticBody(position=xy(anchor))
    shape = engine().b2PolygonShape()
    shape.SetAsBox(half[0], half[1], xy(centre), 0.0)
    if polygon_radius is not None:
        shape.radius = polygon_radius
    extra = {} if friction is None else {"friction": friction}
    body.CreateFixture(shape=shape, restitution=restitution, **extra)
    return body


def scene(bodies: tuple[Any, ...], dim: int, restitution: float, dt: float,
          iterations: int | None, gravity: tuple[float, ...], walls: tuple[Any, ...],
          steps: int, record_every: int, polygon_radius: float | None, friction: float | None,
          fixed_rotation: bool, sleep: bool, velocity_iterations: int,
          position_iterations: int, bullet: bool) -> dict[str, Any]:
    """A world with the scene's walls and discs (see the module docstring)."""
    if dim != 2:
        raise ValueError(f"box2d is a 2-D engine: no {dim}-D scenes")
    check_scene(bodies, dim, restitution, dt)  # Box2D reads a mass <= 0 as 1
    check_surroundings(gravity, walls, dim)
    w = new_world(sleep, gravity)
    planes = tuple(_wall(w, slab, restitution, polygon_radius, friction)
                   for slab in slabs(bodies, walls))
    discs = tuple(disc(w, center, velocity, radius, mass, restitution, friction,
                       fixed_rotation, bullet) for center, radius, mass, velocity in bodies)
    return {"world": w, "discs": discs, "planes": planes, "dt": dt, "steps": steps,
            "record_every": record_every, "bodies": bodies, "gravity": gravity, "walls": walls,
            "iterations": (velocity_iterations if iterations is None else iterations,
                           position_iterations)}


def step_scene(built: dict[str, Any], clock: Any = time.perf_counter) -> Answer:
    """Step the scene to its end (only ``world.Step`` is timed, by ``clock``): the final
    state, the measures and the trajectory."""
    discs = built["discs"]

    def read() -> tuple[list[Any], list[Any]]:
        return [xy(b.position) for b in discs], [xy(b.linearVelocity) for b in discs]

    step = partial(built["world"].Step, built["dt"], *built["iterations"])
    wall_s, records = step_and_record(step, read, built["steps"], built["record_every"], clock)
    return scene_answer(built["bodies"], built["gravity"], built["walls"], built["dt"],
                        built["steps"], read(), records, wall_s)


def release_scene(built: dict[str, Any]) -> None:
    """Destroy the scene's discs and walls (their fixtures and contacts go with them)."""
    for body in (*built["discs"], *built["planes"]):
        built["world"].DestroyBody(body)
