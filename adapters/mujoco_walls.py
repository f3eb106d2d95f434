"""Gravity and static walls of MuJoCo scenes: plane geoms, and how deep a resting sphere sinks.

What it is for: :mod:`adapters.mujoco_scene` builds a scene's :class:`adapters.scene.Wall`
as MuJoCo's users model a ground, and :mod:`adapters.mujoco` declares each variant's
resting-contact conventions from the rules written here.

A wall is a ``plane`` geom of the world body (``adapters.shared.mujoco.SCENE_PLANE``):
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
  ``solref`` (-w0^2, -2 zeta w0) giving the scene's e (``mujoco_scene.stiff_solref``): a wall
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
from dataclasses import dataclass
from itertools import product

from adapters.mujoco_response import MARGIN, MAXIMP, damping_dashpot
from adapters.scene import Wall
from adapters.shared.mujoco import Plane

__all__ = ["DEFAULT_REST", "TUNED_REST", "Rest", "plane_of", "plane_quat", "soft_rest_sink",
           "stiff_sink_steps"]

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


def plane_of(wall: Wall) -> Plane:
    """The plane geom of a wall: position ``offset x normal``, local z along the normal
    (2-D walls get z = 0)."""
    nx, ny, nz = (*(float(n) for n in wall.normal), 0.0)[:3]
    off = float(wall.offset)
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
