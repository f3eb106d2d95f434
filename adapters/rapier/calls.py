"""Rapier's calls through rapier3d (the ``rapier``, ``rapier-default`` and ``rapier-ccd`` pairs and
times of impact), plain data in and out.  Rapier is float32 (``Real`` = f32).

Detection: two standalone colliders (a ball, or a cuboid of half-extents; a 2-D box gets the
z half-width of the embedding), fixed, paired with ``ActiveCollisionTypes.all()``; each pass
inserts them in new sets and runs ``CollisionPipeline.step`` with a prediction distance.  The
verdict is ``has_any_active_contact`` at the variant's ``prediction``; distance and normal
are the deepest contact point of a pass whose prediction ``reach`` is past any gap (the
manifold's normal points from collider1 to collider2: negated when rapier stores the pair
as (B, A)), no value when rapier gives no contact point.

Response: each ask builds a new ``PhysicsWorld`` (gravity 0, the variant's
``IntegrationParameters``) with the two bodies (tuned or default builders; a 2-D body keeps
to z = 0) and steps up to the first step whose solver put a normal impulse on the pair
(``resolved_at``: the centres at its start), or until the bodies no longer approach (not
above ``tol``), ``max_steps`` at most.  A body rapier quarantined (a non-finite state)
raises, as does a 2-D result that left the plane.

Time of impact: ``QueryPipeline.cast_shape`` of A's ball with velocity va - vb against B's
ball at rest (B's frame), ``ShapeCastOptions(max_time_of_impact=duration, target_distance=0,
stop_at_penetration=True)``; the normal is minus ``normal1`` (B's outward normal at the hit,
pointing to A) as the engine gives it.
"""

from typing import Any

from adapters.shared import approach_speed, no_contact, to3, z_half
from adapters.shared.rapier import (
    default_body,
    default_collider,
    in_plane,
    new_world,
    tuned_body,
    tuned_collider,
)

Answer = dict[str, Any]
Vec = tuple[float, ...]


def engine() -> Any:
    """The ``rapier3d`` module, imported on first use."""
    import rapier3d

    return rapier3d


def _colliders(sa: Any, sb: Any, a_center: Vec, b_center: Vec, prediction: float,
               reach: float) -> dict[str, Any]:
    rp = engine()
    every = rp.ActiveCollisionTypes.all()  # standalone (fixed) colliders pair only so
    ca, cb = to3(a_center), to3(b_center)
    return {"a": rp.Collider.new(sa).translation(ca).active_collision_types(every).build(),
            "b": rp.Collider.new(sb).translation(cb).active_collision_types(every).build(),
            "prediction": prediction, "reach": reach, "dim": len(a_center),
            "pipeline": rp.CollisionPipeline()}


def cuboids(a_center: Vec, a_half: Vec, b_center: Vec, b_half: Vec, prediction: float,
            reach: float) -> dict[str, Any]:
    """Two cuboids (half-extents; a 2-D pair gets a z extent)."""
    rp = engine()
    extra = (z_half(a_half, b_half),) if len(a_center) == 2 else ()
    return _colliders(rp.SharedShape.cuboid(*a_half, *extra),
                      rp.SharedShape.cuboid(*b_half, *extra), a_center, b_center,
                      prediction, reach)


def balls(a_center: Vec, a_radius: float, b_center: Vec, b_radius: float, prediction: float,
          reach: float) -> dict[str, Any]:
    """Two balls."""
    rp = engine()
    return _colliders(rp.SharedShape.ball(a_radius), rp.SharedShape.ball(b_radius), a_center,
                      b_center, prediction, reach)


def _narrow(p: dict[str, Any], prediction: float) -> tuple[Any, bool]:
    """One collision-detection pass over fresh sets: the pair of A and B (or None) and whether
    rapier stored it as (B, A)."""
    rp = engine()
    colliders = rp.ColliderSet()
    ha, hb = colliders.insert(p["a"]), colliders.insert(p["b"])
    narrow = rp.NarrowPhase()
    p["pipeline"].step(prediction, rp.IslandManager(), rp.BroadPhaseBvh(), narrow,
                       rp.RigidBodySet(), colliders)
    pair = narrow.contact_pair(ha, hb)
    return pair, pair is not None and pair.collider1 != ha


def _deepest(pair: Any, flipped: bool) -> tuple[float, Vec] | None:
    """The smallest contact distance of the pair and its manifold's world normal, A to B."""
    best: tuple[float, Vec] | None = None
    for manifold in pair.manifolds if pair is not None else ():
        for point in manifold.points:
            if best is None or point.dist < best[0]:
                best = (float(point.dist), manifold.data.normal.to_tuple())
    if best is None:
        return None
    distance, normal = best
    return distance, ((-normal[0], -normal[1], -normal[2]) if flipped else normal)


