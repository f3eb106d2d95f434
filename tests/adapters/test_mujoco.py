"""The MuJoCo adapters: pinned native behaviour of MuJoCo 4.0.0 and the translation.

The conformance tests pin what the engine does that the adapters rely on, each with the
engine fact named, on models built here with MuJoCo's own API; the translation tests
compare the adapters' answers with the exact oracle (within the float64 bound or the
declared precision), never with a copied engine output.
"""

from __future__ import annotations

import math
import random
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

import adapters  # noqa: E402
from adapters import mujoco_response as response  # noqa: E402
from adapters.mujoco import (  # noqa: E402
    STIFF_RTOL,
    MujocoDefault,
    MujocoStiff,
    sizes_of,
)
from adapters.mujoco.calls import compile_pair, refusal, set_sizes  # noqa: E402
from adapters.mujoco.scene import TUNED_RTOL, Tuning  # noqa: E402
from crosscheck.cases.load import load_paths  # noqa: E402
from crosscheck.core.geometry import Vec, to3  # noqa: E402
from crosscheck.core.model import Category, Observation, Undefined  # noqa: E402
from crosscheck.core.options import RunOptions  # noqa: E402
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, ResponseCase  # noqa: E402
from crosscheck.results.run import read_results  # noqa: E402
from crosscheck.results.store import ResultsStore  # noqa: E402
from crosscheck.run.runner import run  # noqa: E402
from crosscheck.truth import oracle  # noqa: E402
from crosscheck.truth.bounds import bound, error_of  # noqa: E402
from crosscheck.truth.categories import velocity_scale  # noqa: E402
from crosscheck.truth.score import judge  # noqa: E402
from tests.adapters.scene_calls import MujocoSceneCalls  # noqa: E402
from tests.conftest import ROOT, aabb, sphere  # noqa: E402
from tests.conftest import response as resp_case  # noqa: E402
from tools.stiff_precision import draw, relative_error  # noqa: E402

pytestmark = pytest.mark.engine

STIFF, DEFAULT = MujocoStiff(), MujocoDefault()
BOTH = pytest.mark.parametrize("adapter", [STIFF, DEFAULT], ids=["mujoco", "mujoco-default"])

PAIR = """<mujoco><option gravity="0 0 0"{option}/><worldbody>
  <body><freejoint/><inertial pos="0 0 0" mass="{ma}" diaginertia="1 1 1"/>
    <geom type="{geom}" size="{sa}"{extra}/></body>
  <body><freejoint/><inertial pos="0 0 0" mass="{mb}" diaginertia="1 1 1"/>
    <geom type="{geom}" size="{sb}"{extra}/></body>
</worldbody></mujoco>"""


def native(geom: str, sa: str, sb: str, pa: Vec, pb: Vec, **more: Any) -> tuple[Any, Any]:
    """A model of two free bodies built from MJCF text, posed and through one collision pass."""
    fields = {"option": "", "extra": "", "ma": 1.0, "mb": 1.0, **more}
    model = mujoco.MjModel.from_xml_string(PAIR.format(geom=geom, sa=sa, sb=sb, **fields))
    data = mujoco.MjData(model)
    data.qpos[:] = [*to3(pa), 1.0, 0.0, 0.0, 0.0, *to3(pb), 1.0, 0.0, 0.0, 0.0]
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    return model, data


def disc(ca: list[float], ra: float, cb: list[float], rb: float) -> AnyCase:
    """A sphere case with centres anywhere."""
    return CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere", "dim": len(ca),
        "a": {"center": ca, "radius": ra}, "b": {"center": cb, "radius": rb}})


def moving(pa: list[float], va: list[float], pb: list[float], vb: list[float], ra: float = 0.5,
           rb: float = 0.5, ma: float = 1.0, mb: float = 1.0, e: float = 1.0) -> ResponseCase:
    """A response case with any radii, masses and restitution."""
    case = CASE_ADAPTER.validate_python({
        "id": "m", "description": "d", "kind": "sphere_response", "dim": len(pa),
        "restitution": e,
        "a": {"center": pa, "radius": ra, "mass": ma, "velocity": va},
        "b": {"center": pb, "radius": rb, "mass": mb, "velocity": vb}})
    assert isinstance(case, ResponseCase)
    return case


