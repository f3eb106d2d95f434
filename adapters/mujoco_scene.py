"""MuJoCo 4.0.0 stepping a scene of N spheres, for comparison with an exact event-driven run.

What it is for: the scene runners step a whole scene (N spheres, one restitution, in open
space or under gravity between static walls) with a fixed ``dt`` and return the final state
(and, asked, the recorded trajectory), to be scored against the exact reference;
:mod:`adapters.mujoco` answers single pair cases instead.  Types and input checks are
shared with the other scene runners in :mod:`adapters.scene`.

Building (``prepare_scene``, untimed): one model per scene, compiled from MJCF
(``adapters.shared.mujoco.scene_mjcf``: the pair's world, one free body with an explicit
inertial and one sphere geom per body, and one static ``plane`` geom per wall,
:mod:`adapters.mujoco_walls`),
``opt.gravity`` the scene's (open space: 0, the model unchanged), its ``MjData`` given the
centres (2-D: z = 0) and velocities (2-D: vz = 0, no spin).  ``run_scene`` times only
``mj_step`` through ``adapters.scene.step_and_record``: without recording the whole run is
its one step (one call with ``nstep`` = steps x substeps, as before); with ``record_every``
each scene step is one call of ``substeps``, the state read (untimed) between them.  A
MuJoCo warning (a bad value makes ``mj_step`` reset the state) is raised; ``release_scene``
drops the model.

MuJoCo has no coefficient of restitution (see :mod:`adapters.mujoco_response`): a contact is
a soft constraint, a spring-damper acting over many steps.

Variants (``tuning``, passed in by the adapter: a :class:`Tuning` or None):

- tuned (``mujoco``, :class:`Tuning`): the stiff contact of the response adapter
  (``mujoco_response.tune_stiff_model``: frictionless ``condim`` 1, RK4, solver tolerance
  1e-15, ``solimp`` flat at mjMAXIMP, geom margin 2^-1022 so a touching contact is active)
  with one direct ``solref`` (-w0^2, -2 zeta w0) for every geom: zeta gives the scene's e
  (``mujoco_response.damping_ratio``; e = 0 and e > 1 have no spring-dashpot and are
  refused), and ``w0`` makes a contact last exactly one scene step dt, so an impact is over
  within the step it starts in, as an impulse engine resolves it.  The restitution of a
  linear spring-dashpot does not depend on speed or masses, so every pair gets e.  MuJoCo's
  time step is dt / ``substeps`` (:data:`SUBSTEPS` RK4 steps per contact): a scene step is
  ``substeps`` calls of ``mj_step``, the pattern of MuJoCo users' "control step" (MuJoCo has
  no sub-step option).  Inertia = mass: no rotation takes part without friction.
- default (``mujoco-default``, None): only what the scene declares: the time step dt
  (``opt.timestep``, one ``mj_step`` per scene step), ``opt.iterations`` if given (else
  MuJoCo's 100), masses (inertia 2/5 m r^2, a solid sphere's), radii, velocities.  The
  scene's e is not read: MuJoCo's default soft contact (solref 0.02 1, solimp 0.9 0.95 0.001
  0.5 2), friction 1, condim 3, Euler.

Conventions, measured with this module on 4.0.0 (sources in ``adapters.mujoco.SOURCES``):

- 2-D: spheres at z = 0 with vz = 0 on free joints; contact normals between centres in the
  plane lie in it, but the solver works in all 6 N degrees of freedom and leaves rounding
  noise in z (measured: -6e-18 in a default 5-ball cradle at dt 1e-3, friction acting; the
  tuned head-on pair stays exactly at 0).  Noise within ``PLANE`` (2^-40, as
  ``mujoco_response``) x the scene's scale (largest |coordinate| + radius for positions,
  largest speed for velocities) is dropped; beyond it ``run_scene`` raises (left the plane).
- restitution, tuned: the equal-mass head-on pair of the suite (speeds 1) at e = 1 leaves
  within 5.1e-4 of the exchanged velocities at every dt from 1e-5 to 0.1 (declared
  :data:`TUNED_RTOL` 1e-3; 16 sub-steps: 2.7e-5, 32: 1.5e-6); at e = 0.5 within 2.8e-2
  (the contact starts inside a sub-step, so its damping starts late: first order in the
  sub-step).  Momentum is kept to rounding (equal and opposite constraint forces; 1e-12
  pinned in tests/adapters/test_mujoco.py).  Default: e is not read; that pair leaves at
  +-0.1353 (e = 1 and e = 0.25 alike, bit for bit).
- no restitution threshold (the spring-dashpot acts at any speed), no speed cap (MuJoCo
  has none), no damping (joint damping, viscosity, density 0 by default), no sleeping:
  sleeping is the opt-in enable flag ``mjENBL_SLEEP`` (``opt.enableflags`` 0 by default,
  read on 4.0.0), never set here.
- touching at the start: tuned, a contact (margin 2^-1022: distance 0 is active); a ball
  at 1 touching a ball at rest hands over its velocity within the first scene step (left
  at 1.0e-4 and 0.9999 after it, dt 1e-3), a touching pair moving together at 0.3 stays
  together (velocities within 5e-13 after 100 steps).  Default: no force at distance 0
  (margin 0: ``exclude`` = distance >= margin, engine_collision_driver.c): after step 1
  the velocities are unchanged (1, 0), the push comes once they overlap.
- simultaneous contacts are solved together: 5-ball cradle (equal masses, e = 1, striker
  at 1, dt 1e-3, 1 s): tuned, striker -0.5999, the four +0.3998 to +0.4001, one elastic hit
  on a mass-4 block, as PyBullet's; energy kept to 2.3e-4.  Default: 0.075, 0.209, 0.227,
  0.240, 0.248 (momentum 1 to rounding, energy 0.22 of it).  Not the textbook cradle.
- soft contact: a contact lasts one scene step (tuned) or the default solref's 0.02 s time
  constant (default), so centres lag the exact run by about the closing speed x that time.
- walls and gravity (:mod:`adapters.mujoco_walls`): a wall is an infinite plane geom (a
  half-space for collisions) with the spheres' contact parameters in each variant (tuned:
  the scene's e, frictionless; default: MuJoCo's defaults); a resting sphere sinks by the
  soft contact's steady penetration, declared from MuJoCo's solref/solimp formulas.  A 2-D
  scene's plane check scales with the larger of the start's and the current in-plane
  magnitudes (gravity speeds bodies up); 2-D walls have their normal in the plane.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from adapters.mujoco_response import damping_dashpot
from adapters.mujoco_walls import plane_of
from adapters.scene import (
    Body,
    SceneRun,
    State,
    Surroundings,
    check_scene,
    check_steps,
    check_surroundings,
    in_scene_dim,
    step_and_record,
)
from adapters.shared.mujoco import PLANE, WARNINGS, Mass, engine, scene_mjcf, tune_stiff_model

__all__ = ["Body", "SceneRun", "Tuning", "prepare_scene", "release_scene", "run_scene"]


SUBSTEPS = 8
"""MuJoCo steps per scene step in the tuned variant (the RK4 steps of one contact)."""
TUNED_RTOL = 1e-3
"""The tuned variant's restitution precision on an isolated head-on pair (measured)."""


