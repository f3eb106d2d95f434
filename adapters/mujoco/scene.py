"""MuJoCo 4.0.0 stepping a scene of N spheres: the scene's model, its walls, and what was measured.

What it is for: a scene (N spheres, one restitution, in open space or under gravity between
static walls) is stepped with a fixed ``dt`` by the scene calls of :mod:`adapters.mujoco.calls`
(``scene``, ``step_scene``).  Here: the variant's settings (:class:`Tuning`), the scene's
model (:func:`scene_model`, MJCF, and :func:`stiff_solref`), the walls and their resting
conventions (:class:`Rest`), and what was measured with those calls.  Checks and recording
are shared (:mod:`adapters.shared.scene`).

Building (``scene``, untimed): one model per scene, compiled from MJCF
(``adapters.mujoco.calls.scene_mjcf``: the pair's world, one free body with an explicit
inertial and one sphere geom per body, and one static ``plane`` geom per wall,
below),
``opt.gravity`` the scene's (open space: 0, the model unchanged), its ``MjData`` given the
centres (2-D: z = 0) and velocities (2-D: vz = 0, no spin).  ``step_scene`` times only
``mj_step`` through ``adapters.shared.scene.step_and_record``: without recording the whole
run is its one step (one call with ``nstep`` = steps x substeps, as before); with ``record_every``
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

Conventions, measured with the scene calls on 4.0.0 (sources in ``adapters.mujoco.SOURCES``):

- 2-D: spheres at z = 0 with vz = 0 on free joints; contact normals between centres in the
  plane lie in it, but the solver works in all 6 N degrees of freedom and leaves rounding
  noise in z (measured: -6e-18 in a default 5-ball cradle at dt 1e-3, friction acting; the
  tuned head-on pair stays exactly at 0).  Noise within ``PLANE`` (2^-40, as
  ``mujoco_response``) x the scene's scale (largest |coordinate| + radius for positions,
  largest speed for velocities) is dropped; beyond it ``step_scene`` raises (left the plane).
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
- walls and gravity (below): a wall is an infinite plane geom (a
  half-space for collisions) with the spheres' contact parameters in each variant (tuned:
  the scene's e, frictionless; default: MuJoCo's defaults); a resting sphere sinks by the
  soft contact's steady penetration, declared from MuJoCo's solref/solimp formulas.  A 2-D
  scene's plane check scales with the larger of the start's and the current in-plane
  magnitudes (gravity speeds bodies up); 2-D walls have their normal in the plane.

Gravity and static walls: plane geoms, and how deep a resting sphere sinks.  A scene's wall
is built as MuJoCo's users model a ground, and :mod:`adapters.mujoco` declares each variant's
resting-contact conventions from the rules written here.

A wall is a ``plane`` geom of the world body (``adapters.mujoco.calls.SCENE_PLANE``):
MuJoCo's plane is "infinite for collision detection purposes" [XMLreference, body-geom-type] and a
half-space: ``mjraw_PlaneSphere`` (engine_collision_primitive.c) gives a contact at
``dist = (c - pos) . n - r`` however deep the centre is, with ``n`` the plane's local z axis.
So nothing tunnels and no size is chosen; MuJoCo is float64, so no box precision is lost
either.  The plane's position is ``offset x normal``; its orientation is an exact
quaternion of the tetrahedral group (components 0, +-1/2, +-1) that turns z onto the
normal (:func:`plane_quat`): MJCF's ``zaxis="0 1 0"`` compiles to a quaternion with
``sqrt(1/2)`` and leaves a normal (0, 1, 2.2e-16), which tilts a 2-D ground out of the plane
z = 0 (measured on 4.0.0).  Planes belong to the world body, so they never collide with each
other (geoms of one body are never paired).  Gravity is ``opt.gravity`` (2-D: z = 0).

Contact parameters of a wall are the spheres': each variant gives the plane geom what it
gives the sphere geoms, and MuJoCo mixes the two geoms' ``solref`` / ``solimp`` by
``solmix`` (an average of equal values), takes the larger ``condim``, friction and margin
[modeling.rst, Contact parameters]; so a sphere-wall contact is a sphere-sphere contact:

- tuned (``mujoco``): ``condim`` 1, margin 2^-1022, flat ``solimp`` mjMAXIMP and the direct
  ``solref`` (-w0^2, -2 zeta w0) giving the scene's e (:func:`stiff_solref`): a wall
  bounces with the scene's e.  Friction 0 (frictionless contact).
- default (``mujoco-default``): the plane keeps MuJoCo's defaults like the spheres
  (solref 0.02 1, solimp 0.9 0.95 0.001 0.5 2, friction 1, condim 3, margin 0): the
  scene's e is not read, for walls as for spheres.

Resting sink.  MuJoCo's contact is soft: at rest the constrained acceleration
``a1 = d aref + (1 - d) a0`` [computation, soParameters] vanishes, with ``aref = -K d (r -
margin)`` (``mj_referenceConstraint``: ``-K*I*(pos-margin)``; ``mj_makeImpedance`` in
engine_core_constraint.c) and ``a0 = -|g|``, so the steady penetration is
``|g| (1 - d) / (K d^2)``:

- standard solref (timeconst, dampratio): ``K = 1 / (dw^2 tc^2 dr^2)`` (dw = solimp[1]),
  penetration ``|g| (1 - d) dw^2 tc^2 dr^2 / d^2`` ("r = a0 (1 - d) timeconst^2 dampratio^2"
  for a constant d = dw [modeling.rst, CSolverReference]).  The default solimp's d rises
  from d0 = 0.9 at the surface to 0.95 at the width 1 mm, and ``(1 - d) / d^2`` falls with
  d, so d0 gives the largest: ``DEFAULT_SINK_S2`` = 0.1 x 0.95^2 x 0.02^2 / 0.9^2 =
  4.46e-5 s^2 (0.437 mm at 9.81), whatever g.  At g = 9.81 the fixed point (d at that
  depth) is 3.74e-5 s^2, 0.367 mm (:func:`soft_rest_sink`).  ``refsafe`` (on by default)
  raises timeconst to 2 dt (``getsolparam``), so for dt > 0.01 s the bound is
  ``DEFAULT_SINK_STEPS`` = 0.1 x 0.95^2 x 2^2 / 0.9^2 = 0.446 |g| dt^2 instead: declared as
  ``rest_sink_steps`` beside ``rest_sink_s2`` (the sink is |g| times the larger of the two;
  their sum over-allows by at most 2x).
- direct solref (tuned): ``K = w0^2 / dw^2`` and d = dw = mjMAXIMP, so the penetration is
  ``|g| (1 - mjMAXIMP) / w0^2`` ("r = a0 (1 - d) / stiffness" [modeling.rst]); w0 = t_c / dt
  (t_c the contact's duration in units of 1 / w0, ``mujoco_response.dashpot``): a sink in
  units of ``|g| dt^2``.  A sphere set down at rest overshoots that by the spring's
  overshoot (x2 undamped, e = 1): :func:`stiff_sink_steps`; ``TUNED_SINK_STEPS`` is its
  largest for e >= ``TUNED_E_MIN`` (2.9e-5 at e = 0.1; 2.0e-5 at e = 1; it grows as e -> 0:
  1.1e-4 at e = 0.01).

A column: a contact carrying ``w`` body weights sinks ``w`` times as deep, and a
sphere-sphere contact (two bodies in ``A``) twice as deep as a sphere-wall one for equal
masses (``R = (1 - d) / d Ahat``, ``aref = R f`` at rest).

Rest band: a contact acts below the margin (``exclude`` = distance >= margin,
engine_collision_driver.c) and ``aref`` springs from ``r = margin``: tuned (0, 2^-1022),
default (0, 0).  Sleeping: off in both (``mjENBL_SLEEP``, opt-in, not set: ``opt.enableflags``
0 [XMLreference, option-flag-sleep]).

Set down at distance 0, the default contact (margin 0) is excluded for the first step, so
the sphere falls ``|g| dt^2`` (semi-implicit Euler) before its spring takes over; the
declared sink is the steady one, reached after that transient.

Checked (tests/adapters/test_mujoco_walls.py, and a raw-MJCF script outside the suite for
dt 0.001 to 0.03 and g 1 to 30): the default's steady gap is the fixed point above to 1e-12
relative (refsafe included), and the tuned variant's stays within its declared sink.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import product
from typing import Any

from adapters.mujoco.calls import MARGIN, MAXIMP, PLANE, Mass, Plane, scene_mjcf
from adapters.mujoco_response import damping_dashpot

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


def scene_model(bodies: Sequence[Any], walls: Sequence[Any], tuning: Tuning | None) -> str:
    """The scene's MJCF: one free sphere per body (the tuned variant: inertia equal to the mass,
    condim 1, frictionless through the centres; default: a solid sphere's 2/5 m r^2), one plane
    geom per wall with the spheres' contact attributes."""
    def mass(radius: float, m: float) -> Mass:
        return (m, (m,) * 3) if tuning is not None else (m, (0.4 * m * radius * radius,) * 3)

    extra = ' condim="1"' if tuning is not None else ""
    spheres = [(radius, mass(radius, m)) for _, radius, m, _ in bodies]
    try:
        planes = [plane_of(normal, offset) for normal, offset in walls]
    except ValueError:  # a wall the scene calls refuse before compiling (check_surroundings)
        planes = []
    return scene_mjcf(spheres, extra, planes, extra)


