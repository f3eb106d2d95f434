"""Sweep expansion and A/B swapping: one case block becomes the cases that run.

A block with ``sweep`` becomes one case per combination of its parameters,
with stable ids ``<id>.<param>=<value>[,<param>=<value>]``; a scene block one
per time step (and solver iteration count).  Every case (unless ``swap =
false``) also runs with A and B exchanged, as ``<id>.swapped``; its answers
must mirror the original's.  The ids are for people: the coordinates and the
link are fields of the case (``origin``, ``coords``, ``twin_of``), copied to
every record, and nothing parses them back out of an id.

>>> from crosscheck.core.schema import CASE_ADAPTER
>>> case = CASE_ADAPTER.validate_python({"id": "g", "description": "d", "kind": "sphere",
...     "dim": 2, "a": {"center": [0, 0], "radius": 0.5}, "b": {"center": [1, 0], "radius": 0.5},
...     "sweep": {"gap": [0.5, -0.25]}})
>>> [(c.id, c.b.center) for c in expand(case)]
[('g.gap=0.5', (1.5, 0.0)), ('g.gap=-0.25', (0.75, 0.0))]
>>> point = expand(case)[1]
>>> point.origin, point.coords
('g', {'gap': -0.25})
>>> twin = swapped(point)
>>> twin.id, twin.a.center, twin.twin_of, twin.coords
('g.gap=-0.25.swapped', (0.75, 0.0), 'g.gap=-0.25', {'gap': -0.25})

A 3-D block with ``twin_2d`` (a coordinate plane) also stands for its 2-D twin,
the block ``<id>.2d``: the same bodies in that plane, the third axis dropped,
expanded over the same sweep.  The 3-D cases keep their ids and inputs; each
2-D case names the 3-D case it flattens (``from_3d``), and the loader checks
that the exact answer is the same (:func:`crosscheck.cases.load.twin_problems`).

>>> block = CASE_ADAPTER.validate_python({"id": "t", "description": "d", "kind": "sphere",
...     "dim": 3, "a": {"center": [0, 0, 5], "radius": 0.5},
...     "b": {"center": [0, 1, 5], "radius": 0.5}, "twin_2d": "yz", "sweep": {"gap": [0.5]}})
>>> [(c.id, c.b.center, c.from_3d) for c in expand(block)]
[('t.gap=0.5', (0.0, 1.5, 5.0), ''), ('t.2d.gap=0.5', (1.5, 5.0), 't.gap=0.5')]
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

from crosscheck.cases.world_sweep import WORLD_PARAMETERS, world_swept
from crosscheck.core.schema import (
    DEFAULT_DT,
    TWIN_SUFFIX,
    AabbCase,
    AnyCase,
    LinSpace,
    LogSpace,
    Plane,
    ResponseCase,
    SceneCase,
    ToiCase,
    TwoBodyCase,
    Values,
)
from crosscheck.truth.scene_measures import surrounded
from crosscheck.truth.scenes import step_travel
from reference_impl.toi import time_of_impact

PARAMETERS = ("scale", "gap", "overlap", "offset", "mass_ratio", "speed")
MOVING_ONLY = {"mass_ratio": ("sphere_response",), "speed": ("sphere_response", "sphere_toi")}
"""Sweep parameters that apply to some kinds only, and the kinds they apply to."""
SCENE_PARAMETERS = ("step_travel", "phase")
"""The sweep parameters of two-body scenes (see :func:`fast_scene`)."""
PLANES: dict[Plane, int] = {"xy": 2, "xz": 1, "yz": 0}
"""The axis (0 x, 1 y, 2 z) each plane of ``twin_2d`` drops."""
AXIS_NAMES = "xyz"
TWIN_TAG = "2d-twin"


class SweepError(ValueError):
    """A sweep that cannot be expanded; ``field`` names the offending parameter."""

    def __init__(self, field: str, reason: str) -> None:
        super().__init__(reason)
        self.field = field


class TwinError(SweepError):
    """A block whose 2-D twin (``twin_2d``) cannot be made; ``field`` is ``twin_2d``."""

    def __init__(self, reason: str) -> None:
        super().__init__("twin_2d", reason)


def values_of(spec: Values) -> list[float]:
    """The numbers a sweep parameter takes."""
    if isinstance(spec, LogSpace):
        lo, hi, n = spec.logspace
        return [float(x) for x in np.logspace(lo, hi, n)]
    if isinstance(spec, LinSpace):
        lo, hi, n = spec.linspace
        return [float(x) for x in np.linspace(lo, hi, n)]
    return [float(x) for x in spec]


def expand_steps(case: SceneCase) -> Iterator[SceneCase]:
    """One case per ``dt`` x ``iterations`` of the block's ``steps`` (the block itself if none)."""
    if case.steps is None:
        yield case
        return
    iterations: Sequence[int | None] = case.steps.iterations or [None]
    for dt, k in itertools.product(values_of(case.steps.dt), iterations):
        label = f"dt={dt:.6g}" + (f",iterations={k}" if k is not None else "")
        coords = {"dt": dt} | ({"iterations": float(k)} if k is not None else {})
        yield case.model_copy(update={
            "id": f"{case.id}.{label}", "description": f"{case.description} [{label}]",
            "tags": (*case.tags, "dynamics"), "steps": None, "dt": dt, "iterations": k,
            "origin": case.id, "coords": coords})


