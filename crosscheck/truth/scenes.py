"""Dynamics scenes (kind ``sphere_scene``): exact truth and scoring.

A scene is N spheres in open space with a restitution and a duration.  Its
block declares ``steps`` (time steps ``dt`` and, optionally, solver
``iterations``); :func:`crosscheck.cases.expand.expand_steps` makes one case
per combination.  An engine steps ``round(duration / dt)``
times; the truth is :func:`reference_impl.events.simulate` run to exactly
that many steps' worth of time, so no engine is blamed for a partial step.

Four quantities are scored, each as a relative (dimensionless) error:

- ``positions``: the largest distance between an engine's final centre and the
  reference's, in units of the mean radius;
- ``velocities``: the largest velocity difference over the largest initial speed;
- ``momentum``: the change of total momentum over ``sum m |v|`` at the start;
- ``energy``: the difference from the reference's final kinetic energy over the
  initial kinetic energy (for ``e = 1`` this is the energy drift).

The tolerance is :data:`~crosscheck.truth.score.DEFAULT_RTOL` unless the case sets one.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from fractions import Fraction
from typing import Any, cast

from crosscheck.core.geometry import Vec, norm
from crosscheck.core.model import Category, Observation, Status, Undefined, Value
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from reference_impl import events

QUANTITIES = ("positions", "velocities", "momentum", "energy")


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



def _scales(case: SceneCase) -> dict[str, float]:
    speeds = [norm(b.velocity) for b in case.bodies]
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
        diff = max((norm([x - y for x, y in zip(p, q, strict=True)])
                    for p, q in zip(mine, theirs, strict=True)), default=0.0)
    elif quantity == "momentum":
        assert isinstance(value, tuple) and isinstance(want, tuple)
        p, q = cast(Vec, value), cast(Vec, want)
        diff = norm([x - y for x, y in zip(p, q, strict=True)])
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
