"""Types and checks shared by the scene runners (``pybullet_scene``, ``pymunk_scene``, ...).

A scene is N spheres (discs in 2-D) with one restitution for every contact, in open space
or in :class:`Surroundings`: a uniform gravity and static axis-aligned walls (a ground, or
the walls of a box), which every contact with a wall also bounces with.  Each engine module
builds it (``prepare_scene``, untimed), steps it with
a fixed time step (``run_scene``: only the stepping loop is timed) and frees it
(``release_scene``).  Both return a :class:`SceneRun`, which the harness compares with an
exact event-driven reference.  :func:`check_scene` rejects, with ``ValueError``, what an
engine would misread or crash on (pymunk aborts the interpreter on a mass <= 0, NaN or inf;
pybullet makes a mass-0 body static and raises ``pybullet.error`` on a radius <= 0).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from reference_impl.events import Wall, is_axis_normal

__all__ = [
    "Body",
    "Samples",
    "SceneRun",
    "State",
    "Surroundings",
    "Wall",
    "check_scene",
    "check_surroundings",
    "in_scene_dim",
    "step_and_record",
]

Body = tuple[tuple[float, ...], float, float, tuple[float, ...]]
"""A sphere of the scene: (centre, radius, mass, velocity), vectors of the scene's dim."""


@dataclass(frozen=True)
class Surroundings:
    """What a scene has besides its spheres: a uniform gravity (m/s^2, one component per
    dimension) and static walls.  ``Surroundings.none(dim)`` is open space."""

    gravity: tuple[float, ...]
    walls: tuple[Wall, ...] = ()

    @classmethod
    def none(cls, dim: int) -> Surroundings:
        """Open space: no gravity, no walls."""
        return cls((0.0,) * dim, ())


@dataclass(frozen=True)
class Samples:
    """The state of every body after steps ``0, every, 2 every, ...`` (step 0: the start).

    ``positions`` and ``velocities`` have shape ``(samples, bodies, dim)`` (float64).
    """

    every: int
    positions: np.ndarray = field(repr=False)
    velocities: np.ndarray = field(repr=False)


State = tuple[Sequence[Sequence[float]], Sequence[Sequence[float]]]
"""Every body's centre and velocity, in the scene's dimension, as an engine reads them."""


def step_and_record(step: Callable[[], None], read: Callable[[], State], steps: int,
                    record_every: int, clock: Callable[[], float] = time.perf_counter,
                    ) -> tuple[float, Samples | None]:
    """Call ``step`` ``steps`` times; with ``record_every > 0`` also ``read`` the state at
    the start and after every ``record_every`` steps (and after the last).

    Returns the wall time of the stepping alone (reading the state is not timed: the clock
    is read around each run of steps between two records) and the samples, or None.

    >>> box = {"x": 0.0}
    >>> def step(): box["x"] += 1.0
    >>> wall, samples = step_and_record(step, lambda: ([(box["x"],)], [(1.0,)]), 5, 2)
    >>> samples.positions[:, 0, 0].tolist(), samples.every
    ([0.0, 2.0, 4.0, 5.0], 2)
    """
    check_steps(steps)
    if record_every <= 0:
        start = clock()
        for _ in range(steps):
            step()
        return clock() - start, None
    positions, velocities = [], []
    wall, done = 0.0, 0
    while True:
        p, v = read()
        positions.append(np.asarray(p, dtype=np.float64))
        velocities.append(np.asarray(v, dtype=np.float64))
        if done >= steps:
            break
        chunk = min(record_every, steps - done)
        start = clock()
        for _ in range(chunk):
            step()
        wall += clock() - start
        done += chunk
    return wall, Samples(record_every, np.stack(positions), np.stack(velocities))


@dataclass(frozen=True)
class SceneRun:
    """The final state of a stepped scene and the wall time of its stepping loop."""

    positions: tuple[tuple[float, ...], ...]
    """Final centres, in the scene's dimension (2 or 3)."""
    velocities: tuple[tuple[float, ...], ...]
    """Final velocities, in the scene's dimension."""
    wall_s: float
    """Wall-clock seconds of the stepping loop only (no setup, no state read-back)."""
    steps: int
    """Steps taken."""
    samples: Samples | None = None
    """The recorded trajectory (``run_scene(..., record_every=k)``), else None.  With
    ``record_every`` the last sample is the final state and need not be ``every`` steps
    after the one before it."""


def check_surroundings(surroundings: Surroundings | None, dim: int) -> Surroundings:
    """The surroundings to build (open space for None), or ``ValueError`` for gravity or a
    wall of the wrong dimension, a wall normal that is not a unit axis vector, or a
    non-finite value.

    >>> check_surroundings(None, 2)
    Surroundings(gravity=(0.0, 0.0), walls=())
    >>> check_surroundings(Surroundings((0.0, -9.81), (Wall((0.5, 0.5), 0.0),)), 2)
    Traceback (most recent call last):
    ...
    ValueError: wall 0: the normal must be a unit axis vector, got (0.5, 0.5)
    """
    if surroundings is None:
        return Surroundings.none(dim)
    if len(surroundings.gravity) != dim or not all(map(math.isfinite, surroundings.gravity)):
        raise ValueError(f"gravity must be {dim} finite components, got {surroundings.gravity}")
    for k, wall in enumerate(surroundings.walls):
        if not is_axis_normal(wall.normal, dim):
            raise ValueError(f"wall {k}: the normal must be a unit axis vector, got {wall.normal}")
        if not math.isfinite(wall.offset):
            raise ValueError(f"wall {k}: the offset must be finite, got {wall.offset}")
    return surroundings


def check_scene(bodies: Sequence[Body], dim: int, restitution: float, dt: float) -> None:
    """Raise ``ValueError`` unless the scene is one both engines can build as declared.

    >>> check_scene([((0.0, 0.0), 0.5, 1.0, (1.0, 0.0))], 2, 1.0, 1e-3)
    >>> check_scene([((0.0, 0.0), 0.5, 0.0, (1.0, 0.0))], 2, 1.0, 1e-3)
    Traceback (most recent call last):
    ...
    ValueError: body 0: mass must be positive and finite, got 0.0
    """
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
                 tolerance: float = 0.0) -> tuple[tuple[float, ...], ...]:
    """Vectors of a 3-D engine in the scene's ``dim`` dimensions: a 2-D scene must have kept
    to the plane z = 0, up to ``tolerance`` (NaN is off the plane).

    >>> in_scene_dim(2, [(1.0, 2.0, 0.0)], "position")
    ((1.0, 2.0),)
    >>> in_scene_dim(2, [(1.0, 2.0, 1e-20)], "velocity", tolerance=1e-12)
    ((1.0, 2.0),)
    >>> in_scene_dim(2, [(1.0, 2.0, 1e-20)], "velocity")
    Traceback (most recent call last):
    ...
    RuntimeError: 2-D scene left the plane z = 0: velocity z = 1e-20
    """
    rows = [tuple(float(x) for x in v) for v in vectors]
    if dim == 2:
        off = [v[2] for v in rows if not abs(v[2]) <= tolerance]
        if off:
            raise RuntimeError(f"2-D scene left the plane z = 0: {what} z = {off[0]!r}")
    return tuple(v[:dim] for v in rows)


def check_steps(steps: int) -> None:
    """Raise ``ValueError`` for a negative step count."""
    if steps < 0:
        raise ValueError(f"steps must be >= 0, got {steps}")