def _scene_swept(case: SceneCase) -> list[SceneCase]:
    """A scene case at one ``dt``: itself, or one fast-body case per ``step_travel`` x
    ``phase`` of its sweep (:func:`fast_scene`)."""
    if case.sweep is None:
        return [case]
    world = {n: getattr(case.sweep, n) for n in WORLD_PARAMETERS
             if getattr(case.sweep, n) is not None}
    if world and surrounded(case):
        rest = [n for n in (*PARAMETERS, "step_travel", "phase", "direction")
                if n not in world and getattr(case.sweep, n, None) is not None]
        if rest:
            raise SweepError(f"sweep.{rest[0]}", "a scene with gravity or walls is swept over "
                                                 "scale and offset only")
        return world_swept(case, world, values_of)
    others = [name for name in PARAMETERS if getattr(case.sweep, name) is not None]
    if others or case.sweep.direction is not None:
        field = others[0] if others else "direction"
        raise SweepError(f"sweep.{field}", "scenes are swept over `steps` (dt, iterations) "
                                           "and step_travel or phase, not " + field)
    travels = values_of(case.sweep.step_travel) if case.sweep.step_travel else [None]
    phases = values_of(case.sweep.phase) if case.sweep.phase else [None]
    out = []
    for travel, phase in itertools.product(travels, phases):
        params = {k: v for k, v in (("step_travel", travel), ("phase", phase)) if v is not None}
        labels = ",".join(_label(name, value) for name, value in params.items())
        point = fast_scene(case, travel, 0.5 if phase is None else phase)
        out.append(point.model_copy(update={
            "id": f"{case.id}.{labels}", "description": f"{case.description} [{labels}]",
            "tags": (*case.tags, "fast-body"), "sweep": None,
            "coords": {**case.coords, **params}}))
    return out


def fast_scene(case: SceneCase, travel: float | None, phase: float) -> SceneCase:
    """The two-body scene ``case`` at one ``dt``, made fast: velocities scaled to the per-step
    ``travel`` (:func:`step_travel`; None keeps them), bodies moved back along them so that
    they first touch at ``(approach_steps + phase) dt``, run for twice that time.

    The contact configuration (where the declared bodies first touch) is kept, so every
    point of a sweep collides at the same place and angle; ``phase`` (strictly between 0
    and 1) keeps the impact off the step grid.

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> block = CASE_ADAPTER.validate_python({"id": "f", "description": "d",
    ...     "kind": "sphere_scene", "dim": 2, "dt": 0.01, "bodies": [
    ...     {"center": [-1, 0], "radius": 0.05, "mass": 1, "velocity": [1, 0]},
    ...     {"center": [1, 0], "radius": 0.05, "mass": 1, "velocity": [-1, 0]}]})
    >>> fast = fast_scene(block, 2.0, 0.5)
    >>> fast.bodies[0].velocity, round(step_travel(fast), 12), fast.step_count
    ((20.0, 0.0), 2.0, 9)
    """
    if len(case.bodies) != 2:
        raise SweepError("sweep.step_travel", f"step_travel and phase sweep two-body scenes; "
                                              f"this one has {len(case.bodies)} bodies")
    if not 0.0 < phase < 1.0:
        raise SweepError("sweep.phase", f"phase must be strictly between 0 and 1 (an impact "
                                        f"off the step grid), got {phase!r}")
    a, b = case.bodies
    meet = time_of_impact(a.center, a.velocity, a.radius, b.center, b.velocity, b.radius,
                          1e300)
    if not meet.hit or meet.toi is None or meet.toi == 0.0:
        raise SweepError("bodies", "step_travel and phase need two bodies apart at the start "
                                   "and on a collision course")
    dt = case.dt or DEFAULT_DT
    scale = 1.0 if travel is None else travel / step_travel(case)
    if not (math.isfinite(scale) and scale > 0):
        raise SweepError("sweep.step_travel", f"step_travel must be > 0, got {travel!r}")
    hit_at = (case.approach_steps + phase) * dt
    bodies = []
    for body in case.bodies:
        velocity = tuple(v * scale for v in body.velocity)
        contact = tuple(c + v * meet.toi for c, v in zip(body.center, body.velocity,
                                                         strict=True))
        centre = tuple(p - v * hit_at for p, v in zip(contact, velocity, strict=True))
        bodies.append(body.model_copy(update={"center": centre, "velocity": velocity}))
    return case.model_copy(update={"bodies": tuple(bodies), "duration": 2.0 * hit_at})


