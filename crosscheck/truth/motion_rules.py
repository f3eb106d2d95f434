"""Why a motion measure disagrees (``apex``, ``bounce_time``, ``energy_drift``,
``divergence``): each against one event's bound or a declared value, never a sum over the run.

- ``apex``, ``bounce_time``: the drop's bounces, each from the engine's own previous state
  (:mod:`crosscheck.truth.drop_rules`); the row cites its own worst event;
- ``energy_drift``: a drop's bounces; a two-body run in open space
  (:mod:`crosscheck.truth.scene_runs`: its drift against that run's, within the precision
  and the declared damping); then the declared soft or predictive bounce, restitution
  threshold or damping for a loss (``convention``), the precision (``tolerance``: ``2 rtol``
  of the kinetic energy and the potential energy of a position held to the precision, over
  the run); step lag never explains an energy change (an elastic impact met late is still
  elastic);
- ``divergence``: the precision, a drop's bounces, then a chaotic scene whose trajectory
  stays within one step's travel of the exact one through its first impact (``timestep``:
  that one event's lag, which the impacts after it amplify); else ``error``.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import cast

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, approach_speed, norm
from crosscheck.core.kinds import quantity_named
from crosscheck.core.model import Category, Observation, Value
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import drop_rules, scene_runs
from crosscheck.truth import scene_measures as sm
from crosscheck.truth.scenes import (
    PRECISION_FACTOR,
    damping_bound,
    held,
    mean_radius,
    simulated_time,
)
from reference_impl import events


def apex(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
         want: Value, err: float, truth: Observation, observed: Observation
         ) -> tuple[str, str]:
    drop = drop_rules.sequence(case, conventions, observed, truth)
    what = f"apex off by {err:.3g} (relative) over {len(cast(Vec, want))} exact bounces"
    if drop is None:
        return Category.ERROR, f"{what}: the engine's bounces could not be read"
    return drop.category, f"{what}: {drop.why}"


def bounce_time(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
                want: Value, err: float, truth: Observation, observed: Observation
                ) -> tuple[str, str]:
    mine, exact = cast(Vec, value), cast(Vec, want)
    what = (f"bounce times off by up to {err:.3g} s ({len(mine)} bounces recorded, "
            f"{len(exact)} exact)")
    drop = drop_rules.sequence(case, conventions, observed, truth)
    if drop is None:
        return Category.ERROR, f"{what}: the engine's bounces could not be read"
    worst = drop.worst_interval
    timing = f"; worst time: {worst}" if worst is not None else ""
    return drop.category, f"{what}: {drop.why}{timing}"


def drift_precision(case: SceneCase, conventions: Conventions) -> float:
    """What the declared precision allows the energy drift (per s): ``2 rtol`` of the
    kinetic energy and ``m |g|`` times a position held to the precision, over the energy
    scale and the run."""
    scale = sm.energy_scale(case) or 1.0
    g = norm(sm.gravity(case))
    kinetic = math.fsum(0.5 * b.mass * math.fsum(v * v for v in b.velocity)
                        for b in case.bodies)
    top = sm.top_speed(case)
    kinetic = max(kinetic, math.fsum(0.5 * b.mass * top * top for b in case.bodies))
    potential = math.fsum(b.mass for b in case.bodies) * g * held(case, conventions)
    rtol = PRECISION_FACTOR * conventions.rtol
    return (rtol * (2.0 + rtol) * kinetic + potential) / (
        scale * float(simulated_time(case) or 1))


def _only_lost(value: Value, want: Value, tol: float) -> bool:
    return float(cast(float, value)) <= float(cast(float, want)) + tol


def energy_drift(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
                 want: Value, err: float, truth: Observation, observed: Observation,
                 tol: float = 0.0) -> tuple[str, str]:
    what = f"energy_drift off by {err:.3g} {quantity_named(quantity).words}"
    drop = drop_rules.sequence(case, conventions, observed, truth)
    if drop is not None:
        return drop.category, f"{what}: the run's bounces decide it: {drop.why}"
    run = _run(case, conventions, value, what, observed, truth)
    if run is not None:
        return run
    lost = _only_lost(value, want, tol)
    duration = float(simulated_time(case) or 1)
    if conventions.bounce_may_lose and lost:
        return Category.CONVENTION, (
            f"{what}, all of it lost: the engine's declared {conventions.restitution_model} "
            "contact model sets the bounce, not the scene's e, and keeps no more than it")
    below = unbounced(case, conventions, truth) if lost else ""
    if below:
        return Category.CONVENTION, f"{what}, all of it lost: {below}"
    damp = damping_bound(case, conventions)
    reach = damp * (2.0 - damp) / duration
    if conventions.damping > 0 and lost and err <= reach:
        return Category.CONVENTION, (
            f"{what}, all of it lost, within the {reach:.3g} the declared damping can remove "
            f"({conventions.damping:g} per s: up to {damp:.3g} of a speed over the run)")
    precision = drift_precision(case, conventions)
    if err <= precision:
        return Category.TOLERANCE, (
            f"{what}, within the engine's declared precision: {PRECISION_FACTOR:g} x rtol "
            f"{conventions.rtol:.3g} of the kinetic energy and of the positions, over the "
            f"energy scale and the {duration:.3g} s run = {precision:.3g}")
    return Category.ERROR, (f"{what}: beyond the precision {precision:.3g}; an impact met a "
                            "step late is still elastic, and no declared damping, threshold "
                            "or soft contact takes it")


def _impact_speeds(case: SceneCase, truth: Observation) -> list[float]:
    """The exact normal speeds of body 0's recorded bounces (from the exact apexes); without
    gravity, the closing speed of the exact run's first impact (the pair that touches then,
    in free flight until it)."""
    g = norm(sm.gravity(case))
    if g == 0:
        first = truth.impacts[0] if truth.impacts else None
        return [] if first is None else _first_closing(case, first)
    apexes = truth.apex if isinstance(truth.apex, tuple) else ()
    return [math.sqrt(2 * g * h) for h in apexes]


def _first_closing(case: SceneCase, t: float) -> list[float]:
    """The closing speed, along their line of centres, of the pair of spheres nearest to
    touching at ``t`` (the bodies in free flight until then)."""
    at = [[p + v * t for p, v in zip(b.center, b.velocity, strict=True)] for b in case.bodies]
    best: tuple[float, float] | None = None
    for i, a in enumerate(case.bodies):
        for j in range(i + 1, len(case.bodies)):
            b = case.bodies[j]
            closing = approach_speed(at[i], at[j], a.velocity, b.velocity)
            gap = abs(math.dist(at[i], at[j]) - a.radius - b.radius)
            if closing > 0 and (best is None or gap < best[0]):  # NaN: coincident centres
                best = (gap, closing)
    return [] if best is None else [best[1]]


def below_threshold(case: SceneCase, conventions: Conventions, truth: Observation) -> str:
    """Why an impact of the run closes below the declared restitution threshold ('' if none
    need): the words for a loss of energy that the threshold explains.  An engine that takes
    the bounce from the approach at the step's start (declared ``bounce_from_step_start``)
    meets the threshold with a fall up to one step of gravity, ``|g| dt``, slower than its
    impact."""
    speeds = _impact_speeds(case, truth)
    threshold = conventions.restitution_threshold
    early = (norm(sm.gravity(case)) * (case.dt or DEFAULT_DT)
             if conventions.bounce_from_step_start else 0.0)
    if not (threshold > 0 and case.restitution > 0 and speeds
            and min(speeds) < threshold + early):
        return ""
    if min(speeds) < threshold:
        return (f"impacts close at down to {min(speeds):.3g} m/s, below the declared "
                f"restitution threshold {threshold:g} m/s (no bounce below it)")
    return (f"impacts close at down to {min(speeds):.3g} m/s, within |g| dt = {early:.3g} m/s "
            f"of the declared restitution threshold {threshold:g} m/s, which the engine "
            "compares with the approach at the step's start (declared "
            "bounce_from_step_start): no bounce below it")


_EVENTS: dict[str, tuple[events.Event, ...]] = {}


def _events(case: SceneCase) -> tuple[events.Event, ...]:
    """The exact run's impacts with their bodies (open space or walls, no gravity)."""
    key = case.model_dump_json(include={"bodies", "restitution", "dt", "duration", "walls",
                                        "dim"})
    if key not in _EVENTS:
        if len(_EVENTS) >= 64:
            _EVENTS.pop(next(iter(_EVENTS)))
        balls = [events.Ball(b.center, b.radius, b.mass, b.velocity) for b in case.bodies]
        walls = [events.Wall(w.normal, w.offset) for w in case.walls]
        _EVENTS[key] = events.simulate(balls, case.restitution, simulated_time(case),
                                       walls=walls).events
    return _EVENTS[key]


