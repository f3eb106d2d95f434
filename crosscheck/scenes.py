"""Dynamics scenes (kind ``sphere_scene``): expansion, exact truth and scoring.

A scene is N spheres in open space with a restitution and a duration.  Its
block declares ``steps`` (time steps ``dt`` and, optionally, solver
``iterations``); expansion makes one case per combination, with ids
``<id>.dt=<dt>[,iterations=<k>]``.  An engine steps ``round(duration / dt)``
times; the truth is :func:`reference_impl.events.simulate` run to exactly
that many steps' worth of time, so no engine is blamed for a partial step.

Four quantities are scored, each as a relative (dimensionless) error:

- ``positions``: the largest distance between an engine's final centre and the
  reference's, in units of the mean radius;
- ``velocities``: the largest velocity difference over the largest initial speed;
- ``momentum``: the change of total momentum over ``sum m |v|`` at the start;
- ``energy``: the difference from the reference's final kinetic energy over the
  initial kinetic energy (for ``e = 1`` this is the energy drift).

The tolerance is :data:`~crosscheck.score.DEFAULT_RTOL` unless the case sets one.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Iterator, Sequence
from fractions import Fraction
from typing import Any, cast

from crosscheck.model import Category, Observation, Status, Undefined, Value
from crosscheck.schema import DEFAULT_DT, SceneCase

QUANTITIES = ("positions", "velocities", "momentum", "energy")
Vec = tuple[float, ...]


def generated_bodies(generator: dict[str, Any], dim: Any) -> list[dict[str, Any]]:
    """Bodies of a ``generator`` table, as case-file dicts (see SceneGenerator)."""
    from reference_impl import events

    name = generator.get("name")
    d = dim if dim in (2, 3) else 2
    if name == "cluster":
        balls = events.cluster(int(generator.get("n") or 30), int(generator.get("seed") or 0), d,
                               float(generator.get("extent") or 6.0),
                               radius_range(float(generator.get("radius") or 0.4)),
                               float(generator.get("speed") or 1.0))
    elif name == "cradle":
        balls = events.cradle(int(generator.get("n") or 5), float(generator.get("radius") or 0.5),
                              float(generator.get("speed") or 1.0), d)
    elif name == "billiards":
        balls = events.billiards(d, float(generator.get("offset") or 0.0))
    else:
        return []  # the schema reports the bad name
    return [{"center": list(b.center), "radius": b.radius, "mass": b.mass,
             "velocity": list(b.velocity)} for b in balls]


def radius_range(mean: float) -> tuple[float, float]:
    """Cluster radii: uniform in [0.75, 1.25] x the mean radius."""
    return (0.75 * mean, 1.25 * mean)


def expand_steps(case: SceneCase) -> Iterator[SceneCase]:
    """One case per ``dt`` x ``iterations`` of the block's ``steps`` (the block itself if none)."""
    from crosscheck.expand import values_of

    if case.steps is None:
        yield case
        return
    iterations: Sequence[int | None] = case.steps.iterations or [None]
    for dt, k in itertools.product(values_of(case.steps.dt), iterations):
        label = f"dt={dt:.6g}" + (f",iterations={k}" if k is not None else "")
        yield case.model_copy(update={
            "id": f"{case.id}.{label}", "description": f"{case.description} [{label}]",
            "tags": (*case.tags, "dynamics"), "steps": None, "dt": dt, "iterations": k})


def simulated_time(case: SceneCase) -> Fraction:
    """Exactly the time an engine simulates: ``round(duration / dt)`` steps of ``dt``."""
    return case.step_count * Fraction(case.dt or DEFAULT_DT)


def _key(case: SceneCase) -> tuple[Any, ...]:
    bodies = tuple((b.center, b.radius, b.mass, b.velocity) for b in case.bodies)
    return (bodies, case.restitution, simulated_time(case))


def truth(case: SceneCase) -> Observation:
    """The exact event-driven state at :func:`simulated_time`, as floats."""
    return _truth(_key(case))


@functools.lru_cache(maxsize=256)
def _truth(key: tuple[Any, ...]) -> Observation:
    from reference_impl import events

    bodies, e, t = key
    balls = [events.Ball(c, r, m, v) for c, r, m, v in bodies]
    try:
        state = events.simulate(balls, e, t)
    except (RuntimeError, ValueError, ArithmeticError) as exc:
        return Observation.undefined(QUANTITIES, f"no reference: {exc}")
    positions, velocities = state.positions_float(), state.velocities_float()
    masses = [m for _, _, m, _ in bodies]
    return observation(positions, velocities, masses)


