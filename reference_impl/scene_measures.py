"""The arithmetic of the scene measures, over plain data: one source for the harness and scripts.

:mod:`crosscheck.truth.scene_measures` says what the measures are and calls these functions
with a case's values; an engine's scene calls (``adapters/<engine>/calls.py``) call them on
the states they step, and a repro script holds this module's source verbatim (so it has no
future import and imports only the standard library).  A scene is given as
``gravity`` (one component per dimension), ``walls`` (``(normal, offset)`` pairs, solid where
``normal . x < offset``) and ``bodies`` (``(centre, radius, mass, velocity)``); a measure with
no value is the reason, a ``str`` (:data:`NO_GROUND`, :data:`NOT_RECORDED`).

>>> walls, gravity = [((0.0, 1.0), 0.0)], (0.0, -10.0)
>>> bodies = [((0.0, 1.0), 1.0, 1.0, (0.0, 0.0))]
>>> ground(gravity, walls), gap(walls, 0, (0.0, 3.0), 1.0)
(0, 2.0)
>>> bounces(gravity, walls, bodies, (0.0, 0.1, 0.2, 0.3, 0.4),
...         [((0.0, h + 1),) for h in (1.0, 0.0, 1.0, 2.0, 1.5)],
...         [((0.0, v),) for v in (-1.0, 1.0, 1.0, -1.0, -1.0)])
((2.0,), (0.1,))
"""

import math
from collections.abc import Sequence
from typing import Any

Vector = Sequence[float]
WallPair = tuple[Vector, float]
SceneBody = tuple[Vector, float, float, Vector]

NO_GROUND = "the scene has no ground (no wall facing gravity)"
NOT_RECORDED = "no recorded trajectory (an open-space scene)"


def norm(v: Vector) -> float:
    """The Euclidean length: ``sqrt(fsum(x**2))``."""
    return math.sqrt(math.fsum(x * x for x in v))


def ground(gravity: Vector, walls: Sequence[WallPair]) -> int | None:
    """The index of the first wall facing gravity (a ground), or None."""
    for k, (normal, _) in enumerate(walls):
        if math.fsum(n * x for n, x in zip(normal, gravity, strict=True)) < 0:
            return k
    return None


def gap(walls: Sequence[WallPair], wall: int, center: Vector, radius: float) -> float:
    """A sphere's signed gap to wall number ``wall`` (negative: penetrating)."""
    normal, offset = walls[wall]
    return math.fsum(n * x for n, x in zip(normal, center, strict=True)) - offset - radius


def kinetic(bodies: Sequence[SceneBody]) -> float:
    """The bodies' initial kinetic energy."""
    return math.fsum(0.5 * m * math.fsum(v * v for v in u) for _, _, m, u in bodies)


def energy_scale(gravity: Vector, walls: Sequence[WallPair], bodies: Sequence[SceneBody]) -> float:
    """The initial kinetic energy, plus under gravity each body's ``m |g| h`` with ``h`` its
    centre's height above the ground (its radius when there is none)."""
    g, floor = norm(gravity), ground(gravity, walls)
    start = kinetic(bodies)
    if g == 0.0:
        return start
    heights = [gap(walls, floor, c, 0.0) if floor is not None else r for c, r, _, _ in bodies]
    return start + math.fsum(b[2] * g * h for b, h in zip(bodies, heights, strict=True))


def total_energy(gravity: Vector, bodies: Sequence[SceneBody], positions: Sequence[Vector],
                 velocities: Sequence[Vector]) -> float:
    """Kinetic energy plus ``-m g . (p - p0)`` (potential from each body's start)."""
    return math.fsum(
        0.5 * b[2] * math.fsum(v * v for v in vel)
        - b[2] * math.fsum(q * (x - x0) for q, x, x0 in zip(gravity, p, b[0], strict=True))
        for b, p, vel in zip(bodies, positions, velocities, strict=True))


def drift(gravity: Vector, walls: Sequence[WallPair], bodies: Sequence[SceneBody],
          energy_end: float, duration: float) -> float:
    """``(E(T) - E(0)) / (E_scale T)`` (E(0) = the initial kinetic energy)."""
    scale = energy_scale(gravity, walls, bodies)
    return (energy_end - kinetic(bodies)) / ((scale if scale > 0 else 1.0)
                                             * max(duration, 1e-300))


def bounces(gravity: Vector, walls: Sequence[WallPair], bodies: Sequence[SceneBody],
            times: Sequence[float], positions: Sequence[Sequence[Vector]],
            velocities: Sequence[Sequence[Vector]]) -> tuple[tuple[float, ...], ...]:
    """Body 0's apexes and bounce times in recorded states: a bounce is a record at which the
    normal velocity (along the ground's normal) has turned from closing (through records of
    exactly 0 too) to opening, and the apex after it the largest gap before the velocity
    turns closing again (an apex not reached by the end is not counted)."""
    floor = ground(gravity, walls)
    if floor is None:
        return (), ()
    normal = walls[floor][0]
    heights = [gap(walls, floor, ps[0], bodies[0][1]) for ps in positions]
    speeds = [math.fsum(n * v for n, v in zip(normal, vs[0], strict=True)) for vs in velocities]
    apexes: list[float] = []
    bounced: list[float] = []
    top, rising, falling = -math.inf, False, False
    for k in range(1, len(speeds)):
        falling = speeds[k - 1] < 0 or (falling and speeds[k - 1] == 0)  # through a 0 too
        if falling and speeds[k] > 0:
            bounced.append(times[k])
            top, rising = heights[k], True
        elif rising:
            top = max(top, heights[k])
            if speeds[k] <= 0:
                apexes.append(top)
                rising = False
    return tuple(apexes), tuple(bounced)


def engine_measures(gravity: Vector, walls: Sequence[WallPair], bodies: Sequence[SceneBody],
                    duration: float, positions: Sequence[Vector], velocities: Sequence[Vector],
                    trajectory: tuple[Sequence[float], Sequence[Any], Sequence[Any]] | None,
                    ) -> dict[str, Any]:
    """Every measure but ``divergence`` (judged against the exact trajectory) from the final
    state and the recorded ``(times, positions, velocities)`` (None: none recorded)."""
    out: dict[str, Any] = {"energy_drift": drift(
        gravity, walls, bodies, total_energy(gravity, bodies, positions, velocities), duration)}
    floor = ground(gravity, walls)
    out["settle"] = NO_GROUND if floor is None else tuple(
        gap(walls, floor, p, b[1]) for p, b in zip(positions, bodies, strict=True))
    if trajectory is None:
        return out | {q: NOT_RECORDED for q in ("jitter", "apex", "bounce_time")}
    times, _, speeds = trajectory
    half = [k for k, t in enumerate(times) if t >= duration / 2]
    out["jitter"] = max((norm(v) for k in half for v in speeds[k]), default=0.0)
    if floor is None:
        out["apex"] = out["bounce_time"] = NO_GROUND
    else:
        out["apex"], out["bounce_time"] = bounces(gravity, walls, bodies, *trajectory)
    return out