def scene_settings(case_plane: bool, restitution: float, dt: float,
                   tuning: Tuning | None) -> dict[str, Any]:
    """The variant's inputs to the scene calls besides the scene and its model: stiff or not,
    substeps, the direct solref (tuned), and the 2-D plane check's bound (``case_plane``:
    the scene has gravity or walls)."""
    stiff = tuning is not None and 0.0 < dt < math.inf  # else the scene calls refuse the dt
    return {"stiff": tuning is not None, "substeps": tuning.substeps if tuning else 1,
            "solref": stiff_solref(restitution, dt) if stiff else None,
            "plane_bound": WALLED_PLANE if case_plane else PLANE}


Quat = tuple[float, float, float, float]
DEFAULT_SOLREF = (0.02, 1.0)
"""MuJoCo's default solref (timeconst, dampratio) [XMLreference, body-geom-solref]."""
DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
"""MuJoCo's default solimp (d0, dwidth, width, midpoint, power)."""
TUNED_E_MIN = 0.1
"""The smallest restitution :data:`TUNED_SINK_STEPS` holds for."""


def _rotated_z(q: Quat) -> tuple[float, float, float]:
    w, x, y, z = q
    return (2.0 * (x * z + w * y), 2.0 * (y * z - w * x), w * w - x * x - y * y + z * z)


