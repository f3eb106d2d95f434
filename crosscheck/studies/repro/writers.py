"""Which script writer makes the engine part of a repro script, for each adapter class.

Every built-in variant has one (all 15: the textbook formula in float64 and float32, FCL,
PyBullet, pymunk, MuJoCo, coal, Box2D and Rapier, tuned and default), for every kind it
runs, scenes included (PyBullet, pymunk, MuJoCo, Box2D and Rapier step them), and times of
impact (``sphere_toi``: FCL and its three CCD variants, Box2D and Rapier, in
:mod:`~crosscheck.studies.repro.toi`; the textbook's sampled test has no script yet).  The table
is keyed by the exact class: a subclass (a plug-in's) may make other calls, so it has no
writer until it is given one here.  A writer takes the adapter, the case and the quantities
the run recorded as a declared hang (FCL's signed distance), and returns an
:class:`~crosscheck.studies.repro.code.EngineCode`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from adapters.box2d_engine import Box2dDefault, Box2dTuned
from adapters.ccd_variants import Box2dBullet, PyBulletCcd, RapierCcd
from adapters.coal_engine import CoalDefault, CoalTuned
from adapters.fcl_engine import Fcl, FclCcdNaive, FclCcdPolynomial, FclCcdRayShooting
from adapters.mujoco_engine import MujocoDefault, MujocoStiff
from adapters.pybullet_engine import PyBulletDefault, PyBulletTuned
from adapters.pymunk_engine import PymunkDefault, PymunkTuned
from adapters.rapier_engine import RapierDefault, RapierTuned
from adapters.reference import ReferenceF32, ReferenceF64
from crosscheck.core.contract import Adapter
from crosscheck.core.schema import AnyCase, SceneCase, ToiCase
from crosscheck.studies.repro.coal import coal_code
from crosscheck.studies.repro.code import EngineCode
from crosscheck.studies.repro.engines import fcl_code, pymunk_code, reference_code
from crosscheck.studies.repro.pybullet import pybullet_code
from crosscheck.studies.repro.scenes import pybullet_scene_code, pymunk_scene_code
from crosscheck.studies.repro.scenes_box2d import box2d_writer
from crosscheck.studies.repro.scenes_mujoco import mujoco_writer
from crosscheck.studies.repro.scenes_rapier import rapier_writer
from crosscheck.studies.repro.toi import fcl_toi_code, reference_toi_code

Writer = Callable[[Any, AnyCase, frozenset[str]], EngineCode]
"""A script writer: (adapter, case, quantities the run recorded as a declared hang)."""


class NoScene(ValueError):
    """An engine was handed a kind its writer has no script for: a scene for a pair engine,
    or a time of impact for an engine without that query (or without its script)."""


def _no_toi(name: str, case: AnyCase) -> None:
    if isinstance(case, ToiCase):
        raise NoScene(f"no repro script for sphere_toi on {name}")


def _pairs_only(write: Callable[[Any, Any], EngineCode]) -> Writer:
    def writer(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
        if isinstance(case, SceneCase):
            raise NoScene(f"{adapter.name} does not step scenes")
        _no_toi(adapter.name, case)
        return write(adapter, case)
    return writer


def _fcl(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    if isinstance(case, SceneCase):
        raise NoScene("fcl does not step scenes")
    if isinstance(case, ToiCase):
        return fcl_toi_code(adapter.solver, case)
    return fcl_code(case, hung)


def _pybullet(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    if isinstance(case, SceneCase):
        return pybullet_scene_code(adapter, case)
    if isinstance(case, ToiCase):
        raise NoScene("pybullet declares no time-of-impact capability")
    return pybullet_code(adapter, case)


def _pymunk(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    if isinstance(case, SceneCase):
        return pymunk_scene_code(adapter, case)
    if isinstance(case, ToiCase):
        raise NoScene("pymunk declares no time-of-impact capability")
    return pymunk_code(adapter, case)


def _reference(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    if isinstance(case, SceneCase):
        raise NoScene(f"{adapter.name} does not step scenes")
    if isinstance(case, ToiCase):
        return reference_toi_code(adapter.precision, case)
    return reference_code(adapter, case)


def _mujoco(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    _no_toi(adapter.name, case)
    return mujoco_writer(adapter, case, hung)


WRITERS: dict[type[Adapter], Writer] = {
    ReferenceF64: _reference,
    ReferenceF32: _reference,
    Fcl: _fcl,
    FclCcdNaive: _fcl,
    FclCcdRayShooting: _fcl,
    FclCcdPolynomial: _fcl,
    PyBulletTuned: _pybullet,
    PyBulletDefault: _pybullet,
    PyBulletCcd: _pybullet,
    PymunkTuned: _pymunk,
    PymunkDefault: _pymunk,
    MujocoStiff: _mujoco,
    MujocoDefault: _mujoco,
    CoalTuned: _pairs_only(coal_code),
    CoalDefault: _pairs_only(coal_code),
    Box2dTuned: box2d_writer,
    Box2dDefault: box2d_writer,
    Box2dBullet: box2d_writer,
    RapierTuned: rapier_writer,
    RapierDefault: rapier_writer,
    RapierCcd: rapier_writer,
}
"""The script writer of each adapter class (exact classes: a subclass may call otherwise)."""


def writer_for(adapter: Adapter) -> Writer | None:
    """The script writer of ``adapter``'s exact class, or None."""
    return WRITERS.get(type(adapter))
