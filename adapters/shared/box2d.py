"""What Box2D's pair calls and its scene runner share: the lazy import, a world, a disc; plain,
so a repro script holds this source (until the scenes are calls of
:mod:`adapters.box2d.calls`, which then holds it).

A world has gravity 0 (a scene's gravity if it has one) and sleeping set with
``SetAllowSleeping`` (pybox2d's ``b2World(doSleep=...)`` only sets a Python attribute); a disc
is a dynamic body with one circle fixture of density 0 whose mass is then set exactly through
``massData`` (centre 0; moment ``m r^2 / 2`` when rotation is free, else 0 with
``fixedRotation``).
"""

from collections.abc import Sequence
from typing import Any


def engine() -> Any:
    """The ``Box2D`` module (pybox2d), imported on first use."""
    import Box2D  # type: ignore[import-untyped]

    return Box2D


def xy(v: Sequence[float]) -> tuple[float, float]:
    """The first two components of ``v`` as floats (a ``b2Vec2`` or a tuple)."""
    return (float(v[0]), float(v[1]))


def new_world(sleep: bool, gravity: Sequence[float] = (0.0, 0.0)) -> Any:
    """A ``b2World`` with ``gravity`` (none by default); sleeping on or off in Box2D itself."""
    world = engine().b2World(gravity=xy(gravity))
    world.SetAllowSleeping(sleep)  # not doSleep=: it only sets a Python attribute
    return world


def disc(world: Any, center: Sequence[float], velocity: Sequence[float], radius: float,
         mass: float, restitution: float, friction: float | None, fixed_rotation: bool,
         bullet: bool) -> Any:
    """A dynamic body at ``center`` with ``velocity`` and ``mass``, with one circle fixture
    (``friction`` None: Box2D's default)."""
    b2 = engine()
    body = world.CreateDynamicBody(position=xy(center), linearVelocity=xy(velocity),
                                   fixedRotation=fixed_rotation, bullet=bullet)
    extra = {} if friction is None else {"friction": friction}
    body.CreateCircleFixture(radius=radius, density=0.0, restitution=restitution, **extra)
    moment = 0.0 if fixed_rotation else 0.5 * mass * radius**2
    body.massData = b2.b2MassData(mass=mass, center=(0.0, 0.0), I=moment)
    return body
