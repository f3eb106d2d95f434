"""Stepping a scene and its answer, shared by the engines' scene calls, as plain data.

A scene (``sphere_scene``) is N spheres (discs in 2-D), ``bodies`` as ``(centre, radius,
mass, velocity)``, one restitution for every contact, a uniform ``gravity`` and static
axis-aligned ``walls`` (``(normal, offset)`` pairs, solid where ``normal . x < offset``).  An
engine's calls module builds it (checking it first with :func:`check_scene`: what an engine
would misread or crash on raises ``ValueError``), steps it with :func:`step_and_record` (only
the stepping is timed; with ``record_every`` > 0 the states are recorded too) and answers
with :func:`scene_answer`: the final state, the total momentum and kinetic energy, the
measures (:mod:`reference_impl.scene_measures`), the recorded ``trajectory`` and ``wall_s``.
Only the standard library (and :mod:`reference_impl.scene_measures`, whose source a repro
script holds too): a script includes this module's source.
"""

import math
import time
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from reference_impl.scene_measures import engine_measures, total_energy

Vec = tuple[float, ...]
State = tuple[Sequence[Sequence[float]], Sequence[Sequence[float]]]
"""Every body's centre and velocity, in the scene's dimension, as an engine reads them."""
NOT_JUDGED = "no recorded trajectory (an open-space scene)"
"""``divergence``'s reason in an engine's answer: the harness judges it against the exact run."""


def is_axis_normal(normal: Sequence[float], dim: int) -> bool:
    """Whether ``normal`` is a unit axis vector of ``dim`` components (one +1 or -1)."""
    return len(normal) == dim and sorted(map(abs, normal)) == [0.0] * (dim - 1) + [1.0]


def wall_axis(normal: Sequence[float]) -> int:
    """The axis of a wall's unit axis normal."""
    return next(k for k, n in enumerate(normal) if n != 0.0)


def check_surroundings(gravity: Sequence[float], walls: Sequence[tuple[Vec, float]],
                       dim: int) -> None:
    """``ValueError`` for gravity or a wall of the wrong dimension, a wall normal that is not
    a unit axis vector, or a non-finite value."""
    if len(gravity) != dim or not all(map(math.isfinite, gravity)):
        raise ValueError(f"gravity must be {dim} finite components, got {tuple(gravity)}")
    for k, (normal, offset) in enumerate(walls):
        if not is_axis_normal(normal, dim):
            raise ValueError(f"wall {k}: the normal must be a unit axis vector, got {normal}")
        if not math.isfinite(offset):
            raise ValueError(f"wall {k}: the offset must be finite, got {offset}")


def check_scene(bodies: Sequence[Any], dim: int, restitution: float, dt: float) -> None:
    """Raise ``ValueError`` unless the scene is one every engine can build as declared (pymunk
    aborts the interpreter on a mass <= 0, NaN or inf; pybullet makes a mass-0 body static)."""
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    if not (0.0 <= restitution < math.inf):
        raise ValueError(f"restitution must be >= 0 and finite, got {restitution}")
    if not (0.0 < dt < math.inf):
        raise ValueError(f"dt must be positive and finite, got {dt}")
    for i, (center, radius, mass, velocity) in enumerate(bodies):
        if len(center) != dim or len(velocity) != dim:
            raise ValueError(f"body {i}: centre and velocity must have {dim} components")
        if not all(math.isfinite(x) for x in (*center, *velocity)):
            raise ValueError(f"body {i}: centre and velocity must be finite")
        if not (0.0 < radius < math.inf):
            raise ValueError(f"body {i}: radius must be positive and finite, got {radius}")
        if not (0.0 < mass < math.inf):
            raise ValueError(f"body {i}: mass must be positive and finite, got {mass}")


def in_scene_dim(dim: int, vectors: Iterable[Sequence[float]], what: str,
                 tolerance: float = 0.0) -> tuple[Vec, ...]:
    """Vectors of a 3-D engine in the scene's ``dim`` dimensions: a 2-D scene must have kept
    to the plane z = 0, up to ``tolerance`` (NaN is off the plane)."""
    rows = [tuple(float(x) for x in v) for v in vectors]
    if dim == 2:
        off = [v[2] for v in rows if not abs(v[2]) <= tolerance]
        if off:
            raise RuntimeError(f"2-D scene left the plane z = 0: {what} z = {off[0]!r}")
    return tuple(v[:dim] for v in rows)


def step_and_record(step: Callable[[], None], read: Callable[[], State], steps: int,
                    record_every: int, clock: Callable[[], float] = time.perf_counter,
                    ) -> tuple[float, list[Any] | None]:
    """Call ``step`` ``steps`` times; with ``record_every > 0`` also ``read`` the state at the
    start and after every ``record_every`` steps (and after the last).

    Returns the wall time of the stepping alone (the clock is read around each run of steps
    between two records) and the records ``(step, positions, velocities)``, or None.
    """
    if steps < 0:
        raise ValueError(f"steps must be >= 0, got {steps}")
    if record_every <= 0:
        start = clock()
        for _ in range(steps):
            step()
        return clock() - start, None
    records: list[Any] = []
    wall, done = 0.0, 0
    while True:
        positions, velocities = read()
        records.append((done, positions, velocities))
        if done >= steps:
            break
        chunk = min(record_every, steps - done)
        start = clock()
        for _ in range(chunk):
            step()
        wall += clock() - start
        done += chunk
    return wall, records


def _vectors(rows: Sequence[Sequence[float]]) -> tuple[Vec, ...]:
    return tuple(tuple(float(x) for x in row) for row in rows)


def scene_answer(bodies: Sequence[Any], gravity: Sequence[float],
                 walls: Sequence[tuple[Vec, float]], dt: float, steps: int, state: State,
                 records: list[Any] | None, wall_s: float) -> dict[str, Any]:
    """The answer of a stepped scene: the final ``positions`` and ``velocities``, the total
    ``momentum`` and kinetic ``energy`` (fsum), the measures, the ``trajectory`` (``times,
    positions, velocities, energies`` of the records; None without) and ``wall_s``."""
    positions, velocities = _vectors(state[0]), _vectors(state[1])
    masses = [b[2] for b in bodies]
    dim = len(positions[0]) if positions else 0
    trajectory = None
    if records is not None:
        frames = [(_vectors(p), _vectors(v)) for _, p, v in records]
        trajectory = (tuple(k * dt for k, _, _ in records), tuple(p for p, _ in frames),
                      tuple(v for _, v in frames),
                      tuple(total_energy(gravity, bodies, p, v) for p, v in frames))
    measures = engine_measures(gravity, walls, bodies, steps * dt, positions, velocities,
                               None if trajectory is None else trajectory[:3])
    return {"positions": positions, "velocities": velocities,
            "momentum": tuple(math.fsum(m * v[i] for m, v in zip(masses, velocities, strict=True))
                              for i in range(dim)),
            "energy": math.fsum(0.5 * m * math.fsum(x * x for x in v)
                                for m, v in zip(masses, velocities, strict=True)),
            **measures, "divergence": NOT_JUDGED, "trajectory": trajectory, "wall_s": wall_s}
