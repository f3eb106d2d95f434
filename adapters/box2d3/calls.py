"""Box2D v3.1.1's calls through pyb2d3 0.11.1 (the ``box2d3``, ``box2d3-default`` and
``box2d3-bullet`` pairs, responses and scenes), plain data in and out.  Box2D is float32: the
binding rounds every input.

pyb2d3 0.11.1 binds no standalone narrow phase (``b2CollideCircles``, ``b2CollidePolygons``),
nor ``b2ShapeDistance`` or ``b2TimeOfImpact`` (compiled out with ``#if 0`` in its
src/export_collision.cpp), and no ``b2Body_GetContactData``: a contact's manifold reaches
Python only in a begin-touch event (``b2ContactBeginTouchEvent.manifold``, "recorded before the
solver is called").  So detection is a world's step:

Detection: a world (gravity 0) with two dynamic bodies, each with one shape (``b2MakeBox(hx,
hy)``, half-widths, radius 0; or a ``b2Circle``) with contact events on.  Each ask puts both
bodies at the case's centres at rest (``set_transform``, velocities 0), enables them (which
makes their broad-phase proxies and so a new contact), steps the world once
(``b2World_Step``: pairs, then ``b2Collide`` at the positions the step starts from, then the
solver) and reads the begin-touch event of the pair: its manifold's ``normal`` (shape A to
shape B, negated when Box2D ordered the pair the other way) and the least of its points'
``separation`` (negative: overlap).  No event: no contact (Box2D calls a pair touching when
its manifold has points, ``touching = pointCount > 0`` in contact.c, which includes the
speculative points up to ``B2_SPECULATIVE_DISTANCE`` apart).  Both bodies are then disabled
(dropping the contact), so every ask starts alike.

Response: a world (gravity 0, sleeping as the variant says) with two dynamic discs (density
0, the mass set with ``mass_data``: moment 0 with ``fixed_rotation``, else the disc's),
restitution A = e and B = 0 (Box2D takes the larger).  Each ask disables and re-enables both
bodies (dropping the contact and its impulses), puts back the case's centres and velocities,
and steps until the bodies no longer approach, or ``max_steps``: ``resolved_at`` is the centres
at the start of that step if the pair had begun touching (a begin-touch event) and the step
changed a velocity, else None (no contact: passed by or through).

Scene (2-D; a 3-D scene raises): a new world (the scene's gravity, the variant's settings); per
wall a static body at the wall box's anchor with one box (``b2MakeOffsetBox`` in the body's
frame: the surface at 0 there, exactly; :mod:`adapters.shared.wall_boxes`), restitution e,
the variant's friction; per disc a dynamic body of restitution e (the bullet variant makes every
disc a bullet, as ``box2d-bullet`` does in v2: bullets are not swept against bullets, so
between two discs contacts stay sampled).  The ask times only
``world.step(dt, sub_steps)`` and reads ``position`` / ``linear_velocity`` (float32, widened).
"""

import time
from collections.abc import Sequence
from functools import partial
from typing import Any

from adapters.shared.scene import check_scene, check_surroundings, scene_answer, step_and_record
from adapters.shared.wall_boxes import slabs


def engine() -> Any:
    """The ``pyb2d3`` module, imported on first use."""
    import pyb2d3  # type: ignore[import-untyped]

    return pyb2d3


def xy(v: Any) -> tuple[float, float]:
    """The two components of a ``b2Vec2`` or a sequence, as floats."""
    if hasattr(v, "x"):
        return (float(v.x), float(v.y))
    return (float(v[0]), float(v[1]))


def new_world(gravity: Sequence[float], sleep: bool, max_speed: float | None,
              continuous: bool = True) -> Any:
    """A world with ``gravity``, sleeping on or off, the maximum linear speed (None: Box2D's
    default) and continuous collision (Box2D's default: on)."""
    b2 = engine()
    extra = {} if max_speed is None else {"maximum_linear_speed": max_speed}
    world = b2.World(gravity=xy(gravity), **extra)
    world.sleeping_enabled = sleep
    world.continuous_enabled = continuous
    return world


def _shape_def(restitution: float, friction: float | None, density: float) -> Any:
    b2 = engine()
    sd = b2.ShapeDef()  # b2DefaultShapeDef: friction 0.6, restitution 0, density 1
    material = sd.material
    material.restitution = restitution
    if friction is not None:
        material.friction = friction
    sd.material = material
    sd.density = density
    sd.enable_contact_events = True
    return sd