def velocity_error(case: ResponseCase, obs: Observation) -> float:
    truth = oracle.truth(case)
    assert obs.v1 is not None and obs.v2 is not None
    assert isinstance(truth.v1, tuple) and isinstance(truth.v2, tuple)
    return max(error_of("v1", obs.v1, truth.v1), error_of("v2", obs.v2, truth.v2))


# --- native behaviour (conformance) ------------------------------------------------------------

def test_box_size_is_half_sizes() -> None:
    # XMLreference: a box geom's size is its half-sizes; boxes "1 1 1" at x = 0 and 3 are 1
    # apart (they would touch if the sizes were full side lengths).
    model, data = native("box", "1 1 1", "1 1 1", (0.0, 0.0, 0.0), (3.0, 0.0, 0.0))
    assert mujoco.mj_geomDistance(model, data, 0, 1, 1e30, None) == 1.0


def test_touching_spheres_are_listed_at_distance_zero_and_left_out_of_forces() -> None:
    # mjraw_SphereSphere rejects only |d|^2 > (r1 + r2 + margin)^2; mj_setContact excludes a
    # contact whose distance is >= its margin (0 here): listed, but no force.
    _, touching = native("sphere", "0.5", "0.5", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    assert (touching.ncon, touching.contact.dist[0], touching.contact.exclude[0]) == (1, 0.0, 1)
    _, deep = native("sphere", "0.5", "0.5", (0.0, 0.0, 0.0), (0.75, 0.0, 0.0))
    assert (deep.ncon, deep.contact.dist[0], deep.contact.exclude[0]) == (1, -0.25, 0)


@pytest.mark.parametrize(("where", "contacts"), [
    ((2.0, 0.0, 0.0), True), ((2.0, 2.0, 0.0), True), ((2.0, 2.0, 2.0), False),
], ids=["face", "edge", "corner"])
def test_touching_boxes_make_contacts_on_faces_and_edges_not_corners(
        where: Vec, contacts: bool) -> None:
    # The box-box collider clips contact points at distance 0 on a shared face or edge, none
    # at a lone corner; mj_geomDistance reads 0 for all three.
    model, data = native("box", "1 1 1", "1 1 1", (0.0, 0.0, 0.0), where)
    assert (data.ncon > 0) == contacts
    assert all(d == 0.0 for d in data.contact.dist[:data.ncon])
    assert mujoco.mj_geomDistance(model, data, 0, 1, 1e30, None) == 0.0


def test_contact_normal_and_fromto_point_from_geom0_to_geom1() -> None:
    for sign in (1.0, -1.0):
        _, data = native("sphere", "0.5", "0.5", (0.0, 0.0, 0.0), (0.75 * sign, 0.0, 0.0))
        assert tuple(data.contact.geom[0]) == (0, 1)
        assert tuple(data.contact.frame[0][:3]) == (sign, 0.0, 0.0)
    model, data = native("sphere", "0.5", "0.5", (0.0, 0.0, 0.0), (3.0, 0.0, 0.0))
    fromto = np.zeros(6)
    assert mujoco.mj_geomDistance(model, data, 0, 1, 1e30, fromto) == 2.0
    assert fromto.tolist() == [0.5, 0.0, 0.0, 2.5, 0.0, 0.0]  # on A's surface, then on B's


def test_stale_bounds_make_the_broad_phase_drop_the_pair() -> None:
    # Why set_sizes also sets geom_rbound and geom_aabb: the bounding-sphere filter uses them.
    pair = compile_pair("sphere")
    m, d = pair.model, pair.data
    d.qpos[:] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 3.0, 4.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    m.geom_size[0][0] = m.geom_size[1][0] = 3.0  # overlapping by 1, bounds still radius 1
    mujoco.mj_kinematics(m, d)
    mujoco.mj_collision(m, d)
    assert d.ncon == 0
    set_sizes(pair, ((3.0, 0.0, 0.0), (3.0, 0.0, 0.0)))
    mujoco.mj_collision(m, d)
    assert (d.ncon, d.contact.dist[0]) == (1, -1.0)


def test_a_bad_qpos_resets_the_state_and_only_counts_a_warning() -> None:
    # mj_checkPos: a NaN (or |x| > 1e10) in qpos resets mjData and counts mjWARN_BADQPOS;
    # mj_step returns as if nothing happened, hence the adapter's check of mjData.warning.
    model, data = native("sphere", "0.5", "0.5", (0.0, 0.0, 0.0), (3.0, 0.0, 0.0))
    data.qpos[0] = math.nan
    mujoco.mj_step(model, data)
    assert data.warning[mujoco.mjtWarning.mjWARN_BADQPOS].number == 1
    # the step went on from the reference pose: both bodies at the origin, B no longer at 3
    assert abs(data.qpos[7]) < 0.1 and all(math.isfinite(x) for x in data.qpos)


def test_the_compiler_refuses_non_positive_sizes_and_masses() -> None:
    with pytest.raises(ValueError, match="must be positive"):
        native("sphere", "0", "0.5", (0.0, 0.0, 0.0), (3.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="mjMINVAL"):
        native("sphere", "0.5", "0.5", (0.0, 0.0, 0.0), (3.0, 0.0, 0.0), ma=0.0)
    # refusal() asks the compiler itself, and only about numbers outside its range
    assert "must be positive" in (refusal("sphere", ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))) or "")
    assert "must be positive" in (refusal("box", ((1.0, -1.0, 1.0), (1.0, 1.0, 1.0))) or "")
    assert "mjMINVAL" in (refusal("sphere", ((1.0, 0.0, 0.0),) * 2,
                                  ((0.0, (1.0, 1.0, 1.0)), (1.0, (1.0, 1.0, 1.0)))) or "")
    assert refusal("sphere", ((1e-300, 0.0, 0.0), (1.0, 0.0, 0.0))) is None


