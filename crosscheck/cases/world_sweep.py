"""Offset and scale sweeps of scenes with gravity or walls: the same scene moved and resized.

A ``sphere_scene`` block with ``gravity`` or ``walls`` may sweep ``offset`` (added to every
centre coordinate and carried by the walls) and ``scale`` (multiplying every centre, radius,
velocity, wall offset and the gravity: the exact run scales with it, times unchanged).
Masses, restitution, ``dt`` and the duration stay.  A scale that is a power of two keeps
every contact that touches exactly at the origin touching exactly; an offset beyond the
scene's own coordinates rounds them, and the exact reference runs the scene as rounded.

>>> from crosscheck.core.schema import CASE_ADAPTER
>>> block = CASE_ADAPTER.validate_python({"id": "r", "description": "d",
...     "kind": "sphere_scene", "dim": 2, "duration": 1.0, "gravity": [0, -8],
...     "walls": [{"normal": [0, 1]}], "bodies": [{"center": [0, 0.5], "radius": 0.5,
...     "mass": 1, "velocity": [0, 0]}]})
>>> moved = moved_scene(block, offset=1024.0, scale=2.0)
>>> moved.bodies[0].center, moved.bodies[0].radius, moved.walls[0].offset, moved.gravity
((1024.0, 1025.0), 1.0, 1024.0, (0.0, -16.0))
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator

from crosscheck.core.schema import SceneCase, Values, WallSpec
from reference_impl.events import is_axis_normal

WORLD_PARAMETERS = ("scale", "offset")
"""The sweep parameters of a scene with gravity or walls, in the order they apply."""


def moved_scene(case: SceneCase, offset: float = 0.0, scale: float = 1.0) -> SceneCase:
    """``case`` scaled by ``scale`` about the origin, then moved by ``offset`` along every axis."""
    bodies = tuple(b.model_copy(update={
        "center": tuple(c * scale + offset for c in b.center),
        "radius": b.radius * scale,
        "velocity": tuple(v * scale for v in b.velocity)}) for b in case.bodies)
    walls = tuple(WallSpec(normal=w.normal, offset=w.offset * scale + offset * sum(w.normal))
                  for w in case.walls)
    gravity = None if case.gravity is None else tuple(g * scale for g in case.gravity)
    return case.model_copy(update={"bodies": bodies, "walls": walls, "gravity": gravity})


def world_swept(case: SceneCase, values: dict[str, Values],
                values_of: Callable[[Values], list[float]]) -> list[SceneCase]:
    """One case per ``scale`` x ``offset`` of the sweep (ids ``<id>.scale=..,offset=..``);
    ``values_of`` reads a list, logspace or linspace."""
    axes = [(name, values_of(values[name])) for name in WORLD_PARAMETERS if name in values]
    out = []
    for point in itertools.product(*(vals for _, vals in axes)):
        params = dict(zip((name for name, _ in axes), point, strict=True))
        labels = ",".join(f"{name}={value:.6g}" for name, value in params.items())
        moved = moved_scene(case, params.get("offset", 0.0), params.get("scale", 1.0))
        out.append(moved.model_copy(update={
            "id": f"{case.id}.{labels}", "description": f"{case.description} [{labels}]",
            "tags": (*case.tags, "metamorphic"), "sweep": None,
            "coords": {**case.coords, **params}}))
    return out


def world_problems(case: SceneCase) -> Iterator[tuple[str, str]]:
    """The field and reason of each problem with a scene's gravity and walls, before any work
    (lengths and finite components are the loader's general rules): a normal that is not a
    unit axis vector, a non-finite wall offset, a body
    starting inside a wall, a sweep over anything but scale and offset.  (A restitution
    outside [0, 1], the exact reference's range, is refused for every scene by the loader.)"""
    for k, wall in enumerate(case.walls):
        if len(wall.normal) != case.dim:
            continue  # the loader's length rule names it
        if not is_axis_normal(wall.normal, case.dim):
            yield f"walls[{k}].normal", (f"must be a unit axis vector of {case.dim} components "
                                         f"(one +1 or -1, the rest 0), got {list(wall.normal)}")
            continue
        if not math.isfinite(wall.offset):
            yield f"walls[{k}].offset", f"must be finite, got {wall.offset}"
            continue
        for i, body in enumerate(case.bodies):
            if len(body.center) == case.dim and math.fsum(
                    n * x for n, x in zip(wall.normal, body.center, strict=True)) \
                    - wall.offset < body.radius:
                yield f"bodies[{i}]", f"starts inside wall {k} (its gap is below 0)"
    if case.sweep is not None and (case.walls or any(case.gravity or ())):
        # as expand.py rules for world sweeps: fast_scene times and places the first impact
        # in open space (a ground or a wall may come first)
        swept = [n for n, v in case.sweep if v is not None and n not in WORLD_PARAMETERS]
        if swept:
            yield f"sweep.{swept[0]}", ("a scene with gravity or walls is swept over scale "
                                        "and offset only")
