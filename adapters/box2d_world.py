"""Building Box2D (pybox2d 2.3.10) worlds of discs, shared by the response and the scene runner.

What it is for: :mod:`adapters.box2d` (``sphere_response``: two discs, in its calls) and
:mod:`adapters.box2d_scene` (``sphere_scene``: N discs) build their worlds the same way,
with the same variant settings (:class:`Variant`): a ``b2World`` with gravity 0 (a scene's
gravity if it has one) and sleeping set with ``SetAllowSleeping`` (pybox2d's
``b2World(doSleep=...)`` only sets a Python attribute), per wall of a scene a static body
with a box fixture (``add_wall``, sized by :mod:`adapters.wall_boxes`), and per disc a
dynamic body with one circle fixture of density 0 whose mass is then set exactly through
``massData`` (centre 0; moment ``m r^2 / 2`` when rotation is free, what a density would
give, else 0 with ``fixedRotation``).  The reasons for each setting are in
:mod:`adapters.box2d`'s docstring.  Box2D is imported on first use (``engine``), so a
missing engine shows as unavailable.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from adapters.shared.box2d import disc, engine, new_world, xy
from adapters.wall_boxes import Slab

__all__ = ["Variant", "add_disc", "add_wall", "engine", "new_world", "xy"]


@dataclass(frozen=True, slots=True)
class Variant:
    """What a variant sets (None: Box2D's default)."""

    polygon_radius: float | None
    use_radii: bool
    dt: float
    friction: float | None
    fixed_rotation: bool
    sleep: bool
    velocity_iterations: int = 8
    position_iterations: int = 3
    bullet: bool = False
    """Every disc a bullet (``b2BodyDef.bullet``): Box2D's continuous collision (time of
    impact) then acts between it and other dynamic bodies too, not only static ones."""


def add_disc(world: Any, center: Sequence[float], velocity: Sequence[float], radius: float,
             mass: float, restitution: float, variant: Variant) -> Any:
    """A dynamic body at ``center`` with ``velocity`` and ``mass``, with one circle fixture
    (:func:`adapters.box2d.calls.disc` with the variant's settings)."""
    return disc(world, center, velocity, radius, mass, restitution, variant.friction,
                variant.fixed_rotation, variant.bullet)


def add_wall(world: Any, slab: Slab, restitution: float, variant: Variant) -> Any:
    """A static body at the slab's anchor with one box fixture (``SetAsBox(hx, hy, centre,
    0)`` in the body's frame: the surface is at 0 there, exactly), the disc's restitution,
    the variant's friction and polygon radius (None: Box2D's ``b2_polygonRadius`` skin)."""
    b2 = engine()
    body = world.CreateStaticBody(position=xy(slab.anchor))
    shape = b2.b2PolygonShape()
    shape.SetAsBox(slab.half[0], slab.half[1], xy(slab.centre), 0.0)
    if variant.polygon_radius is not None:
        shape.radius = variant.polygon_radius
    extra = {} if variant.friction is None else {"friction": variant.friction}
    body.CreateFixture(shape=shape, restitution=restitution, **extra)
    return body
