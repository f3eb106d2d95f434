"""Types and checks shared by the scene runners in ``pybullet_scene`` and ``pymunk_scene``.

A scene is N spheres (discs in 2-D) in open space: no gravity, no ground, one restitution
for every contact.  Each engine module builds it (``prepare_scene``, untimed), steps it with
a fixed time step (``run_scene``: only the stepping loop is timed) and frees it
(``release_scene``).  Both return a :class:`SceneRun`, which the harness compares with an
exact event-driven reference.  :func:`check_scene` rejects, with ``ValueError``, what an
engine would misread or crash on (pymunk aborts the interpreter on a mass <= 0, NaN or inf;
pybullet makes a mass-0 body static and raises ``pybullet.error`` on a radius <= 0).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

Body = tuple[tuple[float, ...], float, float, tuple[float, ...]]
"""A sphere of the scene: (centre, radius, mass, velocity), vectors of the scene's dim."""


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