def _label(name: str, value: float) -> str:
    return f"{name}={value:.6g}"


def expand(case: AnyCase) -> list[AnyCase]:
    """The cases a block stands for: itself, or one per sweep combination; then as many
    2-D twins if it has ``twin_2d`` (each naming its 3-D case in ``from_3d``)."""
    if isinstance(case, SceneCase):
        if case.twin_2d is not None:
            raise TwinError("scenes have no 2-D twin: write the 2-D scene as a block of its own")
        return [point for stepped in expand_steps(case) for point in _scene_swept(stepped)]
    points = _swept(case)
    if case.twin_2d is None:
        return list(points)
    twins = _swept(flattened(case, case.twin_2d))
    return [*points, *(twin.model_copy(update={"from_3d": point.id})
                       for point, twin in zip(points, twins, strict=True))]


def _swept(case: TwoBodyCase) -> list[TwoBodyCase]:
    """The block itself, or one case per combination of its sweep parameters."""
    if case.sweep is None:
        return [case]
    for name in SCENE_PARAMETERS:
        if getattr(case.sweep, name) is not None:
            raise SweepError(f"sweep.{name}", f"{name} applies to sphere_scene cases only")
    grid = [(name, values_of(spec)) for name in PARAMETERS
            if (spec := getattr(case.sweep, name)) is not None]
    if not grid:
        raise SweepError("sweep", "a sweep needs at least one parameter")
    for name, _ in grid:
        kinds = MOVING_ONLY.get(name)
        if kinds is not None and case.kind not in kinds:
            raise SweepError(f"sweep.{name}",
                             f"{name} applies to {' and '.join(kinds)} cases only")
    return [_point(case, dict(zip([n for n, _ in grid], combo, strict=True)))
            for combo in itertools.product(*(values for _, values in grid))]


def _point(case: TwoBodyCase, params: dict[str, float]) -> TwoBodyCase:
    out = case
    for name in PARAMETERS:
        if name in params:
            out = _APPLY[name](out, params[name])
    labels = ",".join(_label(name, value) for name, value in params.items())
    shown = ", ".join(f"{name} = {value:.6g}" for name, value in params.items())
    return out.model_copy(update={
        "id": f"{case.id}.{labels}", "description": f"{case.description} [{shown}]",
        "tags": (*case.tags, "sweep"), "sweep": None, "origin": case.id, "coords": params})


def _bodies(case: TwoBodyCase, **changes: dict[str, Any]) -> TwoBodyCase:
    a = case.a.model_copy(update=changes.get("a", {}))
    b = case.b.model_copy(update=changes.get("b", {}))
    return case.model_copy(update={"a": a, "b": b})


def _scale(case: TwoBodyCase, s: float) -> TwoBodyCase:
    """Every centre and size times ``s``; for a time of impact the velocities too, so that
    the time of impact does not change."""
    def sized(body: Any) -> dict[str, Any]:
        size = ({"half": tuple(h * s for h in body.half)} if isinstance(case, AabbCase)
                else {"radius": body.radius * s})
        moving = ({"velocity": tuple(v * s for v in body.velocity)}
                  if isinstance(case, ToiCase) else {})
        return {"center": tuple(c * s for c in body.center), **size, **moving}
    return _bodies(case, a=sized(case.a), b=sized(case.b))


def _unit(case: TwoBodyCase) -> tuple[float, ...]:
    d = case.sweep.direction if case.sweep and case.sweep.direction else tuple(
        y - x for x, y in zip(case.a.center, case.b.center, strict=True))
    if len(d) != case.dim:
        raise SweepError("sweep.direction", f"expected {case.dim} components, got {len(d)}")
    length = math.sqrt(math.fsum(x * x for x in d))
    if not length > 0:
        raise SweepError("sweep.direction", "gap needs a direction: the centres coincide")
    return tuple(x / length for x in d)


def _touch_distance(case: TwoBodyCase, u: tuple[float, ...]) -> float:
    if not isinstance(case, AabbCase):
        return case.a.radius + case.b.radius
    axes = [i for i, x in enumerate(u) if x != 0]
    if len(axes) != 1:
        raise SweepError("sweep.direction", "a box gap must be along one axis")
    return case.a.half[axes[0]] + case.b.half[axes[0]]


def _gap(case: TwoBodyCase, g: float) -> TwoBodyCase:
    u = _unit(case)
    step = _touch_distance(case, u) * (1.0 + g)
    centre = tuple(c + x * step for c, x in zip(case.a.center, u, strict=True))
    return _bodies(case, b={"center": centre})