@dataclass(frozen=True)
class Tuning:
    """The tuned variant's settings; ``None`` instead of a Tuning: MuJoCo's defaults.

    ``substeps``: MuJoCo steps per scene step (each contact lasts one scene step).
    """

    substeps: int = SUBSTEPS


@dataclass(frozen=True, eq=False)
class Prepared:
    """A built scene: its model and data, the MuJoCo steps per scene step, the dimension."""

    model: Any
    data: Any
    substeps: int
    dim: int
    count: int
    scales: tuple[float, float]
    """Position and velocity scales of a 2-D scene's plane check (see the module docstring)."""
    radius: float = 0.0
    """The largest radius (the plane check's position scale adds it to a centre)."""
    plane: float = PLANE
    """The plane check's relative bound: :data:`PLANE` in open space, :data:`WALLED_PLANE`
    with gravity or walls."""


WALLED_PLANE = 2.0**-30
"""A 2-D scene with gravity or walls keeps to z = 0 within this share of its scales: resting
contacts and wall bounces, solved in all 6 N degrees of freedom for many steps, leave
rounding noise in z far above :data:`PLANE` (measured on 4.0.0: 1.5e-13 m/s in a resting
column at dt 1/60).  It is a bound, not a cure: on free joints the noise grows, and a 60 s
gas in a box leaves it (2e-9 m/s in z): that run is an error, the scene left its plane
(slide joints would hold it; not done here)."""


def stiff_solref(restitution: float, dt: float) -> tuple[float, float]:
    """Direct solref (-w0^2, -2 zeta w0) of a spring-dashpot with restitution e lasting dt.

    >>> k, b = stiff_solref(1.0, 0.5)  # undamped: half a period is pi / w0 = dt
    >>> round((-k) ** 0.5 * 0.5 / 3.141592653589793, 12), b
    (1.0, -0.0)
    """
    if not 0.0 < restitution <= 1.0:
        raise ValueError(f"restitution {restitution!r} outside (0, 1]: MuJoCo's direct solref "
                         "has no spring-dashpot for it")
    zeta, duration = damping_dashpot(restitution)
    w0 = duration / dt
    return -w0 * w0, -2.0 * zeta * w0


