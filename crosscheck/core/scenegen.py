"""Scene generators: the bodies of a ``generator`` table of a ``sphere_scene`` block.

The schema calls :func:`generated_bodies` while it validates a block, so a
generated scene is a case like any other from then on.  The generators
themselves are :func:`reference_impl.events.cluster`, ``cradle`` and
``billiards`` (seeded, deterministic).

>>> bodies = generated_bodies({"name": "cradle", "n": 3}, 2)
>>> [b["center"] for b in bodies]
[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]
"""

from __future__ import annotations

from typing import Any

from reference_impl import events


def generated_bodies(generator: dict[str, Any], dim: Any) -> list[dict[str, Any]]:
    """Bodies of a ``generator`` table, as case-file dicts (see SceneGenerator)."""
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