def _offset(case: TwoBodyCase, t: float) -> TwoBodyCase:
    return _bodies(case, a={"center": tuple(c + t for c in case.a.center)},
                   b={"center": tuple(c + t for c in case.b.center)})


def _mass_ratio(case: TwoBodyCase, r: float) -> TwoBodyCase:
    assert isinstance(case, ResponseCase)
    return _bodies(case, b={"mass": case.a.mass * r})


def _speed(case: TwoBodyCase, k: float) -> TwoBodyCase:
    assert isinstance(case, ResponseCase | ToiCase)
    return _bodies(case, a={"velocity": tuple(v * k for v in case.a.velocity)},
                   b={"velocity": tuple(v * k for v in case.b.velocity)})


_APPLY = {"scale": _scale, "gap": _gap, "overlap": lambda c, o: _gap(c, -o),
          "offset": _offset, "mass_ratio": _mass_ratio, "speed": _speed}


def swapped(case: TwoBodyCase) -> TwoBodyCase:
    """The same case with A and B exchanged (its answers mirror the original's)."""
    return case.model_copy(update={
        "id": swapped_id(case.id), "description": f"{case.description} (A and B swapped)",
        "tags": (*case.tags, "swapped"), "a": case.b, "b": case.a, "swap": False,
        "twin_of": case.id, "from_3d": swapped_id(case.from_3d) if case.from_3d else ""})


def swapped_id(case_id: str) -> str:
    """The id of the A/B-swapped twin of case ``case_id``."""
    return f"{case_id}.swapped"


# --- 2-D twins ---------------------------------------------------------------------------------


def flattened(case: TwoBodyCase, plane: Plane) -> TwoBodyCase:
    """The 2-D twin of a 3-D block: its bodies in ``plane``, the third axis dropped.

    Its id is ``<id>.2d``.  Only a case that lies in a plane parallel to ``plane``
    has a twin: both centres equal on the dropped axis, and velocities and the sweep
    direction zero on it (:class:`TwinError` otherwise).  The loader also checks the
    exact answer (boxes can overlap least along the dropped axis).
    """
    axis = PLANES[plane]
    problem = next(_flattening_problems(case, axis), None)
    if problem is not None:
        raise TwinError(f"no 2-D twin in the {plane} plane: {problem[0]} {problem[1]}")
    sweep = case.sweep
    if sweep is not None and sweep.direction is not None:
        sweep = sweep.model_copy(update={"direction": _drop(sweep.direction, axis)})
    flat = _bodies(case, a=_flat_body(case.a, axis), b=_flat_body(case.b, axis))
    return flat.model_copy(update={
        "id": f"{case.id}{TWIN_SUFFIX}", "dim": 2, "sweep": sweep, "twin_2d": None,
        "description": f"{case.description} (2-D twin in the {plane} plane)",
        "tags": (*case.tags, TWIN_TAG)})


def _flattening_problems(case: TwoBodyCase, axis: int) -> Iterator[tuple[str, str]]:
    """What keeps ``case`` from lying in a plane across ``axis``: (field, reason) pairs."""
    name = AXIS_NAMES[axis]
    if case.dim != 3:
        yield "dim", f"is {case.dim}; a 2-D twin is made from a 3-D case"
        return
    if case.a.center[axis] != case.b.center[axis]:
        yield f"a.center[{axis}]", (f"= {case.a.center[axis]!r} and b.center[{axis}] = "
                                    f"{case.b.center[axis]!r} differ (the centres must share "
                                    f"their {name})")
    moving = ((("a", case.a), ("b", case.b)) if isinstance(case, ResponseCase | ToiCase)
              else ())
    for side, body in moving:
        if body.velocity[axis] != 0:
            yield f"{side}.velocity[{axis}]", f"is {body.velocity[axis]!r}, not 0"
    direction = case.sweep.direction if case.sweep is not None else None
    if direction is not None and len(direction) == 3 and direction[axis] != 0:
        yield f"sweep.direction[{axis}]", f"is {direction[axis]!r}, not 0"


def _drop(vector: tuple[float, ...], axis: int) -> tuple[float, ...]:
    return tuple(x for i, x in enumerate(vector) if i != axis)


def _flat_body(body: Any, axis: int) -> dict[str, Any]:
    """The changes that put ``body`` in the plane across ``axis``."""
    return {name: _drop(getattr(body, name), axis)
            for name in ("center", "half", "velocity") if hasattr(body, name)}


def with_swaps(cases: list[AnyCase]) -> Iterator[AnyCase]:
    """Each case, followed by its swapped twin unless it opts out."""
    for case in cases:
        yield case
        if case.swap and not isinstance(case, SceneCase):
            yield swapped(case)
