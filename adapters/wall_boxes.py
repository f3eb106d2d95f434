"""Static walls as thick boxes, for the 2-D scene runners (``pymunk_scene``, ``box2d_scene``).

What it is for: pymunk and Box2D have no half-space shape, and their users model a ground as
a static box (or a segment / edge) on a static body.  :func:`slabs` turns each
:class:`adapters.scene.Wall` into such a box, :class:`Slab`, the same way for both engines:

- thickness ``THICKNESS`` x the largest radius (at least the largest radius), on the solid
  side, so that nothing tunnels through it: a disc would have to move that far in a step;
- sideways ``SIDEWAYS`` x the scene's extent on each side of the scene's centre (the extent:
  the widest span, over the axes, of the discs' extents and the walls' surfaces), so that a
  disc of the scene never reaches an edge or a corner of a wall;
- the box is held relative to an ``anchor``, the point of the wall's surface sideways at the
  scene's centre: its surface is at coordinate exactly 0 relative to the anchor (``centre``
  is ``-normal * thickness / 2``, ``half`` the box's half sizes, so ``centre + half`` along
  the normal is 0 in any binary float format).  A float32 engine (Box2D) puts a static body
  at the anchor with the box in its frame: the face a disc rests on is then exact and does
  not depend on the box's size, which only enters the far edges and corners' arithmetic
  (about 1e4 x the extent, far within float32's range).  A float64 engine (pymunk) can use
  the box's world corners (:meth:`Slab.corners`), whose surface coordinate is the wall's
  offset exactly.

Walls are static: the engines never collide two static bodies (or two shapes of one static
body), so the overlapping corners of a box's walls do nothing.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from adapters.scene import Body, Wall

THICKNESS = 1000.0
"""A wall box's thickness, in units of the scene's largest radius."""
SIDEWAYS = 1e4
"""How far a wall box reaches sideways from the scene's centre, in units of its extent."""


@dataclass(frozen=True)
class Slab:
    """A wall as an axis-aligned box: its ``anchor`` (the point of the surface sideways at
    the scene's centre), its centre relative to the anchor and its half sizes.

    >>> s = Slab(anchor=(0.0, 0.0), centre=(0.0, -5.0), half=(100.0, 5.0))
    >>> s.corners()
    ((-100.0, -10.0), (100.0, 0.0))
    """

    anchor: tuple[float, ...]
    centre: tuple[float, ...]
    half: tuple[float, ...]

    def corners(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The box's lowest and highest corners in world coordinates (float64; along the
        normal the surface is ``anchor`` exactly, the far face ``anchor -+ thickness``)."""
        lo, hi = [], []
        for a, c, h in zip(self.anchor, self.centre, self.half, strict=True):
            lo.append(a if c > 0 else a + c - h)  # c > 0: the surface is the low face
            hi.append(a if c < 0 else a + c + h)  # c < 0: the surface is the high face
        return tuple(lo), tuple(hi)


def extent(bodies: Sequence[Body], walls: Sequence[Wall]) -> tuple[tuple[float, ...], float]:
    """The scene's centre and extent: the middle and the widest span of the box holding
    every disc (centre +- radius) and every wall's surface along its axis.

    >>> extent([((1.0, 2.0), 0.5, 1.0, (0.0, 0.0))], [Wall((0.0, 1.0), 0.0)])
    ((1.0, 1.25), 2.5)
    """
    dim = len(bodies[0][0]) if bodies else len(walls[0].normal)
    lo, hi = [float("inf")] * dim, [-float("inf")] * dim
    for center, radius, _, _ in bodies:
        for k in range(dim):
            lo[k], hi[k] = min(lo[k], center[k] - radius), max(hi[k], center[k] + radius)
    for wall in walls:
        k = wall.axis
        surface = wall.offset * wall.normal[k]
        lo[k], hi[k] = min(lo[k], surface), max(hi[k], surface)
    spans = [h - low for low, h in zip(lo, hi, strict=True) if h >= low]
    centre = tuple((low + h) / 2 if h >= low else 0.0 for low, h in zip(lo, hi, strict=True))
    return centre, max(spans, default=0.0)


def slabs(bodies: Sequence[Body], walls: Sequence[Wall]) -> tuple[Slab, ...]:
    """Every wall as a :class:`Slab` (see the module docstring for the sizes).

    >>> ground = Wall((0.0, 1.0), 0.0)
    >>> s, = slabs([((0.0, 0.1), 0.1, 1.0, (0.0, 0.0))], [ground])
    >>> s.anchor, s.centre, s.half
    ((0.0, 0.0), (0.0, -50.0), (2000.0, 50.0))
    """
    if not walls:
        return ()
    largest = max((radius for _, radius, _, _ in bodies), default=1.0)
    centre, span = extent(bodies, walls)
    thickness = THICKNESS * largest
    reach = SIDEWAYS * max(span, largest)
    made = []
    for wall in walls:
        k, sign = wall.axis, wall.normal[wall.axis]
        anchor = tuple(wall.offset * sign if j == k else centre[j] for j in range(len(centre)))
        middle = tuple(-sign * thickness / 2 if j == k else 0.0 for j in range(len(centre)))
        half = tuple(thickness / 2 if j == k else reach for j in range(len(centre)))
        made.append(Slab(anchor, middle, half))
    return tuple(made)
