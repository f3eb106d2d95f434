"""Dynamics scenes (kind ``sphere_scene``): exact truth, errors and allowances.

Why a quantity disagrees (the category and reason) is :mod:`crosscheck.truth.scene_rules`.

A scene is N spheres in open space with a restitution and a duration.  Its
block declares ``steps`` (time steps ``dt`` and, optionally, solver
``iterations``); :func:`crosscheck.cases.expand.expand_steps` makes one case
per combination.  An engine steps ``round(duration / dt)``
times; the truth is :func:`reference_impl.events.simulate` run to exactly
that many steps' worth of time, so no engine is blamed for a partial step.

Four quantities are scored, each as a relative (dimensionless) error:

- ``positions``: the largest distance between an engine's final centre and the
  reference's, in units of the mean radius;
- ``velocities``: the largest velocity difference over the largest initial speed;
- ``momentum``: the change of total momentum over ``sum m |v|`` at the start;
- ``energy``: the difference from the reference's final kinetic energy over the
  initial kinetic energy (for ``e = 1`` this is the energy drift).

The tolerance is :data:`~crosscheck.truth.score.DEFAULT_RTOL` unless the case sets one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from fractions import Fraction
from pathlib import Path
from typing import Any, cast

from crosscheck.core import disk_cache
from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, norm
from crosscheck.core.kinds import quantity_named
from crosscheck.core.model import Observation, Trajectory, Undefined, Value
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import scene_measures as sm
from reference_impl import events, gravity
from reference_impl.rounding import to_float

QUANTITIES = ("positions", "velocities", "momentum", "energy")
"""The final-state quantities (the measures are :data:`scene_measures.MEASURES`)."""


def simulated_time(case: SceneCase) -> Fraction:
    """Exactly the time an engine simulates: ``round(duration / dt)`` steps of ``dt``."""
    return case.step_count * Fraction(case.dt or DEFAULT_DT)


def truth(case: SceneCase) -> Observation:
    """The exact event-driven state at :func:`simulated_time`, as floats, and the measures."""
    key = case.model_dump_json(include={"bodies", "restitution", "dt", "duration", "gravity",
                                        "walls", "diverge_at", "dim"})
    if key not in _CACHE:
        if len(_CACHE) >= 256:
            _CACHE.pop(next(iter(_CACHE)))
        entry = _entry(key)
        found = disk_cache.get(*entry, _is_observation) if entry else None
        if not isinstance(found, Observation):
            found = _truth(case)
            if entry:
                disk_cache.put(*entry, found, DISK_LIMIT)
        _CACHE[key] = found
    return _CACHE[key]


_CACHE: dict[str, Observation] = {}

DISK_FORMAT = 1
"""The layout of a stored truth (an :class:`Observation` pickle); bump it if that changes."""
DISK_PACKAGES = ("crosscheck/core", "crosscheck/truth", "reference_impl")
"""The code a scene's exact run depends on: a change to any of it is a new key."""
DISK_LIMIT = 5000
"""Most stored truths kept (the suite has a few hundred scenes)."""


def _entry(key: str) -> tuple[Path, str] | None:
    """Where the exact run of the scene ``key`` is stored on disk (None: caching is off).

    The exact event-driven run of a long scene costs seconds and depends only on the scene
    and the reference's code, so it is kept in the harness's disk cache
    (:mod:`crosscheck.core.disk_cache`, sub-folder ``truths``): every run, report and test
    after the first reads it."""
    where = disk_cache.folder("truths")
    if where is None:
        return None
    return where, disk_cache.key(disk_cache.code_hash(DISK_PACKAGES, DISK_FORMAT), key.encode())


def _is_observation(value: object) -> bool:
    return isinstance(value, Observation)


OPEN_SPACE = "open space: no ground and no recorded trajectory"


