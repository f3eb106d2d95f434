"""pymunk's calls (the ``pymunk`` and ``pymunk-default`` engines), plain data in and out.

Detection: two static bodies at the centres, each with a box (``Poly.create_box`` takes full
width and height: 2 x the half-widths) or a circle; shapes outside a Space keep stale
positions until ``cache_bb()``.  One ``shapes_collide``: pymunk signals "no contact" with an
assert (pymunk 7; pymunk 6 returns a ContactPointSet with no points), so run it without
``python -O``.  pymunk gives no separation distance.

Response: two dynamic discs in a Space (gravity 0, damping 1.0: none), moment ``moment`` (an
infinite one: no rotation), elasticities A = e and B = 1.0 (pymunk multiplies them).  Each
ask removes and re-adds the shapes (no cached arbiter), zeroes the bias velocity the last
solve left (``Body.update_position(body, 0)``), puts back the case's centres and velocities,
and steps until the first step whose contact reached ``pre_solve`` (its centres are
``resolved_at``), or until the bodies no longer approach, or ``max_steps``.

Scenes (``sphere_scene``, 2-D): a new Space with the scene's gravity and damping 1.0, the
iterations if given; per disc a dynamic ``Body(m, moment_for_circle(m, 0, r))`` with a Circle;
per wall a ``Poly`` box (radius 0) on ``space.static_body`` with its world corners
(:mod:`adapters.shared.wall_boxes`: the surface at the wall's offset exactly).  Every shape
gets elasticity sqrt(e) (pymunk multiplies them: every pair bounces with e); ``slop``,
``bias`` and ``friction`` are the variant's (None: pymunk's default).  The ask times only
``space.step(dt)`` and reads ``Body.position`` / ``Body.velocity`` (every ``record_every``
steps too, untimed).  Measured conventions (resting, sinking, apexes): the adapter's
docstring and tests/adapters/test_pymunk_walls.py.
"""

import math
import time
from functools import partial
from typing import Any

import pymunk

from adapters.shared.scene import check_scene, check_surroundings, scene_answer, step_and_record
from adapters.shared.wall_boxes import corners, slabs

Answer = dict[str, Any]
Vec = tuple[float, ...]


def _static(center: Vec) -> Any:
    body = pymunk.Body(body_type=pymunk.Body.STATIC)
    body.position = (center[0], center[1])
    return body


def boxes(a_center: Vec, a_half: Vec, b_center: Vec, b_half: Vec) -> tuple[Any, Any]:
    """Two static boxes, bounding boxes cached."""
    shapes = []
    for center, half in ((a_center, a_half), (b_center, b_half)):
        shape = pymunk.Poly.create_box(_static(center), (2.0 * half[0], 2.0 * half[1]))
        shape.cache_bb()
        shapes.append(shape)
    return shapes[0], shapes[1]


def discs(a_center: Vec, a_radius: float, b_center: Vec, b_radius: float) -> tuple[Any, Any]:
    """Two static circles, bounding boxes cached."""
    shapes = []
    for center, radius in ((a_center, a_radius), (b_center, b_radius)):
        shape = pymunk.Circle(_static(center), radius)
        shape.cache_bb()
        shapes.append(shape)
    return shapes[0], shapes[1]


def _vec(v: Any) -> Vec:
    return (float(v.x), float(v.y))


def collide(shapes: tuple[Any, Any]) -> Answer:
    """``shapes_collide``: the smallest contact distance and the normal (first shape to second)."""
    a, b = shapes
    try:  # no contact: pymunk 7 asserts, pymunk 6 returns a ContactPointSet with no points
        points = a.shapes_collide(b)
        distance = min(float(p.distance) for p in points.points)
    except (AssertionError, ValueError):  # ValueError: min() of no points
        return {"hit": False}
    return {"hit": True, "distance": distance, "normal": _vec(points.normal)}


def world(a_center: Vec, a_radius: float, a_mass: float, a_velocity: Vec, b_center: Vec,
          b_radius: float, b_mass: float, b_velocity: Vec, restitution: float, dt: float,
          slop: float | None, bias: float | None, iterations: int | None,
          friction: float | None, moment: float, max_steps: int) -> dict[str, Any]:
    """A Space with the two discs and a ``pre_solve`` that records where the contact is first
    handled; None settings stay at pymunk's defaults."""
    bodies, shapes = [], []
    for mass, radius, elasticity in ((a_mass, a_radius, restitution), (b_mass, b_radius, 1.0)):
        body = pymunk.Body(mass, moment)
        shape = pymunk.Circle(body, radius)
        shape.elasticity = elasticity
        if friction is not None:
            shape.friction = friction
        bodies.append(body)
        shapes.append(shape)
    space: Any = pymunk.Space()
    space.gravity = (0.0, 0.0)
    space.damping = 1.0
    for name, value in (("collision_slop", slop), ("collision_bias", bias),
                        ("iterations", iterations)):
        if value is not None:
            setattr(space, name, value)
    space.add(*bodies, *shapes)
    built: dict[str, Any] = {
        "space": space, "bodies": bodies, "shapes": shapes, "contact": [], "dt": dt,
        "start": ((a_center, a_velocity), (b_center, b_velocity)), "max_steps": max_steps}
    contact: list[tuple[Vec, Vec]] = built["contact"]

    def pre_solve(arbiter: Any, space: Any, data: Any) -> bool:
        if not contact:
            contact.append((_vec(bodies[0].position), _vec(bodies[1].position)))
        return True  # pymunk 6 reads it (keep the contact); pymunk 7 ignores it

    if hasattr(space, "on_collision"):  # pymunk >= 7; else pymunk 6
        space.on_collision(pre_solve=pre_solve)
    else:
        space.add_default_collision_handler().pre_solve = pre_solve
    return built