def test_direct_solref_with_flat_solimp_is_a_linear_spring_dashpot() -> None:
    # eq:solref_direct and efc_aref: with solimp d0 = d_width = d the normal acceleration is
    # d * aref = -k r - b v exactly (solver tolerance 1e-15), whatever the masses.
    k, b = 100.0, 3.0
    extra = f' condim="1" solref="{-k} {-b}" solimp="0.9999 0.9999 0.001 0.5 2"'
    model, data = native("sphere", "0.5", "0.5", (0.0, 0.0, 0.0), (0.75, 0.0, 0.0),
                         extra=extra, option=' integrator="RK4"', ma=1.0, mb=3.0)
    model.opt.tolerance = 1e-15
    mujoco.mj_setConst(model, data)
    data.qpos[:] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.75, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    data.qvel[:] = [1.0, 0, 0, 0, 0, 0, -1.0, 0, 0, 0, 0, 0]  # approaching at 2: v = -2
    mujoco.mj_forward(model, data)
    normal_acceleration = data.qacc[6] - data.qacc[0]
    assert normal_acceleration == pytest.approx(-(k * -0.25 + b * -2.0), rel=1e-12)


def test_no_log_file_is_written_and_without_the_handler_there_is_one(tmp_path: Path) -> None:
    warn = ("model = mujoco.MjModel.from_xml_string('<mujoco><worldbody><body><freejoint/>"
            "<geom size=\"1\"/></body></worldbody></mujoco>')\n"
            "data = mujoco.MjData(model)\n"
            "data.qpos[0] = float('nan')\n"
            "mujoco.mj_step(model, data)\n")
    with_handler = "from adapters.mujoco.calls import engine\nmujoco = engine()\n" + warn
    plain = "import mujoco\n" + warn
    for name, code in (("handled", with_handler), ("plain", plain)):
        folder = tmp_path / name
        folder.mkdir()
        subprocess.run([sys.executable, "-c", code], cwd=folder, check=True, capture_output=True,
                       env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert not (tmp_path / "handled" / "MUJOCO_LOG.TXT").exists()
    assert (tmp_path / "plain" / "MUJOCO_LOG.TXT").exists()


def test_an_overflowing_contact_normal_is_a_fatal_error() -> None:
    # mju_error("mju_makeFrame: xaxis of contact frame undefined"): in C it ends the process;
    # the binding raises mujoco.FatalError, the adapter a RuntimeError, and a new pair follows.
    huge = disc([1.7e308, 0.0], 1.7e308, [1e15, 0.0], 5e-324)
    with pytest.raises(RuntimeError, match=r"fatal error.*contact frame"):
        DEFAULT.observe(huge)
    assert DEFAULT.observe(sphere(0.0, 0.75)).distance == -0.25


def test_the_fatal_error_is_an_error_row_in_a_worker_and_the_next_case_runs(
        tmp_path: Path) -> None:
    huge = disc([1.7e308, 0.0], 1.7e308, [1e15, 0.0], 5e-324).model_copy(
        update={"id": "huge", "tags": ("bad-input",)})
    after = sphere(0.0, 0.75, id="after")
    store = ResultsStore(tmp_path / "run")
    run([huge, after], [DEFAULT], store, RunOptions(quick=True, timeout_s=10.0))
    store.close()
    frame = read_results(tmp_path / "run")
    rows = frame[frame["case_id"] == "huge"]
    assert set(rows["status"]) == {"error"}
    assert rows["reason"].str.contains("contact frame undefined").all()
    assert set(frame[frame["case_id"] == "after"]["status"]) == {"agree"}


# --- translation: detection ----------------------------------------------------------------------

@pytest.mark.parametrize("case", [
    sphere(0.0, 0.75), sphere(0.0, 3.0, dim=2), disc([0.0, 0.0], 2.5, [3.0, 4.5], 2.5),
    disc([1.0, 2.0, 2.0], 1.0, [0.0, 0.0, 0.0], 1.5),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.5, 0.5, 0.0], [1.0, 1.0, 1.0]),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [3.0, 3.0, 0.0], [1.0, 1.0, 1.0]),
    aabb([0.0, 0.0], [1.0, 0.5], [0.0, -1.25], [2.0, 1.0]),
    aabb([0.0, 0.0], [0.5, 0.5], [3.0, 4.0], [0.5, 0.5]),
], ids=["sphere-overlap", "disc-gap", "disc-345-gap", "sphere-122", "box-overlap",
        "box-edge-gap", "box-2d-overlap-y", "box-2d-corner-gap"])