_TETRAHEDRAL: tuple[Quat, ...] = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0),
                                  (0.0, 0.0, 0.0, 1.0),
                                  *((0.5, sx * 0.5, sy * 0.5, sz * 0.5)
                                    for sx, sy, sz in product((1.0, -1.0), repeat=3)))


def plane_quat(normal: tuple[float, float, float]) -> Quat:
    """An exact quaternion turning the z axis onto the unit axis vector ``normal``.

    >>> plane_quat((0.0, 1.0, 0.0))
    (0.5, -0.5, 0.5, 0.5)
    """
    for q in _TETRAHEDRAL:
        if _rotated_z(q) == tuple(float(n) for n in normal):
            return q
    raise ValueError(f"not a unit axis vector: {normal}")


def plane_of(normal: tuple[float, ...], offset: float) -> Plane:
    """The plane geom of a wall: position ``offset x normal``, local z along the normal
    (2-D walls get z = 0)."""
    nx, ny, nz = (*(float(n) for n in normal), 0.0)[:3]
    off = float(offset)
    return (nx * off + 0.0, ny * off + 0.0, nz * off + 0.0), plane_quat((nx, ny, nz))


def soft_sink_s2(timeconst: float, dampratio: float, d: float, dwidth: float) -> float:
    """Steady penetration over |g| (s^2) of a standard-solref contact at impedance ``d``:
    ``(1 - d) dw^2 tc^2 dr^2 / d^2`` (see the module docstring).

    >>> round(soft_sink_s2(0.02, 1.0, 0.95, 0.95), 12)  # constant d: the docs' (1-d) tc^2
    2e-05
    """
    return (1.0 - d) * (dwidth * timeconst * dampratio) ** 2 / (d * d)


def impedance(depth: float, solimp: tuple[float, ...] = DEFAULT_SOLIMP) -> float:
    """``getimpedance`` of engine_core_constraint.c at a penetration ``depth`` (margin 0)."""
    d0, dw, width, mid, power = solimp
    x = abs(depth) / width
    if x >= 1.0 or x <= 0.0:
        return dw if x >= 1.0 else d0
    if x <= mid:
        y = math.pow(x, power) / math.pow(mid, power - 1.0)
    else:
        y = 1.0 - math.pow(1.0 - x, power) / math.pow(1.0 - mid, power - 1.0)
    return d0 + y * (dw - d0)


