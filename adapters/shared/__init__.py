"""What several engines' calls share, as plain functions of plain data (floats and tuples).

Only the standard library: a repro script includes this module's source where an engine's
calls module imports from it (``from adapters.shared import ...``; the script builder,
:mod:`crosscheck.studies.repro.calls`, puts the source in place of the import).  So do its
modules: :mod:`adapters.shared.scene` (checking, stepping and recording a scene, and its
answer with the measures of :mod:`reference_impl.scene_measures`) and
:mod:`adapters.shared.wall_boxes` (walls as thick static boxes, for pymunk and Box2D).

- 2-D in a 3-D engine: :func:`to3` (a 2-D case lies in the plane z = 0) and :func:`z_half`
  (the z half-width both boxes of a 2-D case get);
- the speed at which two bodies approach along their line of centres (a stepped response
  stops when they no longer do);
- times of impact (``sphere_toi``: two spheres in linear motion over ``[0, duration]``):
  the end centres, the unit vector from A's centre to B's at a time, the inputs no engine is
  asked (:func:`toi_refusal`) and the answer without a contact (:data:`NO_CONTACT`).

>>> end_centres((0.0, 0.0), (1.0, 0.0), (4.0, 0.0), (-1.0, 0.0), 2.0)
((2.0, 0.0), (2.0, 0.0))
>>> centre_normal((0.0, 0.0), (1.0, 0.0), (4.0, 0.0), (-1.0, 0.0), 1.5)
(1.0, 0.0)
"""

import math
from collections.abc import Sequence
from typing import Any

Vec = tuple[float, ...]
NO_CONTACT = "no contact in the interval"
"""The reason of ``toi`` and ``normal`` without a contact (the truth's own words)."""
COINCIDE = "the centres coincide at the reported time"


def to3(v: Sequence[float]) -> Vec:
    """A 2- or 3-vector as a 3-vector: a 2-D case lies in the plane z = 0."""
    return (float(v[0]), float(v[1]), float(v[2]) if len(v) > 2 else 0.0)


def z_half(*halves: Sequence[float]) -> float:
    """The z half-width that embeds 2-D boxes in 3-D: 2 x their largest half-width (1 if all
    are 0), so z is never the axis of least overlap nor a gap."""
    return 2.0 * max(abs(h) for half in halves for h in half) or 1.0


def approach_speed(pa: Vec, pb: Vec, va: Vec, vb: Vec) -> float:
    """Speed at which A and B approach along their line of centres (negative: separating;
    NaN when the centres coincide: no line of centres)."""
    d = tuple(y - x for x, y in zip(pa, pb, strict=True))
    length = math.sqrt(math.fsum(x * x for x in d))
    if not length > 0:
        return math.nan
    dv = tuple(y - x for x, y in zip(vb, va, strict=True))
    return math.fsum(x * y for x, y in zip(dv, d, strict=True)) / length


def end_centres(a_center: Vec, a_velocity: Vec, b_center: Vec, b_velocity: Vec,
                duration: float) -> tuple[Vec, ...]:
    """A's and B's centres at the interval's end, ``center + velocity x duration``."""
    return tuple(tuple(c + v * duration for c, v in zip(center, velocity, strict=True))
                 for center, velocity in ((a_center, a_velocity), (b_center, b_velocity)))


def centre_normal(a_center: Vec, a_velocity: Vec, b_center: Vec, b_velocity: Vec,
                  t: float) -> Vec | str:
    """The unit vector from A's centre to B's at time ``t``: ``d = (cb - ca) + (vb - va) t``
    normalised; the reason (:data:`COINCIDE`) where the centres coincide then."""
    dp = tuple(y - x for x, y in zip(a_center, b_center, strict=True))
    dv = tuple(y - x for x, y in zip(a_velocity, b_velocity, strict=True))
    d = tuple(p + v * t for p, v in zip(dp, dv, strict=True))
    length = math.sqrt(math.fsum(x * x for x in d))
    if not length > 0:
        return COINCIDE
    return tuple(x / length for x in d)


def no_contact() -> dict[str, Any]:
    """The answer without a contact in the interval."""
    return {"hit": False, "toi": NO_CONTACT, "normal": NO_CONTACT}


def toi_refusal(a_center: Vec, a_radius: float, a_velocity: Vec, b_center: Vec,
                b_radius: float, b_velocity: Vec, duration: float) -> str:
    """Why no engine is asked a time of impact ('' if it is): a non-finite input or a negative
    radius (the engines take them unchecked), or a duration not positive and finite."""
    numbers = [*a_center, *b_center, *a_velocity, *b_velocity, a_radius, b_radius]
    if not all(math.isfinite(x) for x in numbers):
        return "non-finite input: the engine's time-of-impact query takes it unchecked"
    if a_radius < 0 or b_radius < 0:
        return "negative radius: no sphere has one"
    if not (math.isfinite(duration) and duration > 0):
        return f"duration {duration!r}: the interval [0, duration] needs 0 < duration < inf"
    return ""