def test_detection_agrees_with_the_oracle(case: AnyCase) -> None:
    obs, truth = DEFAULT.observe(case), oracle.truth(case)
    assert obs.hit is truth.hit
    assert isinstance(obs.distance, float) and isinstance(truth.distance, float)
    assert abs(obs.distance - truth.distance) <= bound(case, "distance")
    assert isinstance(obs.normal, tuple) and isinstance(truth.normal, tuple)
    assert len(obs.normal) == case.dim
    assert error_of("normal", obs.normal, truth.normal) <= bound(case, "normal", truth.distance)


def test_2d_boxes_get_a_z_half_width_of_twice_the_largest_half_width() -> None:
    case = aabb([0.0, 0.0], [1.0, 0.25], [1.5, 0.0], [0.5, 3.0])
    assert sizes_of(case) == ((1.0, 0.25, 6.0), (0.5, 3.0, 6.0))
    assert sizes_of(sphere(0.0, 1.0)) == ((0.5, 0.0, 0.0), (0.5, 0.0, 0.0))


def test_the_corner_rule_is_declared_and_2d_corners_are_3d_edges() -> None:
    corner3 = aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [1.0, 1.0, 1.0])
    corner2 = aabb([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [1.0, 1.0])
    assert DEFAULT.observe(corner3).hit is False
    assert DEFAULT.conventions.touching_is_contact("corner") is False
    assert DEFAULT.observe(corner2).hit is True is oracle.truth(corner2).hit
    assert DEFAULT.observe(sphere(0.0, 1.0)).hit is True
    assert DEFAULT.conventions.touching_is_contact("sphere") is True


def test_non_finite_detection_input_is_undefined() -> None:
    obs = DEFAULT.observe(sphere(math.nan, 1.0, tags=["bad-input"]))
    assert all(isinstance(obs.get(q), Undefined) for q in ("hit", "distance", "normal"))
    assert isinstance(obs.hit, Undefined) and "non-finite" in obs.hit.reason


@pytest.mark.parametrize("bad", [
    sphere(0.0, 1.0, ra=0.0), sphere(0.0, 1.0, rb=-0.5),
    aabb([0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0]),
    resp_case([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0], ma=0.0),
], ids=["zero-radius", "negative-radius", "zero-half", "zero-mass"])
def test_what_the_compiler_refuses_raises_its_message(bad: AnyCase) -> None:
    with pytest.raises(ValueError, match="MuJoCo's compiler refuses"):
        DEFAULT.prepare(bad)


def test_interleaved_prepared_cases_each_answer_for_themselves() -> None:
    first, second = sphere(0.0, 0.75), sphere(0.0, 3.0, ra=1.0)
    p1, p2 = DEFAULT.prepare(first), DEFAULT.prepare(second)
    assert DEFAULT.query(p1) == DEFAULT.observe(first)
    assert DEFAULT.query(p2) == DEFAULT.observe(second)
    r1 = moving([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0])
    r2 = moving([0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [0.0, 0.0], mb=3.0)
    q1, q2 = STIFF.prepare(r1), STIFF.prepare(r2)
    assert STIFF.query(q1) == STIFF.observe(r1)
    assert STIFF.query(q2) == STIFF.observe(r2)


# --- translation: responses ----------------------------------------------------------------------

def test_dashpot_matches_a_direct_integration() -> None:
    # x'' = -x - 2 zeta x' from x = 0, x' = 1 until the force x + 2 zeta x' reaches 0.
    def integrate(zeta: float, h: float = 1e-4) -> tuple[float, float]:
        def f(s: tuple[float, float]) -> tuple[float, float]:
            return s[1], -s[0] - 2.0 * zeta * s[1]
        t, s = 0.0, (0.0, 1.0)
        while True:
            k1 = f(s)
            k2 = f((s[0] + h / 2 * k1[0], s[1] + h / 2 * k1[1]))
            k3 = f((s[0] + h / 2 * k2[0], s[1] + h / 2 * k2[1]))
            k4 = f((s[0] + h * k3[0], s[1] + h * k3[1]))
            nxt = (s[0] + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
                   s[1] + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]))
            if nxt[0] + 2.0 * zeta * nxt[1] <= 0.0 and t > 0.0:
                return -nxt[1], t + h
            t, s = t + h, nxt
    for zeta in (0.0, 0.3, 0.9, 1.0, 2.5):
        e, duration = response.dashpot(zeta)
        want_e, want_t = integrate(zeta)
        assert e == pytest.approx(want_e, abs=1e-3) and duration == pytest.approx(want_t, abs=2e-4)


