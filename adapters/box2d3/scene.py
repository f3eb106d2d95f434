"""Box2D v3.1.1 (pyb2d3 0.11.1) stepping a 2-D scene of N discs: what a variant sets and the
gravity-and-walls conventions, measured.

A scene (N discs, one restitution, in open space or with gravity and static walls) is stepped
with a fixed ``dt`` by the scene calls of :mod:`adapters.box2d3.calls` (``scene``,
``step_scene``, ``release_scene``).  Here: what a variant sets (:class:`Variant`), its inputs to
the scene calls (:func:`scene_settings`) and its gravity-and-walls conventions
(:func:`with_walls`).  Box2D is 2-D: a 3-D scene raises ``ValueError``.

Building (``scene``, untimed): a new world per scene (the scene's gravity; sleeping, continuous
collision and the maximum linear speed as the variant says); per wall a static body with a box
(:mod:`adapters.shared.wall_boxes`: the face a disc touches at exactly 0 in the body's frame);
per disc a dynamic body at its centre with its velocity and one circle of restitution e and
density 0, its mass set exactly through ``mass_data``.  ``step_scene`` times only
``world.step(dt, sub_steps)`` (``b2World_Step(worldId, timeStep, subStepCount)``: sub-steps
the scene's ``iterations`` if given, else the variant's 4, the count Box2D's documentation
recommends) and reads ``position`` / ``linear_velocity`` after it.

Contact model (Box2D v3.1.1 sources, ``adapters.box2d3.SOURCES``): a soft step.  Contacts are
made at a step start for shapes whose manifold has points, which includes the speculative
points up to ``B2_SPECULATIVE_DISTANCE`` (4 ``B2_LINEAR_SLOP`` = 0.02 m) apart (manifold.c);
each sub-step integrates velocities (gravity, then the speed cap ``maximumLinearSpeed``), solves
the contacts as soft constraints (``contactHertz`` 30, ``contactDampingRatio`` 10; twice the
hertz against static bodies; overlap pushed out at most ``maxContactPushSpeed`` 3 m/s), then
integrates positions and relaxes (solver.c, contact_solver.c); restitution is applied once
after the sub-steps, to points whose pre-solve normal velocity is at most
``-restitutionThreshold`` and that took an impulse.  No linear slop acts in the v3.1.1 contact
solver: a resting contact is held at separation 0 less the soft spring's sag.

Measured with the scene calls (one disc r 0.1 set on the ground, 3 s, every variant, dt 1/60,
1/240, 1e-3): it rests 6.9e-5 below touching, ``|g| / (2 pi 60)^2`` (the static softness at
twice 30 Hz), speed exactly 0 at the end; a column of three discs: the ground contact 2.1e-4,
the contact under two discs 1.1e-3 (``2 x 2 |g| / (2 pi 30)^2``: two discs' weight on a
dynamic pair of effective mass m/2), the top one 5.5e-4.  Declared: ``rest_gap`` (0, 0) and
``rest_sink_s2`` ``4 / (2 pi 30)^2``: two discs' weight on a disc-disc contact; a taller column
sinks more (the bound is per contact, as Box2D v2's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from crosscheck.core.contract import Conventions

CONTACT_HERTZ = 30.0
"""``b2WorldDef.contactHertz`` (b2DefaultWorldDef, types.c)."""
REST_SINK_S2 = 4.0 / (2.0 * math.pi * CONTACT_HERTZ) ** 2
"""Two discs' weight (m each) on a disc-disc soft contact of effective mass m / 2, stiffness
``(2 pi contactHertz)^2`` per unit mass: the sag is ``4 |g| / (2 pi 30)^2``."""
WALL_RESTITUTION = (
    "max of the shapes' restitutions (b2DefaultRestitutionCallback, world.c): a wall's shape "
    "gets e like every disc, so a disc-wall contact bounces with e when its pre-solve "
    "approach is at least restitutionThreshold (1 m/s) and it took an impulse "
    "(contact_solver.c)")
B2_HUGE = 100_000.0
"""``B2_HUGE`` (constants.h): 100 km, Box2D's bound on a sensible position; the tuned
variants' maximum linear speed (m/s), so that no case meets the cap."""


@dataclass(frozen=True, slots=True)
class Variant:
    """What a variant sets (None: Box2D's default)."""

    dt: float
    friction: float | None
    fixed_rotation: bool
    sleep: bool
    max_speed: float | None
    sub_steps: int = 4
    bullet: bool = False
    """Every disc a bullet (``b2BodyDef.isBullet``): swept against static, kinematic and
    non-bullet dynamic bodies, not against other bullets (solver.c
    ``b2ContinuousQueryCallback`` skips them; simulation.md)."""


DEFAULTS = Variant(dt=0.0, friction=None, fixed_rotation=False, sleep=True, max_speed=None)
"""What a scene of the default variant is built with: Box2D's defaults (dt: the scene's)."""


def scene_settings(tuning: Variant | None) -> dict[str, Any]:
    """A variant's inputs to the scene calls besides the scene (None: Box2D's defaults).

    >>> s = scene_settings(None)
    >>> s["sub_steps"], s["sleep"], s["friction"], s["max_speed"]
    (4, True, None, None)
    """
    v = DEFAULTS if tuning is None else tuning
    return {"friction": v.friction, "fixed_rotation": v.fixed_rotation, "sleep": v.sleep,
            "sub_steps": v.sub_steps, "bullet": v.bullet, "max_speed": v.max_speed}


def with_walls(conventions: Conventions, variant: Variant) -> Conventions:
    """``conventions`` with the gravity-and-walls fields of ``variant``: resting contacts held
    at separation 0 less the soft contact's sag, sleeping as set."""
    return replace(conventions, rest_gap=(0.0, 0.0), rest_sink_steps=0.0,
                   rest_sink_s2=REST_SINK_S2, sleeps=variant.sleep,
                   wall_restitution=WALL_RESTITUTION)