def chained(case: SceneCase, conventions: Conventions) -> str:
    """Why the engine's run gives a bounce of the exact run none ('' if it need not): under
    a declared ``bounce_from_step_start`` the bounce is taken from the approach at the
    step's start, so an impact of the exact run less than a step after another one of the
    same body (a chain: a pair that begins approaching within the step) may get none."""
    if not (conventions.bounce_from_step_start and case.restitution > 0
            and not any(case.gravity or ()) and (len(case.bodies) > 2 or case.walls)):
        return ""
    dt = Fraction(case.dt or DEFAULT_DT)
    seen: dict[int, events.Event] = {}
    for event in _events(case):
        bodies = [k for k in (event.i, event.j) if k < len(case.bodies)]  # walls are static
        for k in bodies:
            before = seen.get(k)
            if before is not None and event.time - before.time < dt:
                return (
                    f"the exact run's impact of bodies {event.i} and {event.j} at t = "
                    f"{float(event.time):.4g} s comes {float(event.time - before.time):.3g} s "
                    f"after body {k}'s impact at t = {float(before.time):.4g} s, less than a "
                    f"step (dt = {float(dt):.3g} s): the engine takes a bounce from the "
                    "approach at the step's start, once per contact (declared "
                    "bounce_from_step_start), so a pair set approaching within the step, "
                    "as in a chain, may get none")
        for k in bodies:
            seen[k] = event
    return ""