def model_of(bodies: Sequence[Body], restitution: float, dt: float, iterations: int | None,
             tuning: Tuning | None, surroundings: Surroundings | None = None) -> Any:
    """The scene's compiled model with the variant's settings (see the module docstring)."""
    def mass(radius: float, m: float) -> Mass:
        return (m, (m,) * 3) if tuning is not None else (m, (0.4 * m * radius * radius,) * 3)

    extra = ' condim="1"' if tuning is not None else ""
    spheres = [(radius, mass(radius, m)) for _, radius, m, _ in bodies]
    walls = surroundings.walls if surroundings is not None else ()
    planes = [plane_of(wall) for wall in walls]
    try:
        model = engine().MjModel.from_xml_string(scene_mjcf(spheres, extra, planes, extra))
    except ValueError as exc:
        raise ValueError(f"MuJoCo's compiler refuses this scene: {exc}") from None
    if iterations is not None:
        model.opt.iterations = iterations
    model.opt.timestep = dt
    if surroundings is not None:
        model.opt.gravity[:] = (*surroundings.gravity, 0.0, 0.0)[:3]
    if tuning is not None:
        tune_stiff_model(model)  # every geom, the planes too
        model.opt.timestep = dt / tuning.substeps
        model.geom_solref[:] = stiff_solref(restitution, dt)
    return model


def prepare_scene(bodies: Sequence[Body], dim: int, restitution: float, dt: float,
                  iterations: int | None, tuning: Tuning | None,
                  surroundings: Surroundings | None = None) -> Any:
    """Build the scene's model and data (untimed).

    ``tuning``: the variant's settings (see :class:`Tuning`), or None for MuJoCo's defaults.
    ``surroundings``: gravity and static walls (None: open space, the model as before).
    """
    check_scene(bodies, dim, restitution, dt)
    around = check_surroundings(surroundings, dim)
    model = model_of(bodies, restitution, dt, iterations, tuning, around)
    data = engine().MjData(model)
    pad = (0.0,) * (3 - dim)
    for i, (center, _, _, velocity) in enumerate(bodies):
        data.qpos[7 * i:7 * i + 7] = (*center, *pad, 1.0, 0.0, 0.0, 0.0)
        data.qvel[6 * i:6 * i + 6] = (*velocity, *pad, 0.0, 0.0, 0.0)
    engine().mj_forward(model, data)
    substeps = tuning.substeps if tuning is not None else 1
    reach = max((abs(x) + r for c, r, _, _ in bodies for x in c), default=0.0)
    speed = max((abs(x) for _, _, _, v in bodies for x in v), default=0.0)
    # gravity is a speed scale too: a body at rest carries up to |g| dt between solves
    speed = max(speed, math.hypot(*around.gravity) * dt)
    radius = max((r for _, r, _, _ in bodies), default=0.0)
    plane = PLANE if surroundings is None else WALLED_PLANE
    return Prepared(model, data, substeps, dim, len(bodies), (reach, speed), radius, plane)


def read_state(scene: Prepared) -> State:
    """Every centre and velocity in the scene's dimension (a copy, float64).

    A 2-D scene's plane check (see the module docstring) scales with the larger of the
    start's and the current state's in-plane magnitudes: gravity speeds bodies up.
    """
    d, dim = scene.data, scene.dim
    qpos = d.qpos.reshape(scene.count, 7)[:, :3]
    qvel = d.qvel.reshape(scene.count, 6)[:, :3]
    reach, speed = scene.scales
    if dim == 2 and scene.count:
        reach = max(reach, float(np.abs(qpos[:, :2]).max()) + scene.radius)
        speed = max(speed, float(np.abs(qvel[:, :2]).max()))
    return (in_scene_dim(dim, qpos, "position", scene.plane * reach),
            in_scene_dim(dim, qvel, "velocity", scene.plane * speed))


def run_scene(prepared: Any, steps: int, clock: Callable[[], float] = time.perf_counter,
              record_every: int = 0) -> SceneRun:
    """Step the scene ``steps`` times (only ``mj_step`` is timed, read from ``clock`` just
    before and just after it) and read its final state.

    ``record_every`` > 0: also record the state at the start and every ``record_every``
    steps (:func:`adapters.scene.step_and_record`; reading is not timed).  Without it the
    whole run is one ``mj_step(m, d, steps x substeps)`` call, as before.
    """
    scene: Prepared = prepared
    check_steps(steps)
    mujoco, m, d = engine(), scene.model, scene.data
    WARNINGS.clear()
    if record_every > 0:
        def step() -> None:
            mujoco.mj_step(m, d, scene.substeps)

        wall, samples = step_and_record(step, lambda: read_state(scene), steps, record_every,
                                        clock)
    else:
        def whole() -> None:
            mujoco.mj_step(m, d, steps * scene.substeps)

        wall, samples = step_and_record(whole, lambda: read_state(scene), min(steps, 1), 0,
                                        clock)
    if d.warning.number.any():
        raise RuntimeError(f"MuJoCo warned while stepping, and a bad value resets the state: "
                           f"{' | '.join(WARNINGS) or 'no message'}")
    positions, velocities = read_state(scene)
    return SceneRun(tuple(map(tuple, positions)), tuple(map(tuple, velocities)), wall, steps,
                    samples)


def release_scene(prepared: Any) -> None:
    """Nothing to free: the model and data go with the last reference to them."""
