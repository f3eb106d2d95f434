"""The engine part of a repro script for MuJoCo (``mujoco``, ``mujoco-default``).

The adapter (``adapters/mujoco_engine.py``, ``mujoco_setup.py``, ``mujoco_response.py``)
compiles one two-body model per kind from MJCF (two free bodies with explicit inertials,
one geom each, gravity 0) and sets each case into the compiled model: geom sizes with the
bounds the compiler derives from them, masses and inertias (then ``mj_setConst``), the
stiff variant's contact (RK4, solver tolerance, margin and solimp once; per case the time
step and a direct solref the adapter computes), and ``qpos``/``qvel``.  The script embeds
that MJCF (``mujoco_setup.MJCF``, filled by ``mujoco_setup.pair_mjcf``, the very text the
adapter compiles) and makes the same assignments and
calls: detection is ``mj_kinematics``, ``mj_collision`` and ``mj_geomDistance``; a response
steps from ``mj_resetData`` until no contact is active and the spheres no longer approach,
raising on a MuJoCo warning as the adapter does (the warning handler keeps MuJoCo from
writing ``MUJOCO_LOG.TXT``).  A case MuJoCo's compiler refuses compiles its own model, as
the adapter does, and raises its error; non-finite detection input is a guard.
"""

from __future__ import annotations

from string import Template

from adapters import mujoco_engine, mujoco_response, mujoco_setup
from adapters.mujoco_engine import MujocoDefault
from crosscheck.core.geometry import to3
from crosscheck.core.model import quantities_of
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase
from crosscheck.studies.repro.code import EngineCode, number, undefined

SETUP = Template('''\
WARNINGS = collections.deque(maxlen=16)  # MuJoCo's warnings, kept (not MUJOCO_LOG.TXT)
mujoco.set_mju_user_warning(lambda message: WARNINGS.append(str(message)))
MJCF = """\\
$mjcf
"""
$compile
# The case, set into the compiled model: geom sizes, with the bounds the compiler derives
# from them (the broad phase drops a pair whose bounds are stale).
SIZES = $sizes
for g, size in enumerate(SIZES):
    model.geom_size[g] = size
$bounds''')
SPHERE_BOUNDS = """\
    model.geom_rbound[g] = size[0]
    model.geom_aabb[g] = (0.0, 0.0, 0.0, size[0], size[0], size[0])
"""
BOX_BOUNDS = """\
    model.geom_rbound[g] = math.sqrt(math.fsum(h * h for h in size))
    model.geom_aabb[g] = (0.0, 0.0, 0.0, *size)
"""
COMPILE = """\
model = mujoco.MjModel.from_xml_string(MJCF)
data = mujoco.MjData(model)"""
REFUSED = """\
try:  # the case's own model: MuJoCo's compiler checks what a changed model would not
    model = mujoco.MjModel.from_xml_string(MJCF)
except ValueError as exc:
    message = str(exc).strip().splitlines()[0]
    raise ValueError(f"MuJoCo's compiler refuses this case: {message}") from exc
data = mujoco.MjData(model)"""
DETECTION = Template("""\
data.qpos[:] = $qpos
fromto = np.zeros(6)
try:
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    distance = float(mujoco.mj_geomDistance(model, data, 0, 1, $distmax, fromto))
except mujoco.FatalError as exc:  # mju_error
    raise RuntimeError(f"MuJoCo fatal error (mju_error): {exc}") from None


def unit(v):
    # v normalised; None for a zero, overflowing or NaN vector (no direction)
    length = math.hypot(*(float(x) for x in v))
    return tuple(float(x) / length for x in v) if 0.0 < length < math.inf else None


hit, normal = False, None
if data.ncon:  # a contact at distance <= 0 is a hit; its frame's first axis: geom 0 to 1
    deepest = int(np.argmin(data.contact.dist))
    if data.contact.dist[deepest] <= 0.0:
        sign = 1.0 if data.contact.geom[deepest][0] == 0 else -1.0
        hit, normal = True, unit(sign * data.contact.frame[deepest][:3])
if not hit and distance > 0.0:  # apart: the segment from A's nearest point to B's
    start, end = fromto[:3].tolist(), fromto[3:].tolist()
    normal = unit([y - x for x, y in zip(start, end, strict=True)])
if normal is not None:
    normal = normal[:$dim]
""")
STIFF = Template("""\
# The stiff variant's contact: RK4, solver tolerance $tolerance, geom margin 2^-1022 (a
# touching contact is active), solimp flat at mjMAXIMP; this case's direct solref (-k, -b)
# and time step (the contact's duration / 256), as the adapter computes them.
model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
model.opt.tolerance = $tolerance
for g in range(2):
    model.geom_margin[g] = $margin
    model.geom_solimp[g] = $solimp
model.opt.timestep = $timestep
for g in range(2):
    model.geom_solref[g] = $solref
""")
RESPONSE = Template("""\
$stiff
MASSES = $masses  # (mass, diagonal inertia) of A and B
for body, (mass, inertia) in enumerate(MASSES, start=1):
    model.body_mass[body] = mass
    model.body_inertia[body] = inertia
mujoco.mj_setConst(model, data)  # what the compiler derives from masses
MAX_STEPS, PLANE = $max_steps, $plane


def active(d):
    # whether the last collision pass found a contact in the constraint problem
    return bool(d.ncon) and bool((d.contact.exclude == 0).any())


def approaching(d):
    # whether B moves towards A along their line of centres (False for NaN)
    with np.errstate(all="ignore"):
        gap = d.qpos[7:10] - d.qpos[0:3]
        return bool((d.qvel[6:9] - d.qvel[0:3]) @ gap < 0.0)


def warned(d):
    # MuJoCo's warnings of this step in words ('' if none)
    counts = d.warning.number
    if not counts.any():
        return ""
    names = [f"{mujoco.mjtWarning(i).name} x{n}" for i, n in enumerate(counts) if n]
    return f"{' | '.join(WARNINGS) or 'no message'} (counters: {', '.join(names)})"


def centres(d):
    return (tuple(float(x) for x in d.qpos[0:$dim]), tuple(float(x) for x in d.qpos[7:7 + $dim]))


mujoco.mj_resetData(model, data)
WARNINGS.clear()
data.qpos[:], data.qvel[:] = $qpos, $qvel
resolved_at = None  # the centres at the start of the first step with an active contact
try:
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    for _ in range(MAX_STEPS):
        if resolved_at is None and active(data):
            resolved_at = centres(data)
        mujoco.mj_step(model, data)
        if message := warned(data):
            raise RuntimeError(f"MuJoCo warned while stepping, and a bad value resets the "
                               f"state: {message}")
        mujoco.mj_kinematics(model, data)  # the collision pass the next step starts with
        mujoco.mj_collision(model, data)
        if not active(data) and not approaching(data):
            break
    else:
        raise RuntimeError(f"contact still active after {MAX_STEPS} steps of "
                           f"{model.opt.timestep:.3g} s")
except mujoco.FatalError as exc:  # mju_error
    raise RuntimeError(f"MuJoCo fatal error (mju_error): {exc}") from None
va = tuple(float(x) for x in data.qvel[0:3])
vb = tuple(float(x) for x in data.qvel[6:9])
$result""")
RESULT_3D = "v1, v2 = va, vb\n"
RESULT_2D = """\
# the solver leaves rounding noise in vz: dropped within PLANE x the largest speed
if not max(abs(va[2]), abs(vb[2])) <= PLANE * max(map(abs, (*va, *vb))):
    raise RuntimeError(f"2-D response left the plane z = 0: vz = {va[2]!r}, {vb[2]!r}")
v1, v2 = va[:2], vb[:2]
"""


