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

Scene: a new ``PhysicsWorld`` (gravity 0) with the variant's ``IntegrationParameters`` (its
``dt`` replaced by the scene's, ``num_solver_iterations`` the scene's if given); one dynamic
body per sphere (tuned or default builders, ``ccd_enabled`` when ``ccd``; a 2-D scene keeps
to z = 0) with a ball collider of restitution e; then the scene's gravity and one fixed body
with a ``HalfSpace`` collider per wall (the variant's material, restitution e).  Numbers
float32 cannot hold raise ``OverflowError``.  The ask times only ``PhysicsWorld.step`` and
reads ``translation`` / ``linvel`` (a quarantined body raises).  What was measured:
:mod:`adapters.rapier.scene`.

What the pairs, responses and scenes share:
- tuned bodies: no sleeping, soft CCD (``soft_ccd_prediction`` :data:`SOFT_CCD`), rotations
  locked, no damping; default bodies: only a centre and a velocity;
- a 2-D body keeps to the plane z = 0 (z translation locked);
- tuned balls: friction 0, a restitution combined by a named rule; default balls: a mass
  and a restitution;
- a ``PhysicsWorld`` with gravity 0 and ``IntegrationParameters`` overrides.
"""

import time
from typing import Any

from adapters.shared import approach_speed, no_contact, to3, z_half
from adapters.shared.scene import (
    check_scene,
    check_surroundings,
    in_scene_dim,
    scene_answer,
    step_and_record,
)

SOFT_CCD = 1e30
"""Tuned bodies' ``soft_ccd_prediction``: no bound on the predictive reach of a step."""


def tuned_body(centre: Any, velocity: Any) -> Any:
    """The tuned variant's body: no sleeping, soft CCD, rotations locked, no damping."""
    import rapier3d as rp

    return (rp.RigidBody.dynamic().translation(centre).linvel(velocity).can_sleep(False)
            .soft_ccd_prediction(SOFT_CCD).locked_axes(rp.LockedAxes.ROTATION_LOCKED)
            .linear_damping(0.0).angular_damping(0.0))


def default_body(centre: Any, velocity: Any) -> Any:
    """The default variant's body: only its centre and velocity."""
    import rapier3d as rp

    return rp.RigidBody.dynamic().translation(centre).linvel(velocity)


def in_plane(builder: Any, dim: int) -> Any:
    """A 2-D body keeps to the plane z = 0 (z translation locked); a 3-D one is unchanged."""
    return builder.enabled_translations((True, True, False)) if dim == 2 else builder


def tuned_collider(radius: float, mass: float, restitution: float,
                   rule: str = "MULTIPLY") -> Any:
    """The tuned variant's ball: friction 0, ``restitution`` combined by ``rule`` (the name
    of a ``CoefficientCombineRule``)."""
    import rapier3d as rp

    return (rp.Collider.ball(radius).mass(mass).friction(0.0).restitution(restitution)
            .restitution_combine_rule(getattr(rp.CoefficientCombineRule, rule)))


def default_collider(radius: float, mass: float, restitution: float) -> Any:
    """The default variant's ball: its mass and restitution, the rest rapier's defaults."""
    import rapier3d as rp

    return rp.Collider.ball(radius).mass(mass).restitution(restitution)


def new_world(parameters: tuple[tuple[str, float], ...]) -> Any:
    """A ``PhysicsWorld`` with gravity 0 and these ``IntegrationParameters`` overrides."""
    import rapier3d as rp

    world = rp.PhysicsWorld(gravity=(0.0, 0.0, 0.0))
    params = world.integration_parameters
    for key, value in parameters:
        setattr(params, key, value)
    return world


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


F32_MAX = 3.4028234663852886e38
"""The largest finite float32 (rapier's ``Real``): a scene's numbers must fit in it."""


def scene_parameters(parameters: tuple[tuple[str, float], ...], dt: float,
                     iterations: int | None) -> tuple[tuple[str, float], ...]:
    """A scene world's ``IntegrationParameters``: the variant's, then dt and iterations."""
    settings = [(k, v) for k, v in parameters if k != "dt"]
    settings.append(("dt", dt))
    if iterations is not None:
        settings.append(("num_solver_iterations", iterations))
    return tuple(settings)


def _check_f32(bodies: tuple[Any, ...], restitution: float, gravity: Vec,
               walls: tuple[Any, ...]) -> None:
    """``OverflowError`` for a number float32 cannot hold (rapier would read it as inf)."""
    for i, (center, radius, mass, velocity) in enumerate(bodies):
        for x in (*center, radius, mass, *velocity):
            if abs(x) > F32_MAX:
                raise OverflowError(f"body {i}: {x!r} is beyond float32's largest finite value")
    if restitution > F32_MAX:
        raise OverflowError(f"restitution {restitution!r} is beyond float32's range")
    named = [("gravity", g) for g in gravity]
    named += [(f"wall {k} offset", offset) for k, (_, offset) in enumerate(walls)]
    for name, x in named:
        if abs(x) > F32_MAX:
            raise OverflowError(f"{name} {x!r} is beyond float32's largest finite value")


def _wall_collider(normal: Vec, offset: float, restitution: float, tuned: bool,
                   rule: str) -> Any:
    rp = engine()
    n = to3(normal)
    builder = rp.Collider.halfspace(n).translation((offset * n[0], offset * n[1], offset * n[2]))
    builder = builder.restitution(restitution)
    if tuned:
        builder = (builder.friction(0.0)
                   .restitution_combine_rule(getattr(rp.CoefficientCombineRule, rule)))
    return builder


def scene(bodies: tuple[Any, ...], dim: int, restitution: float, dt: float,
          iterations: int | None, gravity: Vec, walls: tuple[Any, ...], steps: int,
          record_every: int, parameters: tuple[tuple[str, float], ...], tuned: bool,
          rule: str, ccd: bool) -> dict[str, Any]:
    """The scene's world (see the module docstring)."""
    check_scene(bodies, dim, restitution, dt)
    check_surroundings(gravity, walls, dim)
    _check_f32(bodies, restitution, gravity, walls)
    if iterations is not None and iterations < 1:
        raise ValueError(f"iterations must be >= 1, got {iterations}")
    world = new_world(scene_parameters(parameters, dt, iterations))
    handles = []
    for center, radius, mass, velocity in bodies:
        if tuned:
            builder = tuned_body(to3(center), to3(velocity))
            if ccd:
                builder = builder.ccd_enabled(True)
            collider = tuned_collider(radius, mass, restitution, rule)
        else:
            builder = default_body(to3(center), to3(velocity))
            collider = default_collider(radius, mass, restitution)
        handles.append(world.add_body(in_plane(builder, dim), [collider]))
    rp = engine()
    if any(gravity):
        world.gravity = rp.Vec3(*to3(gravity))
    if walls:
        world.add_body(rp.RigidBody.fixed(), [
            _wall_collider(normal, offset, restitution, tuned, rule) for normal, offset in walls])
    return {"world": world, "handles": tuple(handles), "dim": dim, "dt": dt, "steps": steps,
            "record_every": record_every, "bodies": bodies, "gravity": gravity, "walls": walls}


def step_scene(built: dict[str, Any], clock: Any = time.perf_counter) -> Answer:
    """Step the scene to its end (only ``PhysicsWorld.step`` is timed, by ``clock``): the
    final state, the measures and the trajectory."""
    world, dim = built["world"], built["dim"]

    def read() -> tuple[Any, Any]:
        if not world.quarantine.is_empty():
            raise FloatingPointError(f"rapier quarantined a body whose state became "
                                     f"non-finite ({world.quarantine})")
        bodies = [world.rigid_bodies[h] for h in built["handles"]]
        return (in_scene_dim(dim, (b.translation.to_tuple() for b in bodies), "position"),
                in_scene_dim(dim, (b.linvel.to_tuple() for b in bodies), "velocity"))

    wall_s, records = step_and_record(world.step, read, built["steps"], built["record_every"],
                                      clock)
    return scene_answer(built["bodies"], built["gravity"], built["walls"], built["dt"],
                        built["steps"], read(), records, wall_s)


def release_scene(built: dict[str, Any]) -> None:
    """Empty the scene's world (``PhysicsWorld.clear``: its bodies and colliders go)."""
    built["world"].clear()