@pytest.mark.parametrize("e", [1e-3, 0.1, 0.5, 0.9, 1.0])
def test_damping_ratio_inverts_the_dashpot(e: float) -> None:
    assert response.dashpot(response.damping_ratio(e))[0] == pytest.approx(e, rel=1e-12)


@pytest.mark.parametrize("e", [0.1, 0.5, 0.9, 1.0])
@pytest.mark.parametrize("geometry", ["head-on", "oblique-3d", "oblique-2d"])
def test_stiff_responses_agree_with_the_textbook_within_the_declared_precision(
        e: float, geometry: str) -> None:
    case = {
        "head-on": moving([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0],
                          mb=3.0, e=e),
        "oblique-3d": moving([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.0, 2.0, 2.0], [0.0, 0.0, -1.0],
                             ra=1.0, rb=2.0, e=e),
        "oblique-2d": moving([0.0, 0.0], [1.0, 1.0], [4.0, 3.0], [-1.0, 0.0], ra=2.0, rb=3.0,
                             ma=2.0, e=e),
    }[geometry]
    assert STIFF.unsupported(case) is None
    assert velocity_error(case, STIFF.observe(case)) <= STIFF_RTOL * velocity_scale(case)


def test_the_declared_stiff_precision_is_measured_off_the_suite() -> None:
    # STIFF_RTOL comes from random touching pairs that are not in cases/ (tools/
    # stiff_precision.py); a sample of them is within it, and none is a suite case.
    suite = {(c.a.center, c.b.center, c.a.velocity) for c in load_paths([ROOT / "cases"]).cases
             if isinstance(c, ResponseCase)}
    rng = random.Random(0)
    for i in range(40):
        case = draw(rng, i)
        assert (case.a.center, case.b.center, case.a.velocity) not in suite
        assert relative_error(case, STIFF) <= STIFF_RTOL, case
    assert STIFF.conventions.response_rtol == STIFF_RTOL and STIFF.conventions.rtol == 2.0**-50