def unbounced(case: SceneCase, conventions: Conventions, truth: Observation) -> str:
    """Why the engine's run may give an impact of the exact run no bounce ('' if none):
    the declared restitution threshold (:func:`below_threshold`) or a chain within a step
    under a declared ``bounce_from_step_start`` (:func:`chained`)."""
    return below_threshold(case, conventions, truth) or chained(case, conventions)


def _run(case: SceneCase, conventions: Conventions, value: Value, what: str,
         observed: Observation, truth: Observation) -> tuple[str, str] | None:
    """The drift against the two-body run the engine gave (its energy is that run's)."""
    fit = scene_runs.find(case, conventions, observed, truth)
    if fit is None or not isinstance(fit.state.energy, float):
        return None
    duration = float(simulated_time(case) or 1)
    scale = sm.energy_scale(case) or 1.0
    start = math.fsum(0.5 * b.mass * math.fsum(v * v for v in b.velocity)
                      for b in case.bodies)
    theirs = (fit.state.energy - start) / (scale * duration)
    off = abs(float(cast(float, value)) - theirs)
    return fit.judged(what, "drift", off, fit.slack(case, conventions, "energy") / duration,
                      conventions)


def first_departure(case: SceneCase, conventions: Conventions, observed: Observation,
                    truth: Observation) -> tuple[float, float, float] | None:
    """Through the exact run's first impact (and one step after it): the largest distance
    of a recorded centre from the exact one, its bound (one step's travel at the top speed
    plus the precision), and the impact's time.  None without trajectories or impacts."""
    mine, exact, impacts = observed.trajectory, truth.trajectory, truth.impacts
    if mine is None or exact is None or not impacts:
        return None
    dt = case.dt or DEFAULT_DT
    until = impacts[0] + dt
    far = 0.0
    for t, ps, qs in zip(mine.times, mine.positions, exact.positions, strict=False):
        if t > until:
            break
        far = max([far] + [norm([x - y for x, y in zip(p, q, strict=True)])
                           for p, q in zip(ps, qs, strict=True)])
    bound = sm.top_speed(case) * dt + held(case, conventions)
    return far, bound, impacts[0]


def divergence(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
               want: Value, err: float, truth: Observation, observed: Observation
               ) -> tuple[str, str]:
    t = float(cast(float, value))
    reach = case.diverge_at * mean_radius(case)
    what = (f"the trajectory left {case.diverge_at:g} mean radii ({reach:.3g} m) of the exact "
            f"one at t = {t:.4g} s ({err:.3g} of the run)")
    if reach <= held(case, conventions):
        return Category.TOLERANCE, (f"{what}: within the engine's declared precision there "
                                    f"({held(case, conventions):.3g} m: {PRECISION_FACTOR:g} x "
                                    f"rtol {conventions.rtol:.3g} of the coordinates)")
    drop = drop_rules.sequence(case, conventions, observed, truth)
    if drop is not None:
        return drop.category, f"{what}: the run's bounces decide it: {drop.why}"
    first = first_departure(case, conventions, observed, truth)
    if first is None:
        return Category.ERROR, f"{what}, before any impact of the exact run"
    far, bound, when = first
    impacts = [x for x in (truth.impacts or ()) if x <= t]
    if far <= bound:
        return Category.TIMESTEP, (
            f"{what}: through the first impact (t = {when:.4g} s) it stays within {far:.3g} m "
            f"of the exact one, inside one step's travel at the top speed {bound:.3g} m (that "
            f"impact seen a step late); the {len(impacts)} impacts up to t part the "
            "trajectories further, each from the other's state")
    return Category.ERROR, (f"{what}: already {far:.3g} m off through the first impact (t = "
                            f"{when:.4g} s), beyond one step's travel at the top speed "
                            f"{bound:.3g} m")
