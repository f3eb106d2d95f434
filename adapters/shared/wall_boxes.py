"""Static walls as thick boxes, for the 2-D engines' scene calls (pymunk, Box2D), plain data.

pymunk and Box2D have no half-space shape, and their users model a ground as a static box on a
static body.  :func:`slabs` turns each wall (``(normal, offset)``, solid where ``normal . x <
offset``) into such a box, the same way for both engines:

- thickness ``THICKNESS`` x the largest radius, on the solid side, so that nothing tunnels
  through it: a disc would have to move that far in a step;
- sideways ``SIDEWAYS`` x the scene's extent on each side of the scene's centre (the extent:
  the widest span, over the axes, of the discs' extents and the walls' surfaces), so that a
  disc of the scene never reaches an edge or a corner of a wall;
- the box is held relative to an ``anchor``, the point of the wall's surface sideways at the
  scene's centre: its surface is at coordinate exactly 0 relative to the anchor (``centre`` is
  ``-normal * thickness / 2``, ``half`` the box's half sizes, so ``centre + half`` along the
  normal is 0 in any binary float format).  A float32 engine (Box2D) puts a static body at the
  anchor with the box in its frame: the face a disc rests on is then exact.  A float64 engine
  (pymunk) uses the box's world corners (:func:`corners`), whose surface coordinate is the
  wall's offset exactly.

Walls are static: the engines never collide two static bodies, so the overlapping corners of
a box's walls do nothing.  Only the standard library: a repro script includes this source.

>>> s, = slabs([((0.0, 0.1), 0.1, 1.0, (0.0, 0.0))], [((0.0, 1.0), 0.0)])
>>> s
((0.0, 0.0), (0.0, -50.0), (2000.0, 50.0))
>>> corners(s)
((-2000.0, -100.0), (2000.0, 0.0))
"""

from collections.abc import Sequence
from typing import Any

THICKNESS = 1000.0
"""A wall box's thickness, in units of the scene's largest radius."""
SIDEWAYS = 1e4
"""How far a wall box reaches sideways from the scene's centre, in units of its extent."""
Slab = tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]
"""A wall as an axis-aligned box: ``(anchor, centre, half)``: the point of the surface
sideways at the scene's centre, the box's centre relative to it and its half sizes."""


def _axis(normal: Sequence[float]) -> int:
    return next(k for k, n in enumerate(normal) if n != 0.0)


def corners(slab: Slab) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The box's lowest and highest corners in world coordinates (float64; along the normal
    the surface is ``anchor`` exactly, the far face ``anchor -+ thickness``)."""
    lo, hi = [], []
    for a, c, h in zip(*slab, strict=True):
        lo.append(a if c > 0 else a + c - h)  # c > 0: the surface is the low face
        hi.append(a if c < 0 else a + c + h)  # c < 0: the surface is the high face
    return tuple(lo), tuple(hi)


def extent(bodies: Sequence[Any], walls: Sequence[Any]) -> tuple[tuple[float, ...], float]:
    """The scene's centre and extent: the middle and the widest span of the box holding every
    disc (centre +- radius) and every wall's surface along its axis."""
    dim = len(bodies[0][0]) if bodies else len(walls[0][0])
    lo, hi = [float("inf")] * dim, [-float("inf")] * dim
    for center, radius, _, _ in bodies:
        for k in range(dim):
            lo[k], hi[k] = min(lo[k], center[k] - radius), max(hi[k], center[k] + radius)
    for normal, offset in walls:
        k = _axis(normal)
        surface = offset * normal[k]
        lo[k], hi[k] = min(lo[k], surface), max(hi[k], surface)
    spans = [h - low for low, h in zip(lo, hi, strict=True) if h >= low]
    centre = tuple((low + h) / 2 if h >= low else 0.0 for low, h in zip(lo, hi, strict=True))
    return centre, max(spans, default=0.0)


def slabs(bodies: Sequence[Any], walls: Sequence[Any]) -> tuple[Slab, ...]:
    """Every wall as a :data:`Slab` (see the module docstring for the sizes)."""
    if not walls:
        return ()
    largest = max((radius for _, radius, _, _ in bodies), default=1.0)
    centre, span = extent(bodies, walls)
    thickness = THICKNESS * largest
    reach = SIDEWAYS * max(span, largest)
    made = []
    for normal, offset in walls:
        k = _axis(normal)
        sign = normal[k]
        anchor = tuple(offset * sign if j == k else centre[j] for j in range(len(centre)))
        middle = tuple(-sign * thickness / 2 if j == k else 0.0 for j in range(len(centre)))
        half = tuple(thickness / 2 if j == k else reach for j in range(len(centre)))
        made.append((anchor, middle, half))
    return tuple(made)