def soft_rest_sink(gravity: float, dt: float) -> float:
    """The default contact's steady penetration (m) under ``gravity`` (m/s^2) at step ``dt``:
    the fixed point of depth = |g| soft_sink_s2(d(depth)), refsafe's timeconst >= 2 dt."""
    timeconst = max(DEFAULT_SOLREF[0], 2.0 * dt)
    depth = 0.0
    for _ in range(200):
        depth = abs(gravity) * soft_sink_s2(timeconst, DEFAULT_SOLREF[1], impedance(depth),
                                            DEFAULT_SOLIMP[1])
    return depth


def stiff_sink_steps(restitution: float) -> float:
    """The tuned contact's deepest sink (units of |g| dt^2) of a sphere set down at rest:
    ``(1 - mjMAXIMP) / t_c^2`` times 1 + the spring's overshoot."""
    zeta, duration = damping_dashpot(restitution)
    overshoot = math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta * zeta)) if zeta < 1.0 else 0.0
    return (1.0 - MAXIMP) / duration ** 2 * (1.0 + overshoot)


DEFAULT_SINK_S2 = soft_sink_s2(*DEFAULT_SOLREF, DEFAULT_SOLIMP[0], DEFAULT_SOLIMP[1])
"""The default contact's sink bound over |g| (s^2), at d0 (see the module docstring)."""
DEFAULT_SINK_STEPS = soft_sink_s2(2.0, DEFAULT_SOLREF[1], DEFAULT_SOLIMP[0], DEFAULT_SOLIMP[1])
"""The same with refsafe's timeconst 2 dt, in units of |g| dt^2 (binds for dt > 0.01 s)."""
TUNED_SINK_STEPS = max(stiff_sink_steps(TUNED_E_MIN + k * (1.0 - TUNED_E_MIN) / 90)
                       for k in range(91))
"""The tuned contact's sink bound for e >= :data:`TUNED_E_MIN`, units of |g| dt^2."""


@dataclass(frozen=True)
class Rest:
    """A variant's gravity-and-walls conventions (``Conventions`` fields of the same names)."""

    rest_gap: tuple[float, float]
    rest_sink_steps: float
    rest_sink_s2: float
    sleeps: bool
    wall_restitution: str
    notes: str


_WALLS = ("Walls: plane geoms of the world body (a half-space for collisions, infinite, "
          "float64: no size chosen), normal = local z from an exact quaternion, position "
          "offset x normal; gravity = opt.gravity.  No sleeping (mjENBL_SLEEP not set).  ")
TUNED_REST = Rest(
    (0.0, MARGIN), TUNED_SINK_STEPS, 0.0, False, "",
    _WALLS + (
        "Tuned walls get the spheres' condim 1, margin 2^-1022, flat solimp and direct solref: "
        "a wall bounces with the scene's e, frictionless.  Rest: the spring's zero is at the "
        "margin (2^-1022); it sinks |g| (1 - mjMAXIMP) / w0^2 with w0 = t_c / dt, x (1 + "
        "overshoot) when set down at rest (modeling.rst, direct solref: r = a0 (1-d) / "
        f"stiffness): rest_sink_steps {TUNED_SINK_STEPS:.3g} |g| dt^2 for e >= {TUNED_E_MIN} "
        "(larger below).  A contact carrying w weights sinks w x; sphere-sphere 2x."))
DEFAULT_REST = Rest(
    (0.0, 0.0), DEFAULT_SINK_STEPS, DEFAULT_SINK_S2, False,
    "no coefficient of restitution: a wall gets MuJoCo's default soft contact (solref 0.02 1, "
    "solimp 0.9 0.95 0.001 0.5 2, friction 1, condim 3) as the spheres do; e is not read",
    _WALLS + (
        "Default walls keep MuJoCo's defaults, as the spheres.  Rest: soft contact, steady "
        "penetration |g| (1-d) dw^2 tc^2 dr^2 / d^2 (a1 = d aref + (1-d) a0, aref = -K d r; "
        "modeling.rst CSolverReference, engine_core_constraint.c), largest at d0 = 0.9: "
        f"rest_sink_s2 {DEFAULT_SINK_S2:.3g} s^2; refsafe (timeconst >= 2 dt) gives "
        f"{DEFAULT_SINK_STEPS:.3g} |g| dt^2 for dt > 0.01 (rest_sink_steps; the sink is |g| "
        "times the larger).  The steady gap is that formula's fixed point at d(depth) (checked to "
        "1e-12, dt 0.001 to 0.03); set down at distance 0 a sphere first falls |g| dt^2 "
        "(margin 0: no force at distance 0).  A contact carrying w weights sinks about w x."))