def _vector(v: tuple[float, ...]) -> str:
    return "(" + ", ".join(number(x) for x in v) + ")"


def _stiff(adapter: MujocoDefault, case: ResponseCase) -> str:
    if adapter.stiff is None:
        return "# (MuJoCo's default soft contact and time step 0.002 s)"
    contact = mujoco_response.stiff_contact(case, adapter.stiff)
    solimp = (mujoco_response.MAXIMP, mujoco_response.MAXIMP, 0.001, 0.5, 2.0)
    return STIFF.substitute(
        tolerance=number(mujoco_response.TOLERANCE), margin=number(mujoco_response.MARGIN),
        solimp=_vector(solimp), timestep=number(contact.timestep),
        solref=_vector(contact.solref))


def mujoco_code(adapter: MujocoDefault, case: PairCase) -> EngineCode:
    """The calls of ``adapter`` (a MuJoCo variant) on the case, with the MJCF it compiles."""
    geom = "box" if isinstance(case, AabbCase) else "sphere"
    sizes = mujoco_engine.sizes_of(case)
    response = isinstance(case, ResponseCase)
    masses = adapter.masses(case) if isinstance(case, ResponseCase) else None
    refused = mujoco_setup.refusal(geom, sizes, masses)
    extra = adapter.condim if response else ""
    unit_masses: tuple[mujoco_setup.Mass, ...] = ((1.0, (1.0, 1.0, 1.0)),) * 2
    model = (mujoco_setup.pair_mjcf(geom, sizes, masses or unit_masses, "") if refused
             else mujoco_setup.pair_mjcf(geom, (mujoco_setup.UNIT[geom],) * 2, unit_masses,
                                         extra))
    code = SETUP.substitute(
        mjcf=model, compile=REFUSED if refused else COMPILE,
        sizes=f"({_vector(sizes[0])}, {_vector(sizes[1])})",
        bounds=SPHERE_BOUNDS if geom == "sphere" else BOX_BOUNDS)
    identity = (1.0, 0.0, 0.0, 0.0)
    qpos = (*to3(case.a.center), *identity, *to3(case.b.center), *identity)
    if refused:  # compiling the case's own model raised: the adapter goes no further
        pass
    elif isinstance(case, ResponseCase):
        assert masses is not None
        qvel = (*to3(case.a.velocity), 0.0, 0.0, 0.0, *to3(case.b.velocity), 0.0, 0.0, 0.0)
        code += RESPONSE.substitute(
            stiff=_stiff(adapter, case),
            masses=f"(({number(masses[0][0])}, {_vector(masses[0][1])}), "
                   f"({number(masses[1][0])}, {_vector(masses[1][1])}))",
            max_steps=mujoco_response.MAX_STEPS, plane=number(mujoco_response.PLANE),
            dim=case.dim, qpos=_vector(qpos), qvel=_vector(qvel),
            result=RESULT_2D if case.dim == 2 else RESULT_3D)
    else:
        code += DETECTION.substitute(qpos=_vector(qpos), distmax=number(mujoco_engine.DISTMAX),
                                     dim=case.dim)
        if bad := mujoco_engine.non_finite(case):
            code = undefined(f"non-finite input ({bad}): MuJoCo's detection reads it silently",
                             quantities_of(case.kind_enum), "MuJoCo", code)
    return EngineCode(("import collections", "import math", "import numpy as np",
                       "import mujoco"), code, model=model, resolved_at=response)