def observation(positions: Sequence[Vec], velocities: Sequence[Vec],
                masses: Sequence[float]) -> Observation:
    """A scene observation: final state, total momentum and kinetic energy (float64, fsum)."""
    dim = len(positions[0]) if positions else 0
    momentum = tuple(math.fsum(m * v[i] for m, v in zip(masses, velocities, strict=True))
                     for i in range(dim))
    energy = math.fsum(0.5 * m * math.fsum(x * x for x in v)
                       for m, v in zip(masses, velocities, strict=True))
    return Observation(positions=tuple(tuple(p) for p in positions),
                       velocities=tuple(tuple(v) for v in velocities),
                       momentum=momentum, energy=energy)


def _norm(v: Sequence[float]) -> float:
    return math.sqrt(math.fsum(x * x for x in v))


def _scales(case: SceneCase) -> dict[str, float]:
    speeds = [_norm(b.velocity) for b in case.bodies]
    masses = [b.mass for b in case.bodies]
    return {
        "positions": math.fsum(b.radius for b in case.bodies) / max(1, len(case.bodies)),
        "velocities": max(speeds, default=0.0),
        "momentum": math.fsum(m * s for m, s in zip(masses, speeds, strict=True)),
        "energy": math.fsum(0.5 * m * s * s for m, s in zip(masses, speeds, strict=True)),
    }


def relative_error(case: SceneCase, quantity: str, value: Value, want: Value) -> float:
    """The relative error of one scene quantity (see the module docstring)."""
    scale = _scales(case)[quantity]
    if quantity in ("positions", "velocities"):
        assert isinstance(value, tuple) and isinstance(want, tuple)
        if len(value) != len(want):
            return math.inf
        mine, theirs = cast(tuple[Vec, ...], value), cast(tuple[Vec, ...], want)
        diff = max((_norm([x - y for x, y in zip(p, q, strict=True)])
                    for p, q in zip(mine, theirs, strict=True)), default=0.0)
    elif quantity == "momentum":
        assert isinstance(value, tuple) and isinstance(want, tuple)
        p, q = cast(Vec, value), cast(Vec, want)
        diff = _norm([x - y for x, y in zip(p, q, strict=True)])
    else:
        assert isinstance(value, float | int) and isinstance(want, float | int)
        diff = abs(float(value) - float(want))
    if not math.isfinite(diff):
        return math.inf
    return diff / scale if scale > 0 else diff


def tolerance(case: SceneCase, quantity: str, default: float) -> float:
    """The case's own tolerance for ``quantity`` (relative), else ``default``."""
    own = case.tolerance
    if own is None:
        return default
    chosen = own.distance if quantity == "positions" else own.velocity
    return chosen if chosen is not None else default


def judge(case: SceneCase, quantity: str, value: Value, want: Value,
          default_tol: float) -> tuple[Status, float, float, str, str]:
    """Status, relative error, tolerance, category and reason of one scene quantity."""
    tol = tolerance(case, quantity, default_tol)
    if isinstance(value, Undefined):
        return Status.DISAGREE, math.inf, tol, Category.ERROR, f"engine gave undefined ({value})"
    err = relative_error(case, quantity, value, want)
    if err <= tol:
        return Status.AGREE, err, tol, "", ""
    what = {"positions": "mean radii", "velocities": "of the largest initial speed",
            "momentum": "of sum m|v|", "energy": "of the initial kinetic energy"}[quantity]
    return (Status.DISAGREE, err, tol, Category.ERROR,
            f"{quantity} off by {err:.3g} {what} after {case.step_count} steps of dt = "
            f"{case.dt or DEFAULT_DT:.3g}")


MAX_STEPS = 10_000_000
"""Most steps a scene case may ask of an engine (duration / dt)."""


def problems(case: SceneCase) -> Iterator[tuple[str, str]]:
    """Scene rules beyond the schema: two bodies or more, radii > 0, no overlap at the start."""
    if len(case.bodies) < 2:
        yield "bodies", "a scene needs at least two bodies (list them or give a generator)"
    for i, body in enumerate(case.bodies):
        if not body.radius > 0:
            yield f"bodies[{i}].radius", f"must be > 0 in a scene, got {body.radius!r}"
    for (i, p), (j, q) in itertools.combinations(enumerate(case.bodies), 2):
        d2 = sum((Fraction(x) - Fraction(y)) ** 2 for x, y in zip(p.center, q.center, strict=False))
        if d2 < (Fraction(p.radius) + Fraction(q.radius)) ** 2:
            yield f"bodies[{j}].center", f"overlaps bodies[{i}] at the start (touching is allowed)"
    if case.step_count > MAX_STEPS:
        yield "dt", f"{case.step_count} steps exceed {MAX_STEPS}: use a larger dt"
