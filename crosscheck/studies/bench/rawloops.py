"""Raw engine loops for ``crosscheck bench``: each engine's own API, no harness around it.

These are the baselines the harness overhead is measured against.  Each loop
answers the same detection question as the adapter (verdict and signed
distance), the way a user of the engine would write it: geometry built from
plain numbers, then the engine's query, with nothing else per case.  The
inputs are plain tuples, converted outside the timed loop:

- ``spheres``: ``(pa, ra, pb, rb)``, centres as 3-lists for FCL and PyBullet,
  2-tuples for pymunk;
- ``boxes``: ``(ca, ha, cb, hb)`` with half-widths.

PyBullet cannot change a body's radius, so its loop resets the poses of bodies
made once per radius before timing (a reset is what a reused body costs).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from adapters.pybullet.calls import connect, engine

Pair = tuple[Sequence[float], Any, Sequence[float], Any]
Loop = Callable[[], None]


def fcl_loop(pairs: Sequence[Pair], boxes: bool) -> Loop:
    """Build two CollisionObjects per case, then collide and signed distance."""
    import fcl

    request = fcl.CollisionRequest(num_max_contacts=1, enable_contact=True)
    signed = fcl.DistanceRequest(enable_nearest_points=True, enable_signed_distance=True)
    sized = [(pa, [2.0 * h for h in sa] if boxes else sa, pb, [2.0 * h for h in sb]
              if boxes else sb) for pa, sa, pb, sb in pairs]

    def geometry(size: Any) -> Any:
        return fcl.Box(*size) if boxes else fcl.Sphere(size)

    def loop() -> None:
        for pa, sa, pb, sb in sized:
            a = fcl.CollisionObject(geometry(sa), fcl.Transform(pa))
            b = fcl.CollisionObject(geometry(sb), fcl.Transform(pb))
            fcl.collide(a, b, request, fcl.CollisionResult())
            fcl.distance(a, b, signed, fcl.DistanceResult())

    return loop


def pymunk_loop(pairs: Sequence[Pair], boxes: bool) -> Loop:
    """Build two static bodies and shapes per case, then ``shapes_collide``."""
    import pymunk

    def shape(centre: Sequence[float], size: Any) -> Any:
        body = pymunk.Body(body_type=pymunk.Body.STATIC)
        body.position = (centre[0], centre[1])
        made = (pymunk.Poly.create_box(body, (2.0 * size[0], 2.0 * size[1])) if boxes
                else pymunk.Circle(body, size))
        made.cache_bb()
        return made

    def loop() -> None:
        for pa, sa, pb, sb in pairs:
            try:  # noqa: SIM105 - suppress() costs a context manager per case
                shape(pa, sa).shapes_collide(shape(pb, sb))
            except AssertionError:  # pymunk's way of saying "no contact points"
                pass

    return loop


def pybullet_loop(pairs: Sequence[Pair]) -> tuple[Loop, Callable[[], None]]:
    """Reset two spheres' poses per case, then detect, read contacts and closest points.

    Returns the loop and a function that disconnects the client it made.
    """
    bt = engine()
    cid = connect({})
    bodies: dict[float, tuple[int, int]] = {}
    for radius in sorted({r for _, ra, _, rb in pairs for r in (ra, rb)}):
        sid = bt.createCollisionShape(bt.GEOM_SPHERE, radius=radius, physicsClientId=cid)
        bodies[radius] = tuple(
            bt.createMultiBody(baseMass=1.0, baseCollisionShapeIndex=sid,
                               basePosition=(0.0, 0.0, 10.0 * (k + 1) * (1 + radius)),
                               physicsClientId=cid) for k in range(2))
    work = [(bodies[ra][0], pa, bodies[rb][1], pb, 1.0 + 2.0 * math.dist(pa, pb))
            for pa, ra, pb, rb in pairs]
    identity = (0.0, 0.0, 0.0, 1.0)

    def loop() -> None:
        for a, pa, b, pb, bound in work:
            bt.resetBasePositionAndOrientation(a, pa, identity, physicsClientId=cid)
            bt.resetBasePositionAndOrientation(b, pb, identity, physicsClientId=cid)
            bt.performCollisionDetection(physicsClientId=cid)
            bt.getContactPoints(a, b, physicsClientId=cid)
            bt.getClosestPoints(a, b, bound, physicsClientId=cid)

    def close() -> None:
        bt.disconnect(physicsClientId=cid)

    return loop, close
