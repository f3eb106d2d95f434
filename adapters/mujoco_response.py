"""Sphere responses on MuJoCo: how they are stepped, and the stiff contact fitted per case.

What it is for: the stiff contact's numbers (:func:`stiff_contact`, from the case: the
inputs of :mod:`adapters.mujoco.calls`' responses) and, in words, what those calls do for
``sphere_response`` (both variants).  MuJoCo has no coefficient of restitution and no impulse: a
contact is a soft constraint whose reference acceleration ``aref = -b v - k r`` (``r`` the
penetration minus the margin, ``v`` its rate) is set by ``solref`` and ``solimp``
[modeling.rst, "Solver parameters"; ``mj_makeImpedance`` in engine_core_constraint.c], so a
bounce is a spring-damper acting over many steps.

The build sets sizes, masses (then ``mj_setConst``) and, for the stiff variant, the per-case
contact and time step in a compiled pair (:mod:`adapters.mujoco.calls`).  The ask resets
the data (``mj_resetData``: time, warm start and warnings), puts the case's centres and
velocities in ``qpos``/``qvel`` (2-D: z = 0, vz = 0) and loops: it runs the collision pass of
the current state (``mj_kinematics``, ``mj_collision``: the pass ``mj_step`` starts with),
calls ``mj_step``, checks ``mjData.warning`` and stops after the first step that leaves no
contact active and the spheres not approaching along their line of centres (at least one
step: MuJoCo's own checks see every input).  A bad value (NaN, inf, |x| > 1e10)
in qpos, qvel or qacc makes ``mj_step`` reset the state to the model's reference pose and
only count a warning [``mj_checkPos`` etc. in engine_forward.c]; that is raised as an error,
never reported as a result.  A contact still active after :data:`MAX_STEPS` steps raises too.
Active: a contact MuJoCo puts in its constraint problem (``exclude`` 0: distance < margin
[``mj_setContact`` in engine_collision_driver.c]).  ``resolved_at``: the centres at the start
of the first step whose collision pass found an active contact.  Bodies already separating
meet no force (a touching pair has no penetration): ``resolves_separating`` False.

The stiff contact (variant ``mujoco``, :class:`Stiff`), chosen per case from its numbers:

- frictionless (``condim`` 1: the textbook has no friction), RK4 integrator, solver
  tolerance 1e-15 (the default 1e-8 is relative to the heavier body's scale: at a mass ratio
  of 1e12 it stopped with the light body's velocity off by 2.5e-4, measured at w0 = 1e4);
- ``solimp`` flat at mjMAXIMP 0.9999 (``d0 = d_width``: impedance independent of depth), so
  with the direct ``solref = (-k, -b)`` the normal motion is exactly ``a = -k r - b v``
  [eq:solref_direct in modeling.rst; ``efc_aref`` in engine_core_constraint.c]: a linear
  spring-dashpot, the same for any masses (constraint space);
- ``k = w0**2`` with ``w0 = V / depth`` (V the relative speed), ``depth = 10 sqrt(P R u)``
  (``R`` the smaller radius, ``P`` the largest |coordinate| or R, ``u = 2**-52``): the peak
  penetration V / w0 is 10 x the geometric mean of the radius and the coordinates' resolution
  u P, so the turn of the line of centres during contact (~ depth / R) and the rounding of
  positions (~ u P / depth) stay about equally small (3.6e-7 of the speed at worst on the
  suite; at P = 1e8 the rounding costs 1.5e-4); ``w0`` is capped so the peak acceleration
  (``w0 V``, and ``w0**2`` x the overlap of spheres that start overlapped) stays <= 1e9, a
  tenth of mjMAXVAL (MuJoCo resets beyond it);
- damping ``b = 2 zeta w0`` where ``zeta`` gives the case's restitution e in the linear
  spring-dashpot whose force stops at zero (the solver's force is >= 0, so the contact ends
  when ``k r + b v`` reaches 0, before the spheres part) [arXiv 2204.10917]: the closed form in
  :func:`dashpot`, inverted by bisection; e = 1: ``b`` 0.  e = 0 needs infinite damping, e > 1
  a negative one (the direct format takes damping >= 0), e < 0 or NaN has no spring-dashpot:
  those cases are skipped;
- time step ``t_c / (256 w0)``, ``t_c`` the contact's duration: the contact starts exactly at
  a step (the suite's spheres touch at the start) and ends exactly on one (no mid-step kink
  for RK4), so the restitution comes out within 1e-10 (measured, e = 0.01 to 1); a step
  costs ~35 us here (RK4: four forward passes), a response ~260 steps, ~9 ms;
- geom margin 2**-1022 (the smallest normal double): a contact at distance 0 is active at
  once (MuJoCo excludes a contact whose distance is >= its margin), so the damping force
  starts with the impact and not one RK4 stage late (that first-order error was 4.5e-4 at
  e = 0.5, measured).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

from crosscheck.core.geometry import difference, norm
from crosscheck.core.schema import ResponseCase

__all__ = ["MAX_STEPS", "Contact", "Stiff", "damping_dashpot", "damping_ratio", "dashpot",
           "restitution_refusal", "stiff_contact"]

MAX_STEPS = 50_000
"""Step cap of one response; a contact still active then is an error."""
U = 2.0**-52


@dataclass(frozen=True, slots=True)
class Stiff:
    """How stiff contacts are set from a case (see the module docstring)."""

    steps: int = 256
    """Steps per contact."""
    depth: float = 10.0
    """Peak penetration in units of sqrt(P R u)."""
    max_acceleration: float = 1e9


@dataclass(frozen=True, slots=True)
class Contact:
    """One case's stiff contact: direct ``solref`` (-k, -b) and the time step."""

    solref: tuple[float, float]
    timestep: float