def test_each_variant_declares_its_own_contact() -> None:
    # the stiff variant is frictionless (condim 1) and fits the case's e: it inherits neither
    # the default's friction 1 nor its soft model; both sample contacts at step starts
    # (mj_step has no continuous detection: a pair faster than its overlap passes through)
    stiff, default = STIFF.conventions, DEFAULT.conventions
    assert (stiff.friction, stiff.restitution_model, stiff.sampled_contacts) == (0.0, "", True)
    assert (default.friction, default.restitution_model, default.sampled_contacts) == (
        1.0, "soft", True)
    case = moving([0.0, 0.0], [1.0, 1.0], [4.0, 3.0], [-1.0, 0.0], ra=2.0, rb=3.0, e=0.5)
    obs = STIFF.observe(case)
    assert isinstance(obs.v2, tuple)  # frictionless: no tangential impulse
    line = (0.8, 0.6)
    tangent = (-line[1], line[0])
    dv = [b - a for a, b in zip(case.b.velocity, obs.v2, strict=True)]
    assert abs(sum(x * t for x, t in zip(dv, tangent, strict=True))) <= STIFF_RTOL


@pytest.mark.parametrize("case_id", ["resp-2d-grazing", "resp-3d-grazing-2pow-20",
                                     "resp-2d-grazing-345", "resp-3d-grazing-1e-6"])
def test_a_grazing_contact_between_two_default_steps_is_the_step(case_id: str) -> None:
    # Contacts make force only below the margin (0): the touching start is excluded, and the
    # overlap ends before the next step starts, so no force acts (the bodies keep their
    # velocities): the declared sampled contacts and time step explain it.
    case = next(c for c in load_paths([ROOT / "cases"]).cases if c.id == case_id)
    assert isinstance(case, ResponseCase)
    obs, truth = DEFAULT.observe(case), oracle.truth(case)
    assert obs.resolved_at is None  # no step ever started in active contact
    for quantity in ("v1", "v2"):
        verdict = judge(case, DEFAULT.conventions, quantity, obs.get(quantity), truth, obs)
        assert verdict.category == Category.TIMESTEP, verdict.reason
        assert "no step of 0.002 s starts in between" in verdict.reason


@pytest.mark.parametrize("e", [0.0, 1.5, -0.5, math.nan])
def test_stiff_skips_restitutions_a_spring_dashpot_cannot_give(e: float) -> None:
    case = moving([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0], e=e)
    reason = STIFF.unsupported(case)
    assert reason is not None and reason.startswith("mujoco (stiff)")
    assert DEFAULT.unsupported(case) is None


def test_stiff_skips_detection_which_mujoco_default_scores() -> None:
    reason = STIFF.unsupported(sphere(0.0, 0.75))
    assert reason is not None and "mujoco-default" in reason
    assert DEFAULT.unsupported(sphere(0.0, 0.75)) is None