def _reset(built: dict[str, Any]) -> None:
    """A and B back at the case's start, with no state left from an earlier ask."""
    space = built["space"]
    space.remove(*built["shapes"])  # drops the cached arbiter (contact persistence, warm start)
    for body, (center, velocity) in zip(built["bodies"], built["start"], strict=True):
        pymunk.Body.update_position(body, 0.0)  # zeroes the bias velocity of the last solve
        body.angle = 0.0
        body.angular_velocity = 0.0
        body.position = (center[0], center[1])
        body.velocity = (velocity[0], velocity[1])
    space.add(*built["shapes"])
    built["contact"].clear()


def respond(built: dict[str, Any]) -> Answer:
    """Step until the contact is handled or the bodies no longer approach: their velocities,
    and the centres where the solver first handled the contact (None: it never did)."""
    _reset(built)
    a, b = built["bodies"]
    contact = built["contact"]
    for _ in range(built["max_steps"]):
        built["space"].step(built["dt"])
        if contact or not bool((b.velocity - a.velocity).dot(b.position - a.position) < 0.0):
            break
    return {"v1": _vec(a.velocity), "v2": _vec(b.velocity),
            "resolved_at": contact[0] if contact else None}


def release_world(built: dict[str, Any]) -> None:
    """Empty the Space."""
    built["space"].remove(*built["bodies"], *built["shapes"])


def scene(bodies: tuple[Any, ...], dim: int, restitution: float, dt: float,
          iterations: int | None, slop: float | None, bias: float | None,
          friction: float | None, gravity: Vec, walls: tuple[Any, ...], steps: int,
          record_every: int) -> dict[str, Any]:
    """A Space with the scene's discs and walls (a 3-D scene raises: pymunk is 2-D)."""
    if dim != 2:
        raise ValueError(f"pymunk is a 2-D engine: no {dim}-D scenes")
    check_scene(bodies, dim, restitution, dt)  # before pymunk.Body: mass <= 0 aborts
    check_surroundings(gravity, walls, dim)
    space: Any = pymunk.Space()
    space.gravity = (gravity[0], gravity[1])
    space.damping = 1.0
    for name, value in (("iterations", iterations), ("collision_slop", slop),
                        ("collision_bias", bias)):
        if value is not None:
            setattr(space, name, value)
    elasticity = math.sqrt(restitution)  # the product of two shapes' is e
    discs: list[Any] = []
    shapes: list[Any] = []
    for center, radius, mass, velocity in bodies:
        disc = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0.0, radius))
        disc.position = (center[0], center[1])
        disc.velocity = (velocity[0], velocity[1])
        discs.append(disc)
        shapes.append(pymunk.Circle(disc, radius))
    for slab in slabs(bodies, walls):
        (x0, y0), (x1, y1) = corners(slab)
        shapes.append(pymunk.Poly(space.static_body, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)],
                                  radius=0.0))
    for shape in shapes:
        shape.elasticity = elasticity
        if friction is not None:
            shape.friction = friction
    space.add(*discs, *shapes)
    return {"space": space, "discs": discs, "shapes": shapes, "dt": dt, "steps": steps,
            "record_every": record_every, "bodies": bodies, "gravity": gravity, "walls": walls}


def step_scene(built: dict[str, Any], clock: Any = time.perf_counter) -> Answer:
    """Step the scene to its end: the final state, the measures and the trajectory (only the
    stepping is timed, by ``clock``)."""
    discs = built["discs"]

    def read() -> tuple[list[Vec], list[Vec]]:
        return [_vec(d.position) for d in discs], [_vec(d.velocity) for d in discs]

    wall_s, records = step_and_record(partial(built["space"].step, built["dt"]), read,
                                      built["steps"], built["record_every"], clock)
    return scene_answer(built["bodies"], built["gravity"], built["walls"], built["dt"],
                        built["steps"], read(), records, wall_s)


def release_scene(built: dict[str, Any]) -> None:
    """Empty the Space."""
    built["space"].remove(*built["discs"], *built["shapes"])
