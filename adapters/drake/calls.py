"""Drake's calls (the ``drake`` engine), plain data in and out.

A ``SceneGraph`` with one source, two frames ``a`` and ``b`` and one geometry on each (a
``Box``, which takes full widths: 2 x the half-widths, or a ``Sphere``), both with the
proximity role, and the scene graph's own context.  The case's centres are the frames'
poses (identity rotation), given as a ``FramePoseVector`` fixed on the source's pose port;
the geometries sit at their frames' origins.  The ask evaluates the query output port and
makes two queries of the ``QueryObject``:

- ``ComputeSignedDistancePairwiseClosestPoints()`` (``max_distance`` infinite, its default:
  every pair is reported): ``distance`` is the pair's signed distance (negative when the
  geometries overlap), ``normal`` is ``-nhat_BA_W`` when Drake's ``id_A`` is the case's A
  (``nhat_BA_W`` points from Drake's B to its A; the harness's normal points from A to B),
  ``nhat_BA_W`` as is when Drake ordered the pair the other way;
- ``ComputePointPairPenetration()``: ``hit`` is whether it reports the pair.

Nothing is built per case once a process has asked one pair of each geometry: ``release``
puts the scene back in an idle pool (``IDLE_LIMIT`` at most per geometry), and the next build
of that geometry takes it, changes its shapes in the context (``SceneGraph.ChangeShape``)
where the sizes differ, and fixes the new poses.  A scene is built anew only when none is
idle.

pydrake turns a failed Drake assertion (``DRAKE_THROW_UNLESS``, as in the ``Box`` and
``Sphere`` constructors, or ``DRAKE_DEMAND``, as in the box-box gradient at touching) into
``SystemExit``, which would end the process: :func:`_shape` raises it as a ``ValueError``
and the ask as a ``RuntimeError``, with Drake's message.  (``DRAKE_UNREACHABLE`` aborts the
process: nothing can catch it.)
"""

import math
from typing import Any

import numpy as np
from pydrake.geometry import (
    Box,
    FramePoseVector,
    GeometryFrame,
    GeometryInstance,
    ProximityProperties,
    SceneGraph,
    Sphere,
)
from pydrake.math import RigidTransform

Answer = dict[str, Any]
Vec = tuple[float, ...]

IDLE_LIMIT = 4
"""Idle scenes kept per geometry (a process asks one pair at a time)."""
_IDLE: dict[str, list[dict[str, Any]]] = {}


def _shape(geometry: str, size: Vec) -> Any:
    """A ``Box`` of full widths ``size`` or a ``Sphere`` of radius ``size[0]``; Drake's
    refusal (``SystemExit`` from its assertion) as a ``ValueError``."""
    try:
        return Box(*size) if geometry == "box" else Sphere(size[0])
    except SystemExit as exc:  # pydrake's translation of DRAKE_THROW_UNLESS
        raise ValueError(f"Drake refuses the shape: {exc}") from None


def _new(geometry: str, sizes: tuple[Vec, Vec]) -> dict[str, Any]:
    """A scene graph with frames a and b, each with one proximity geometry, and a context."""
    scene = SceneGraph()
    source = scene.RegisterSource("crosscheck")
    frames, ids = [], []
    for name, size in zip("ab", sizes, strict=True):
        frame = scene.RegisterFrame(source, GeometryFrame(name))
        geometry_id = scene.RegisterGeometry(
            source, frame, GeometryInstance(RigidTransform(), _shape(geometry, size), name))
        scene.AssignRole(source, geometry_id, ProximityProperties())
        frames.append(frame)
        ids.append(geometry_id)
    return {"scene": scene, "source": source, "frames": tuple(frames), "ids": tuple(ids),
            "context": scene.CreateDefaultContext(), "sizes": sizes, "geometry": geometry}


def _pair(geometry: str, sizes: tuple[Vec, Vec], a_center: Vec, b_center: Vec
          ) -> dict[str, Any]:
    """The scene: an idle one of the same geometry with the case's shapes, else a new one;
    the case's centres fixed as its frames' poses."""
    idle = _IDLE.get(geometry)
    built = idle.pop() if idle else _new(geometry, sizes)
    scene, context = built["scene"], built["context"]
    for geometry_id, old, size in zip(built["ids"], built["sizes"], sizes, strict=True):
        if old != size:
            scene.ChangeShape(context, built["source"], geometry_id, _shape(geometry, size))
    built["sizes"] = sizes
    poses = FramePoseVector()
    for frame, centre in zip(built["frames"], (a_center, b_center), strict=True):
        translation = np.array(centre, dtype=np.float64)
        poses.set_value(frame, RigidTransform(translation))  # type: ignore[arg-type]
    scene.get_source_pose_port(built["source"]).FixValue(context, poses)
    return built


def boxes(a_center: Vec, a_half: Vec, b_center: Vec, b_half: Vec) -> dict[str, Any]:
    """Two boxes (full widths 2 x the half-widths)."""
    sa, sb = (tuple(2.0 * h for h in half) for half in (a_half, b_half))
    return _pair("box", (sa, sb), a_center, b_center)


def spheres(a_center: Vec, a_radius: float, b_center: Vec, b_radius: float) -> dict[str, Any]:
    """Two spheres."""
    return _pair("sphere", ((a_radius,), (b_radius,)), a_center, b_center)


def release(built: dict[str, Any]) -> None:
    """The scene back to its geometry's idle pool (dropped beyond ``IDLE_LIMIT``)."""
    idle = _IDLE.setdefault(built["geometry"], [])
    if len(idle) < IDLE_LIMIT and all(built is not other for other in idle):
        idle.append(built)


def collide_and_distance(built: dict[str, Any]) -> Answer:
    """The penetration verdict, the signed distance and its normal (A to B)."""
    query = built["scene"].get_query_output_port().Eval(built["context"])
    a_id = built["ids"][0]
    try:
        (pair,) = query.ComputeSignedDistancePairwiseClosestPoints()
        hit = len(query.ComputePointPairPenetration()) > 0
    except SystemExit as exc:  # pydrake's translation of a failed DRAKE_DEMAND
        raise RuntimeError(f"Drake's internal check failed: {exc}") from None
    sign = -1.0 if pair.id_A == a_id else 1.0  # nhat_BA_W points from Drake's B to its A
    values = tuple(sign * float(x) + 0.0 for x in pair.nhat_BA_W)
    distance = float(pair.distance)
    normal: Vec | str = values
    if not all(math.isfinite(x) for x in values):
        normal = (f"Drake gives no finite normal ({', '.join(f'{x:g}' for x in values)}) "
                  f"with distance {distance:.3g}")
    return {"hit": hit, "distance": distance, "normal": normal}
