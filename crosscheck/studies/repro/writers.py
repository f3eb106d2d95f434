"""The old script writers, temporary, for what is not yet calls of an engine's calls module.

An adapter's pairs, responses and times of impact are made from its calls module
(:mod:`~crosscheck.studies.repro.calls`); left here, keyed by exact class: every stepping
engine's scenes (PyBullet and its CCD variant, pymunk, Box2D and its bullet variant, Rapier
and its CCD variant, MuJoCo).  A writer takes the adapter,
the case and the quantities the run recorded as a declared hang, and returns an
:class:`~crosscheck.studies.repro.code.EngineCode`.  The table goes when they are calls too.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from adapters.box2d import Box2dBullet, Box2dDefault, Box2dTuned
from adapters.mujoco import MujocoDefault, MujocoStiff
from adapters.pybullet import PyBulletCcd, PyBulletDefault, PyBulletTuned
from adapters.pymunk import PymunkDefault, PymunkTuned
from adapters.rapier import RapierCcd, RapierDefault, RapierTuned
from crosscheck.core.contract import Adapter
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.studies.repro.code import EngineCode
from crosscheck.studies.repro.scenes import pybullet_scene_code, pymunk_scene_code
from crosscheck.studies.repro.scenes_box2d import box2d_writer
from crosscheck.studies.repro.scenes_mujoco import mujoco_writer
from crosscheck.studies.repro.scenes_rapier import rapier_writer

Writer = Callable[[Any, AnyCase, frozenset[str]], EngineCode]
"""A script writer: (adapter, case, quantities the run recorded as a declared hang)."""


class NoScene(ValueError):
    """An engine was handed a kind its writer has no script for: a scene for a pair engine,
    or a time of impact for an engine without that query (or without its script)."""


def _pybullet(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    if isinstance(case, SceneCase):
        return pybullet_scene_code(adapter, case)
    raise NoScene("pybullet's pairs are calls of adapters.pybullet.calls")


def _pymunk(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    if isinstance(case, SceneCase):
        return pymunk_scene_code(adapter, case)
    raise NoScene("pymunk's pairs are calls of adapters.pymunk.calls")


def _mujoco(adapter: Any, case: AnyCase, hung: frozenset[str]) -> EngineCode:
    if isinstance(case, SceneCase):
        return mujoco_writer(adapter, case, hung)
    raise NoScene("mujoco's pairs are calls of adapters.mujoco.calls")


WRITERS: dict[type[Adapter], Writer] = {
    PyBulletTuned: _pybullet,
    PyBulletDefault: _pybullet,
    PyBulletCcd: _pybullet,
    PymunkTuned: _pymunk,
    PymunkDefault: _pymunk,
    MujocoStiff: _mujoco,
    MujocoDefault: _mujoco,
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