def disc(world: Any, center: Sequence[float], velocity: Sequence[float], radius: float,
         mass: float, restitution: float, friction: float | None, fixed_rotation: bool,
         bullet: bool) -> Any:
    """A dynamic body at ``center`` with ``velocity`` and ``mass``, with one circle of density
    0 (``friction`` None: Box2D's default)."""
    b2 = engine()
    body = world.create_dynamic_body(position=xy(center), linear_velocity=xy(velocity),
                                     fixed_rotation=fixed_rotation, is_bullet=bullet)
    body.create_shape(_shape_def(restitution, friction, 0.0), b2.circle(radius=radius))
    data = b2.MassData()
    data.mass = mass
    data.center = (0.0, 0.0)
    data.rotational_inertia = 0.0 if fixed_rotation else 0.5 * mass * radius**2
    body.mass_data = data
    return body


Answer = dict[str, Any]
Vec = tuple[float, ...]
ZERO_NORMAL = ("Box2D's manifold normal is the zero vector (b2GetLengthAndNormalize leaves "
               "a vector shorter than FLT_EPSILON as zero: the centres coincide in float32)")


def _pair(shapes: tuple[Any, Any], a_center: Vec, b_center: Vec, dt: float,
          sub_steps: int) -> dict[str, Any]:
    world = new_world((0.0, 0.0), False, None)
    bodies, made = [], []
    for shape, center in zip(shapes, (a_center, b_center), strict=True):
        body = world.create_dynamic_body(position=xy(center))
        made.append(body.create_shape(_shape_def(0.0, None, 1.0), shape))
        body.enabled = False
        bodies.append(body)
    return {"world": world, "bodies": tuple(bodies), "shapes": tuple(made),
            "centers": (a_center, b_center), "step": (dt, sub_steps)}


def boxes(a_center: Vec, a_half: Vec, b_center: Vec, b_half: Vec, dt: float,
          sub_steps: int) -> dict[str, Any]:
    """Two boxes (half-widths; ``b2MakeBox``, radius 0) on two dynamic bodies, disabled."""
    b2 = engine()
    return _pair((b2.box(a_half[0], a_half[1]), b2.box(b_half[0], b_half[1])), a_center,
                 b_center, dt, sub_steps)


def circles(a_center: Vec, a_radius: float, b_center: Vec, b_radius: float, dt: float,
            sub_steps: int) -> dict[str, Any]:
    """Two circles on two dynamic bodies, disabled."""
    b2 = engine()
    return _pair((b2.circle(radius=a_radius), b2.circle(radius=b_radius)), a_center,
                 b_center, dt, sub_steps)


def collide(p: dict[str, Any]) -> Answer:
    """One step of the pair at rest: the begin-touch manifold (hit, least separation, normal
    A to B), or no contact."""
    b2 = engine()
    for body, center in zip(p["bodies"], p["centers"], strict=True):
        body.set_transform(xy(center), b2.Rot(0.0))
        body.linear_velocity = (0.0, 0.0)
        body.angular_velocity = 0.0
        body.enabled = True
    p["world"].step(*p["step"])
    found = None
    for event in p["world"].get_contact_events().begin_events():
        manifold = event.manifold
        sign = 1.0 if event.shape_a == p["shapes"][0] else -1.0
        normal = (sign * float(manifold.normal.x), sign * float(manifold.normal.y))
        separation = min(float(point.separation) for point in manifold.points())
        found = {"hit": True, "distance": separation,
                 "normal": normal if normal != (0.0, 0.0) else ZERO_NORMAL}
    for body in p["bodies"]:
        body.enabled = False
    return found or {"hit": False, "distance": None, "normal": None}


def world(a_center: Vec, a_radius: float, a_mass: float, a_velocity: Vec, b_center: Vec,
          b_radius: float, b_mass: float, b_velocity: Vec, restitution: float, dt: float,
          sub_steps: int, friction: float | None, fixed_rotation: bool, sleep: bool,
          bullet: bool, max_speed: float | None, max_steps: int) -> dict[str, Any]:
    """A world with the two discs (A's restitution e, B's 0)."""
    w = new_world((0.0, 0.0), sleep, max_speed)
    a, b = (disc(w, center, velocity, radius, mass, e, friction, fixed_rotation, bullet)
            for center, velocity, radius, mass, e in (
                (a_center, a_velocity, a_radius, a_mass, restitution),
                (b_center, b_velocity, b_radius, b_mass, 0.0)))
    return {"world": w, "a": a, "b": b, "start": ((a_center, a_velocity), (b_center, b_velocity)),
            "step": (dt, sub_steps), "max_steps": max_steps}