def _truth(case: SceneCase) -> Observation:
    balls = [events.Ball(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
    end = simulated_time(case)
    dt = Fraction(case.dt or DEFAULT_DT)
    times = [k * dt for k in sm.sample_steps(case)]
    g = sm.gravity(case)
    walls = [events.Wall(w.normal, w.offset) for w in case.walls]
    try:
        if any(g):
            run = gravity.simulate(balls, walls, g, case.restitution, end, times)
            state, bounced, rest_since = run.state, run.bounces, run.rest_since
            samples = [events.FloatState(float(x.time), x.positions_float(),
                                         x.velocities_float()) for x in run.samples]
        else:
            samples = []
            state = events.simulate(balls, case.restitution, end, walls=walls,
                                    sample_times=times, samples=samples)
            bounced, rest_since = (), None
    except (RuntimeError, ValueError, ArithmeticError) as exc:
        return Observation.undefined(QUANTITIES + sm.MEASURES, f"no reference: {exc}")
    positions, velocities = state.positions_float(), state.velocities_float()
    start = [b.center for b in case.bodies]
    exact_drift = (gravity.energy(state, g, start) - events.kinetic_energy(balls)) / (
        Fraction(sm.energy_scale(case) or 1.0) * (end or 1))
    measures: dict[str, Any] = {
        "impacts": tuple(float(e.time) for e in state.events),
        "energy_drift": to_float(exact_drift)}
    measures.update(_exact_measures(case, state, bounced, rest_since, end))
    if samples:
        measures["trajectory"] = Trajectory(
            tuple(s.time for s in samples), tuple(s.positions for s in samples),
            tuple(s.velocities for s in samples),
            tuple(sm.total_energy(case, s.positions, s.velocities) for s in samples))
    return replace(observation(positions, velocities, [b.mass for b in case.bodies]),
                   **measures)


def _exact_measures(case: SceneCase, state: events.SceneState,
                    bounced: Sequence[tuple[Fraction, int, int, Fraction]],
                    rest_since: Fraction | None, end: Fraction) -> dict[str, Value]:
    """The exact settle, jitter, apex, bounce_time and divergence (or why undefined)."""
    floor = sm.ground(case)
    if not sm.surrounded(case):
        return {q: Undefined(OPEN_SPACE) for q in sm.MEASURES if q != "energy_drift"}
    out: dict[str, Value] = {"divergence": float(end)}
    if floor is None or rest_since is None:
        out["settle"] = Undefined("not every body rests on a ground at the end of the exact run")
    else:
        wall = case.walls[floor]
        out["settle"] = tuple(
            to_float(sum((Fraction(n) * x for n, x in zip(wall.normal, p, strict=True)),
                         Fraction()) - Fraction(wall.offset) - Fraction(b.radius))
            for p, b in zip(state.positions, case.bodies, strict=True))
    out["jitter"] = (0.0 if rest_since is not None and 2 * rest_since <= end else
                     Undefined("the exact run does not rest over the run's second half"))
    ground_bounces = [(t, i, u) for t, i, w, u in bounced if w == floor]
    if floor is None or not any(i == 0 for _, i, _ in ground_bounces):
        out["apex"] = out["bounce_time"] = Undefined("body 0 never bounces on a ground")
    else:
        apexes, times = sm.exact_bounces(case, ground_bounces)
        out["apex"], out["bounce_time"] = apexes, times
    return out


def observation(positions: Sequence[Vec], velocities: Sequence[Vec],
                masses: Sequence[float]) -> Observation:
    """A scene observation: final state, total momentum and kinetic energy (float64, fsum)."""
    dim = len(positions[0]) if positions else 0
    momentum = tuple(math.fsum(m * v[i] for m, v in zip(masses, velocities, strict=True))
                     for i in range(dim))
    energy = math.fsum(0.5 * m * math.fsum(x * x for x in v)
                       for m, v in zip(masses, velocities, strict=True))
    return Observation(positions=tuple(tuple(p) for p in positions),
                       velocities=tuple(tuple(v) for v in velocities),
                       momentum=momentum, energy=energy)



def _scales(case: SceneCase) -> dict[str, float]:
    """The scale of each quantity's error: the mean radius; the largest speed, sum m|v| and
    the kinetic energy at the start (with gravity or walls: the top speed a body reaches,
    sum m x that and :func:`~crosscheck.truth.scene_measures.energy_scale`)."""
    speeds = [norm(b.velocity) for b in case.bodies]
    masses = [b.mass for b in case.bodies]
    radius = math.fsum(b.radius for b in case.bodies) / max(1, len(case.bodies))
    if sm.surrounded(case):
        top = sm.top_speed(case)
        return {"positions": radius, "velocities": top, "momentum": math.fsum(masses) * top,
                "energy": sm.energy_scale(case)}
    return {
        "positions": radius,
        "velocities": max(speeds, default=0.0),
        "momentum": math.fsum(m * s for m, s in zip(masses, speeds, strict=True)),
        "energy": math.fsum(0.5 * m * s * s for m, s in zip(masses, speeds, strict=True)),
    }


def units(case: SceneCase, quantity: str) -> str:
    """The units of ``quantity``'s error in this scene, as its spec words them
    (:attr:`Quantity.words <crosscheck.core.kinds.Quantity.words>`; with gravity or walls the
    scales are the top speed, sum m x it and the energy scale: see :func:`_scales`), or its
    absolute unit where the scale is 0 (:attr:`Quantity.absolute
    <crosscheck.core.kinds.Quantity.absolute>`)."""
    named = quantity_named(quantity)
    return named.words if _scales(case)[quantity] > 0 else named.absolute


def gravity_step(case: SceneCase, quantity: str) -> float:
    """One step of gravity, ``|g| dt`` on every body, as a relative error of velocities or
    momentum (0 for other quantities or without gravity): what a body resting in a stepping
    engine may carry between its contact's solves."""
    g = norm(sm.gravity(case)) * (case.dt or DEFAULT_DT)
    scale = _scales(case).get(quantity, 0.0)
    if g == 0.0 or quantity not in ("velocities", "momentum"):
        return 0.0
    size = g if quantity == "velocities" else g * math.fsum(b.mass for b in case.bodies)
    return size / scale if scale > 0 else size


def relative_error(case: SceneCase, quantity: str, value: Value, want: Value) -> float:
    """The relative error of one scene quantity (see the module docstring)."""
    scale = _scales(case)[quantity]
    if quantity in ("positions", "velocities"):
        assert isinstance(value, tuple) and isinstance(want, tuple)
        if len(value) != len(want):
            return math.inf
        mine, theirs = cast(tuple[Vec, ...], value), cast(tuple[Vec, ...], want)
        diff = max((norm([x - y for x, y in zip(p, q, strict=True)])
                    for p, q in zip(mine, theirs, strict=True)), default=0.0)
    elif quantity == "momentum":
        assert isinstance(value, tuple) and isinstance(want, tuple)
        p, q = cast(Vec, value), cast(Vec, want)
        diff = norm([x - y for x, y in zip(p, q, strict=True)])
    else:
        assert isinstance(value, float | int) and isinstance(want, float | int)
        diff = abs(float(value) - float(want))
    if not math.isfinite(diff):
        return math.inf
    return diff / scale if scale > 0 else diff


def tolerance(case: SceneCase, quantity: str, default: float) -> float:
    """The case's own tolerance for ``quantity`` (relative), else ``default``."""
    own = case.tolerance
    if own is None:
        return default
    chosen = own.distance if quantity == "positions" else own.velocity
    return chosen if chosen is not None else default




def damping_bound(case: SceneCase, conventions: Conventions) -> float:
    """How much the engine's declared damping ``c`` can change a speed over the run.

    The drag measured for PyBullet is ``dv/dt = -c (1 + |v|) v``: at most a
    fraction ``1 - exp(-c (1 + v_top) T)`` of any speed over a run of ``T`` s.
    """
    top = max((norm(b.velocity) for b in case.bodies), default=0.0)
    return -math.expm1(-conventions.damping * (1.0 + top) * float(simulated_time(case)))


def extent(case: SceneCase) -> float:
    """The scene's largest |coordinate| (centres and wall offsets; 1 if none)."""
    coords = [abs(x) for b in case.bodies for x in b.center]
    coords += [abs(w.offset) for w in case.walls]
    return max(coords, default=1.0)


def mean_radius(case: SceneCase) -> float:
    """The bodies' mean radius (the unit of the positions' errors)."""
    return math.fsum(b.radius for b in case.bodies) / max(1, len(case.bodies))


def held(case: SceneCase, conventions: Conventions) -> float:
    """How far (m) the engine's declared precision alone can put a position: ``rtol`` (its
    ``Real``) of the scene's largest coordinate, :data:`PRECISION_FACTOR` times."""
    return PRECISION_FACTOR * conventions.rtol * (extent(case) + mean_radius(case))


def stepped_rounding(case: SceneCase) -> float:
    """How far (m) float64 rounding alone can carry a position over the run: one rounding of
    ``x + v dt`` per step, ``u`` of the scene's largest coordinate each (a deterministic
    bound of the arithmetic, not of the step's physics)."""
    return case.step_count * 2.0**-53 * (extent(case) + mean_radius(case))


def coarse(case: SceneCase, conventions: Conventions) -> str:
    """Why the engine's declared precision cannot hold the scene ('' when it can): its
    position precision at the scene's coordinates (:func:`held`) reaches the bodies' mean
    radius, so every quantity of the run is within what the precision allows."""
    reach, size = held(case, conventions), mean_radius(case)
    if not (conventions.rtol > 0 and reach >= size):
        return ""
    return (f"the engine's declared precision at these coordinates, {PRECISION_FACTOR:g} x "
            f"rtol {conventions.rtol:.3g} x {extent(case):.3g} = {reach:.3g} m, reaches the "
            f"bodies' mean radius {size:.3g} m: no position of the scene is held to its own "
            "size")


PRECISION_FACTOR = 2.0
"""How far, in units of the engine's declared relative precision ``rtol`` (its ``Real``:
``2**-21`` for a float32 engine), the scene's velocities, momentum and energy may be off
from the precision alone: each velocity component held to ``rtol`` of its size is at most
``sqrt(3) rtol`` of a speed off, and so of sum m|v| for the momentum; the kinetic energy,
a square, ``2 rtol + rtol**2``."""


def step_travel(case: SceneCase) -> float:
    """Per-step travel of a scene's first two bodies: ``|vb - va| dt / (2 (ra + rb))``.

    The fraction of the overlap window (the ``2 (ra + rb)`` along the line of centres in
    which two spheres closing head-on overlap) that they cross in one step: beyond 1 a
    head-on pair can cross it between two steps, and an engine that only looks for
    contacts at the steps never sees them touch.
    """
    return pair_travel(case.bodies[0], case.bodies[1], case.dt or DEFAULT_DT)


def pair_travel(a: Any, b: Any, dt: float) -> float:
    """Per-step travel of two bodies (anything with a ``velocity`` and a ``radius``):
    ``|vb - va| dt / (2 (ra + rb))``."""
    closing = norm([x - y for x, y in zip(a.velocity, b.velocity, strict=True)])
    return float(closing * dt / (2.0 * (a.radius + b.radius)))


def largest_step_travel(case: SceneCase) -> float:
    """The per-step travel of the scene's fastest pair at the start (:func:`pair_travel` of
    every two bodies; 0 for one body): for two bodies, :func:`step_travel`.

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> scene = CASE_ADAPTER.validate_python({"id": "s", "description": "d",
    ...     "kind": "sphere_scene", "dim": 2, "duration": 1.0, "dt": 0.1, "bodies": [
    ...     {"center": [0, 0], "radius": 0.5, "mass": 1, "velocity": [1, 0]},
    ...     {"center": [3, 0], "radius": 0.5, "mass": 1, "velocity": [-1, 0]},
    ...     {"center": [9, 0], "radius": 0.5, "mass": 1, "velocity": [0, 0]}]})
    >>> round(largest_step_travel(scene), 12), round(step_travel(scene), 12)
    (0.1, 0.1)
    """
    dt, bodies = case.dt or DEFAULT_DT, case.bodies
    return max((pair_travel(a, b, dt) for i, a in enumerate(bodies) for b in bodies[i + 1:]),
               default=0.0)


def aligned(case: SceneCase, impacts: Sequence[float]) -> list[float]:
    """The impact times of the exact run that fall on a step boundary ``k dt`` (to 1e-9 dt).

    An engine that resolves contacts at step boundaries then meets such an
    impact exactly on time: its error at that ``dt`` says nothing of its step
    lag.  The suite's scenes avoid it; a reason flags any case that does not.

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> scene = CASE_ADAPTER.validate_python({"id": "s", "description": "d",
    ...     "kind": "sphere_scene", "dim": 2, "duration": 1.0, "dt": 0.1, "bodies": []})
    >>> aligned(scene, [0.0, 0.5, 0.55])
    [0.5]
    """
    dt = case.dt or DEFAULT_DT  # contacts present at the start are met at step 0 by everyone
    return [t for t in impacts
            if t > 0 and abs(t / dt - round(t / dt)) <= 1e-9 * max(1.0, t / dt)]