def test_default_contact_is_soft_and_ignores_the_restitution() -> None:
    # Default solref (0.02, 1) is critically damped: far from the elastic bounce.
    elastic = moving([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0])
    half = elastic.model_copy(update={"restitution": 0.5})
    obs = DEFAULT.observe(elastic)
    assert obs.v1 is not None and obs.v2 is not None
    bounce = (obs.v2[0] - obs.v1[0]) / 2.0
    assert 0.0 < bounce < 0.5
    assert DEFAULT.observe(half) == obs


def test_resolved_at_is_where_a_step_started_in_active_contact() -> None:
    case = moving([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0])
    # stiff: its margin 2^-1022 makes the touching contact active at the start
    assert STIFF.observe(case).resolved_at == (case.a.center, case.b.center)
    # default: touching is excluded (distance 0 >= margin 0); one Euler step later they overlap
    at = DEFAULT.observe(case).resolved_at
    assert at is not None
    gap = oracle.truth(disc(list(at[0]), 0.5, list(at[1]), 0.5)).distance
    assert isinstance(gap, float) and gap < 0.0


@BOTH
def test_touching_pairs_already_separating_are_left_alone(adapter: Any) -> None:
    assert adapter.conventions.resolves_separating is False
    case = moving([0.0, 0.0, 0.0], [-1.0, 0.5, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    obs = adapter.observe(case)
    assert (obs.v1, obs.v2) == (case.a.velocity, case.b.velocity)


@BOTH
def test_a_bad_velocity_raises_the_warning_instead_of_a_reset_state(adapter: Any) -> None:
    case = moving([0.0, 0.0], [math.nan, 0.0], [1.0, 0.0], [0.0, 0.0])
    with pytest.raises(RuntimeError, match="mjWARN_BADQVEL"):
        adapter.observe(case)


def test_a_contact_that_does_not_resolve_within_the_cap_raises(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(response, "MAX_STEPS", 3)
    with pytest.raises(RuntimeError, match="contact still active after 3 steps"):
        DEFAULT.observe(moving([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0]))


@BOTH
@pytest.mark.parametrize("case", [
    moving([0.0, 0.0], [1.0, 0.5], [0.8, 0.6], [-1.0, 0.0], mb=3.0),
    moving([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.9, 0.0, 0.0], [-1.0, 0.0, 0.0]),
], ids=["oblique-2d", "overlapping-3d"])
def test_responses_are_repeatable_and_stay_in_the_plane(adapter: Any, case: AnyCase) -> None:
    prepared = adapter.prepare(case)
    first = adapter.query(prepared)
    assert adapter.query(prepared) == first == adapter.observe(case)
    assert first.v1 is not None and len(first.v1) == case.dim


def test_registry_and_versions() -> None:
    assert type(adapters.get("mujoco")) is MujocoStiff
    assert type(adapters.get("mujoco-default")) is MujocoDefault
    assert STIFF.version() == DEFAULT.version() == mujoco.__version__ == "4.0.0"
    assert STIFF.engine == DEFAULT.engine == "mujoco"
    assert STIFF.conventions.rtol == DEFAULT.conventions.rtol == 2.0**-50


# --- scenes (the scene calls of adapters/mujoco/calls.py) ---

HEAD_ON = [((-2.0, 0.0), 0.5, 1.0, (1.0, 0.0)), ((2.0123456789, 0.0), 0.5, 1.0, (-1.0, 0.0))]


def _stepped(bodies: list[Any], dim: int, e: float, tuning: Any, steps: int) -> Any:
    mujoco_scene = MujocoSceneCalls(MujocoStiff())

    prepared = mujoco_scene.prepare_scene(bodies, dim, e, 1e-3, None, tuning)
    return mujoco_scene.run_scene(prepared, steps)


@pytest.mark.parametrize("dim", [2, 3])
def test_tuned_scene_exchanges_velocities_of_an_elastic_head_on_pair(dim: int) -> None:
    bodies = [(c + (0.0,) * (dim - 2), r, m, v + (0.0,) * (dim - 2)) for c, r, m, v in HEAD_ON]
    run = _stepped(bodies, dim, 1.0, Tuning(), 3000)
    (va, *rest_a), (vb, *rest_b) = run.velocities
    assert va == pytest.approx(-1.0, abs=TUNED_RTOL)
    assert vb == pytest.approx(1.0, abs=TUNED_RTOL)
    assert va != -1.0  # a soft contact: not the exact exchange (the test can fail)
    assert rest_a == rest_b == [0.0] * (dim - 1)
    assert abs(va + vb) <= 1e-12  # momentum kept: equal and opposite constraint forces
    assert len(run.positions[0]) == dim and run.steps == 3000


def test_tuned_scene_restitution_is_the_scenes_e() -> None:
    run = _stepped(HEAD_ON, 2, 0.5, Tuning(substeps=32), 3000)
    assert run.velocities[0][0] == pytest.approx(-0.5, abs=1e-2)
    assert run.velocities[1][0] == pytest.approx(0.5, abs=1e-2)


def test_default_scene_ignores_restitution_and_keeps_momentum() -> None:
    elastic = _stepped(HEAD_ON, 2, 1.0, None, 3000)
    plastic = _stepped(HEAD_ON, 2, 0.25, None, 3000)
    assert elastic.velocities == plastic.velocities  # e is not read
    assert 0.0 < elastic.velocities[1][0] < 0.5  # the default soft contact loses most of it
    assert abs(elastic.velocities[0][0] + elastic.velocities[1][0]) <= 1e-12


def test_scene_clock_reads_only_around_the_stepping() -> None:
    mujoco_scene = MujocoSceneCalls(MujocoStiff())

    readings = iter([10.0, 10.25, 20.0, 20.5])
    prepared = mujoco_scene.prepare_scene(HEAD_ON, 2, 1.0, 1e-3, None, Tuning())
    assert mujoco_scene.run_scene(prepared, 0, clock=lambda: next(readings)).wall_s == 0.25
    stepped = mujoco_scene.run_scene(prepared, 5, clock=lambda: next(readings))
    assert stepped.wall_s == 0.5 and stepped.steps == 5
    assert stepped.positions[0][0] > -2.0  # it moved: the 5 steps ran between the readings


@pytest.mark.parametrize(("bodies", "dim", "e", "dt", "message"), [
    (HEAD_ON, 3, 1.0, 1e-3, "components"),
    (HEAD_ON, 2, -1.0, 1e-3, "restitution"),
    (HEAD_ON, 2, 1.0, 0.0, "dt must be positive"),
    ([((0.0, 0.0), 0.5, 0.0, (1.0, 0.0))], 2, 1.0, 1e-3, "mass must be positive"),
    ([((0.0, 0.0), -0.5, 1.0, (1.0, 0.0))], 2, 1.0, 1e-3, "radius must be positive"),
    ([((math.nan, 0.0), 0.5, 1.0, (1.0, 0.0))], 2, 1.0, 1e-3, "finite"),
    (HEAD_ON, 2, 0.0, 1e-3, "outside"),  # tuned: no spring-dashpot has e = 0
])
def test_scene_refuses_bad_input(bodies: list[Any], dim: int, e: float, dt: float,
                                 message: str) -> None:
    mujoco_scene = MujocoSceneCalls(MujocoStiff())

    with pytest.raises(ValueError, match=message):
        mujoco_scene.prepare_scene(bodies, dim, e, dt, None, Tuning())
    with pytest.raises(ValueError, match="steps must be"):
        mujoco_scene.run_scene(
            mujoco_scene.prepare_scene(HEAD_ON, 2, 1.0, 1e-3, None, None), -1)


def test_both_variants_declare_scenes_and_the_stiff_one_skips_e_zero() -> None:
    scene = CASE_ADAPTER.validate_python({
        "id": "s", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": 1.0,
        "restitution": 0.0, "bodies": [{"center": [0.0, 0.0], "radius": 0.5, "mass": 1.0,
                                        "velocity": [1.0, 0.0]}]})
    assert DEFAULT.unsupported(scene) is None
    assert "restitution 0" in (STIFF.unsupported(scene) or "")