def _reset(p: dict[str, Any]) -> None:
    """A and B back at the case's start, with no contact (nor its impulses) left over."""
    b2 = engine()
    p["b"].enabled = False  # destroys the contact and the broad-phase proxies
    p["a"].enabled = False
    for body, (center, velocity) in zip((p["a"], p["b"]), p["start"], strict=True):
        body.set_transform(xy(center), b2.Rot(0.0))
        body.enabled = True
        body.linear_velocity = xy(velocity)
        body.angular_velocity = 0.0
        body.awake = True


def respond(p: dict[str, Any]) -> Answer:
    """Step until the bodies no longer approach (or ``max_steps``): the velocities, and the
    centres at the start of that step if the pair touched and it changed a velocity."""
    _reset(p)
    a, b = p["a"], p["b"]
    resolved, touched = None, False
    for _ in range(p["max_steps"]):
        start = (xy(a.position), xy(b.position))
        before = (xy(a.linear_velocity), xy(b.linear_velocity))
        p["world"].step(*p["step"])
        touched = touched or p["world"].get_contact_events().begin_count > 0
        (pa, pb), (va, vb) = (xy(a.position), xy(b.position)), (xy(a.linear_velocity),
                                                                xy(b.linear_velocity))
        if not bool((vb[0] - va[0]) * (pb[0] - pa[0]) + (vb[1] - va[1]) * (pb[1] - pa[1]) < 0.0):
            resolved = start if touched and (va, vb) != before else None
            break
    return {"v1": xy(a.linear_velocity), "v2": xy(b.linear_velocity), "resolved_at": resolved}


def _wall(world: Any, slab: Any, restitution: float, friction: float | None) -> Any:
    b2 = engine()
    anchor, centre, half = slab
    body = world.create_static_body(position=xy(anchor))
    body.create_shape(_shape_def(restitution, friction, 0.0),
                      b2.box(half[0], half[1], center=xy(centre), rotation=b2.Rot(0.0)))
    return body


def scene(bodies: tuple[Any, ...], dim: int, restitution: float, dt: float,
          iterations: int | None, gravity: tuple[float, ...], walls: tuple[Any, ...],
          steps: int, record_every: int, friction: float | None, fixed_rotation: bool,
          sleep: bool, sub_steps: int, bullet: bool, max_speed: float | None) -> dict[str, Any]:
    """A world with the scene's walls and discs (see the module docstring); a scene's
    ``iterations``, if given, are the sub-steps."""
    if dim != 2:
        raise ValueError(f"box2d3 is a 2-D engine: no {dim}-D scenes")
    check_scene(bodies, dim, restitution, dt)
    check_surroundings(gravity, walls, dim)
    w = new_world(gravity, sleep, max_speed)
    planes = tuple(_wall(w, slab, restitution, friction) for slab in slabs(bodies, walls))
    discs = tuple(disc(w, center, velocity, radius, mass, restitution, friction,
                       fixed_rotation, bullet) for center, radius, mass, velocity in bodies)
    return {"world": w, "discs": discs, "planes": planes, "dt": dt, "steps": steps,
            "record_every": record_every, "bodies": bodies, "gravity": gravity, "walls": walls,
            "sub_steps": sub_steps if iterations is None else max(1, iterations)}


def step_scene(built: dict[str, Any], clock: Any = time.perf_counter) -> Answer:
    """Step the scene to its end (only ``world.step`` is timed, by ``clock``): the final
    state, the measures and the trajectory."""
    discs = built["discs"]

    def read() -> tuple[list[Any], list[Any]]:
        return [xy(b.position) for b in discs], [xy(b.linear_velocity) for b in discs]

    step = partial(built["world"].step, built["dt"], built["sub_steps"])
    wall_s, records = step_and_record(step, read, built["steps"], built["record_every"], clock)
    return scene_answer(built["bodies"], built["gravity"], built["walls"], built["dt"],
                        built["steps"], read(), records, wall_s)


def release_scene(built: dict[str, Any]) -> None:
    """Destroy the scene's world (its bodies, shapes and contacts go with it)."""
    built["world"].destroy()