def detect(p: dict[str, Any]) -> Answer:
    """The verdict at the variant's prediction distance; distance and normal from a pass whose
    prediction reaches past any gap."""
    verdict, _ = _narrow(p, p["prediction"])
    hit = verdict is not None and bool(verdict.has_any_active_contact)
    deepest = _deepest(*_narrow(p, p["reach"]))
    if deepest is None:
        none = f"rapier gave no contact point within prediction distance {p['reach']:.3g}"
        return {"hit": hit, "distance": none, "normal": none}
    distance, normal = deepest
    return {"hit": hit, "distance": distance, "normal": tuple(normal[:p["dim"]])}


def response(a_center: Vec, a_radius: float, a_mass: float, a_velocity: Vec, b_center: Vec,
             b_radius: float, b_mass: float, b_velocity: Vec, restitution: float, tuned: bool,
             parameters: tuple[tuple[str, float], ...], tol: float,
             max_steps: int) -> dict[str, Any]:
    """The builders of the two bodies (tuned: restitution A = e, B = 1 combined by product;
    default: both e, rapier's Average) and what a world is made with."""
    dim = len(a_center)
    bodies, colliders = [], []
    for centre, velocity, radius, mass, own in (
            (a_center, a_velocity, a_radius, a_mass, restitution),
            (b_center, b_velocity, b_radius, b_mass, 1.0)):
        make = tuned_body if tuned else default_body
        # the plane z = 0 is a 2-D case's plane: no motion out of it
        bodies.append(in_plane(make(to3(centre), to3(velocity)), dim))
        colliders.append(tuned_collider(radius, mass, own, "MULTIPLY") if tuned
                         else default_collider(radius, mass, restitution))
    return {"bodies": bodies, "colliders": colliders, "parameters": parameters, "dim": dim,
            "tol": tol, "max_steps": max_steps}


def _pushed(world: Any) -> bool:
    """Whether the last step's solver put a normal impulse on the contact between A and B."""
    return any(pair.total_impulse_magnitude() > 0.0 for pair in world.narrow_phase.contact_pairs())


def respond(p: dict[str, Any]) -> Answer:
    """Step a new world up to the first step whose solver pushed A and B apart, or until they
    no longer approach without having touched (or ``max_steps``)."""
    world = new_world(p["parameters"])
    handles = [world.add_body(body, [collider])
               for body, collider in zip(p["bodies"], p["colliders"], strict=True)]
    a, b = (world.rigid_bodies[h] for h in handles)
    resolved = None
    for _ in range(p["max_steps"]):
        pa, pb = a.translation.to_tuple(), b.translation.to_tuple()
        world.step()
        va, vb = a.linvel.to_tuple(), b.linvel.to_tuple()
        if _pushed(world):
            resolved = (pa, pb)  # the contact this step resolved was computed here
            break
        if not approach_speed(pa, pb, va, vb) > p["tol"]:  # NaN (coincident centres): stop
            break
    if not world.quarantine.is_empty():
        raise FloatingPointError(f"rapier quarantined a body whose state became non-finite "
                                 f"({world.quarantine})")
    if p["dim"] == 3:
        return {"v1": va, "v2": vb, "resolved_at": resolved}
    if abs(va[2]) > 0.0 or abs(vb[2]) > 0.0:
        raise RuntimeError(f"2-D response left the plane z = 0: vz = {va[2]!r}, {vb[2]!r}")
    at = None if resolved is None else (resolved[0][:2], resolved[1][:2])
    return {"v1": va[:2], "v2": vb[:2], "resolved_at": at}


def cast(a_center: Vec, a_radius: float, a_velocity: Vec, b_center: Vec, b_radius: float,
         b_velocity: Vec, duration: float) -> dict[str, Any]:
    """B's ball in a query pipeline; A's ball, pose and relative velocity; the options."""
    rp = engine()
    colliders = rp.ColliderSet()
    colliders.insert(rp.Collider.new(rp.SharedShape.ball(b_radius)).translation(to3(b_center))
                     .build())
    bodies = rp.RigidBodySet()
    pipeline = rp.QueryPipeline(rp.BroadPhaseBvh(), rp.NarrowPhase(), bodies, colliders)
    pipeline.update(bodies, colliders)
    velocity = to3(tuple(a - b for a, b in zip(a_velocity, b_velocity, strict=True)))
    options = rp.ShapeCastOptions(max_time_of_impact=duration, target_distance=0.0,
                                  stop_at_penetration=True,
                                  compute_impact_geometry_on_penetration=True)
    return {"pipeline": pipeline, "colliders": colliders, "shape": rp.SharedShape.ball(a_radius),
            "pose": rp.Isometry3(to3(a_center)), "velocity": velocity, "options": options,
            "dim": len(a_center)}


def cast_shape(p: dict[str, Any]) -> Answer:
    """The one ``cast_shape`` call."""
    found = p["pipeline"].cast_shape(p["pose"], p["velocity"], p["shape"], p["options"])
    if found is None:
        return no_contact()
    _, hit = found
    n = hit.normal1.to_tuple()
    return {"hit": True, "toi": float(hit.time_of_impact),
            "normal": tuple(-float(x) for x in n[:p["dim"]])}