def dashpot(zeta: float) -> tuple[float, float]:
    """Restitution and duration (in units of 1 / w0) of a linear spring-dashpot contact.

    ``x'' + 2 zeta x' + x = 0`` from ``x = 0``, ``x' = 1``; the force ``x + 2 zeta x'`` pushes
    only, so the contact ends at its first zero ``t_c``, and e = ``-x'(t_c)``.

    >>> dashpot(0.0)  # undamped: elastic, half a period
    (1.0, 3.141592653589793)
    """
    if zeta < 1.0:
        w = math.sqrt(1.0 - zeta * zeta)
        t = (math.pi - math.atan2(2.0 * zeta, (1.0 - 2.0 * zeta * zeta) / w)) / w
        return -math.exp(-zeta * t) * (math.cos(w * t) - zeta / w * math.sin(w * t)), t
    if zeta == 1.0:
        return math.exp(-2.0), 2.0
    big = math.sqrt(zeta * zeta - 1.0)
    t = math.atanh(2.0 * zeta * big / (2.0 * zeta * zeta - 1.0)) / big
    return -math.exp(-zeta * t) * (math.cosh(big * t) - zeta / big * math.sinh(big * t)), t


@lru_cache(maxsize=64)
def damping_ratio(e: float) -> float:
    """The damping ratio whose :func:`dashpot` restitution is ``e`` (0 < e <= 1), by bisection."""
    if e >= 1.0:
        return 0.0
    lo, hi = 0.0, 1e3
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if dashpot(mid)[0] > e else (lo, mid)
    return 0.5 * (lo + hi)


def damping_dashpot(e: float) -> tuple[float, float]:
    """The damping ratio of restitution ``e`` and the contact's duration in units of 1 / w0."""
    zeta = damping_ratio(e)
    return zeta, dashpot(zeta)[1]


def stiff_contact(case: ResponseCase, stiff: Stiff) -> Contact:
    """The case's spring-dashpot (see the module docstring)."""
    speed = norm(difference(case.a.velocity, case.b.velocity))
    radius = min(case.a.radius, case.b.radius)
    scale = max([radius, *(abs(x) for x in (*case.a.center, *case.b.center))])
    overlap = case.a.radius + case.b.radius - norm(difference(case.a.center, case.b.center))
    w0 = 1.0  # no relative motion, or an infinite one (MuJoCo's checks stop it)
    if 0.0 < speed < math.inf:
        w0 = min(speed / (stiff.depth * math.sqrt(scale * radius * U)),
                 stiff.max_acceleration / speed)
    if overlap > 0.0:  # starting overlapped: the spring's first push is k x overlap
        w0 = min(w0, math.sqrt(stiff.max_acceleration / overlap))
    if not 0.0 < w0 < math.inf:  # NaN input: MuJoCo's own checks report it
        w0 = 1.0
    zeta = damping_ratio(case.restitution)
    duration = dashpot(zeta)[1]
    return Contact((-w0 * w0, -2.0 * zeta * w0), duration / (w0 * stiff.steps))


def restitution_refusal(e: float) -> str | None:
    """Why the stiff contact cannot give restitution ``e`` (None: it can)."""
    if 0.0 < e <= 1.0:
        return None
    if e == 0.0:
        return ("a spring-dashpot reaches restitution 0 only with infinite damping "
                "(MuJoCo has no coefficient of restitution)")
    return (f"restitution {e!r} outside (0, 1]: MuJoCo's direct solref has damping >= 0 "
            "(no energy gain) and no coefficient of restitution")
