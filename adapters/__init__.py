"""The adapter registry: the built-in table of engine adapters, and plug-ins.

Two routes lead to an engine (docs/adding-an-engine.md):

- built-in: one package in this package (``adapters/<engine>/``: its variants in
  ``__init__``, its engine calls in ``calls.py``) and one line of :data:`REGISTRY` per variant;
- plug-in: a distribution declares an entry point in the ``crosscheck.adapters``
  group (:data:`ENTRY_POINT_GROUP`): its name is the engine's name, its value
  ``"module:Class"`` an :class:`~crosscheck.core.contract.Adapter` subclass.

Each :class:`Entry` names a module and a class and where it comes from; listing
reads only the table and the installed distributions' metadata, and a module is
imported only when its adapter is asked for, so a missing engine shows as
unavailable instead of an ImportError at start-up.

An entry that cannot be used is refused, never skipped in silence and never a
traceback: a module that fails to import (a built-in's too), an object that is not
a concrete Adapter subclass, a class whose ``name`` is not the entry's, a plug-in
whose name is a built-in's (the built-in keeps the name: a plug-in never shadows
it) or another plug-in's (neither is used).  :meth:`Entry.load` raises
:class:`RefusedEngine` with the origin (the distribution and its version) and the
reason; ``crosscheck engines`` lists every entry with its origin and any refusal.
"""

from __future__ import annotations

import importlib
import inspect
from collections import Counter
from dataclasses import dataclass
from importlib.metadata import EntryPoint, entry_points
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the contract (pydantic, numpy) loads with an entry, not with the names
    from crosscheck.core.contract import Adapter

REGISTRY: dict[str, tuple[str, str]] = {
    "reference": ("adapters.reference", "ReferenceF64"),
    "reference-f32": ("adapters.reference", "ReferenceF32"),
    "fcl": ("adapters.fcl", "Fcl"),
    "fcl-ccd-naive": ("adapters.fcl", "FclCcdNaive"),
    "fcl-ccd-ray-shooting": ("adapters.fcl", "FclCcdRayShooting"),
    "fcl-ccd-polynomial": ("adapters.fcl", "FclCcdPolynomial"),
    "pybullet": ("adapters.pybullet", "PyBulletTuned"),
    "pybullet-default": ("adapters.pybullet", "PyBulletDefault"),
    "pybullet-ccd": ("adapters.pybullet", "PyBulletCcd"),
    "pymunk": ("adapters.pymunk", "PymunkTuned"),
    "pymunk-default": ("adapters.pymunk", "PymunkDefault"),
    "mujoco": ("adapters.mujoco", "MujocoStiff"),
    "mujoco-default": ("adapters.mujoco", "MujocoDefault"),
    "coal": ("adapters.coal", "CoalTuned"),
    "coal-default": ("adapters.coal", "CoalDefault"),
    "box2d": ("adapters.box2d", "Box2dTuned"),
    "box2d-default": ("adapters.box2d", "Box2dDefault"),
    "box2d-bullet": ("adapters.box2d", "Box2dBullet"),
    "box2d3": ("adapters.box2d3", "Box2d3Tuned"),
    "box2d3-default": ("adapters.box2d3", "Box2d3Default"),
    "box2d3-bullet": ("adapters.box2d3", "Box2d3Bullet"),
    "rapier": ("adapters.rapier", "RapierTuned"),
    "rapier-default": ("adapters.rapier", "RapierDefault"),
    "rapier-ccd": ("adapters.rapier", "RapierCcd"),
    "drake": ("adapters.drake", "Drake"),
}

ENTRY_POINT_GROUP = "crosscheck.adapters"
"""The entry-point group plug-in distributions declare their adapters in."""
BUILT_IN = "built-in"
"""The origin of an entry of :data:`REGISTRY`."""


class UnknownEngine(KeyError):
    """Raised for an engine name that is neither built in nor declared by a plug-in."""

    def __str__(self) -> str:  # the message, without KeyError's quotes
        return str(self.args[0]) if self.args else ""


class RefusedEngine(UnknownEngine):
    """Raised for an engine that is listed but cannot be used; the message says why."""


@dataclass(frozen=True, slots=True)
class Entry:
    """One engine name, the class it stands for (``module:Class``) and where it comes from.

    ``origin`` is :data:`BUILT_IN` or a plug-in's distribution name and version;
    ``clash`` why its name is refused before anything is imported ('' if it is not).

    >>> entry = Entry("fcl", "adapters.fcl:Fcl")
    >>> entry.builtin, entry.load().__name__
    (True, 'Fcl')
    >>> Entry("x", "no_such_module:X", "dist-x 1.0").problem()
    "import failed: ModuleNotFoundError: No module named 'no_such_module'"
    """

    name: str
    target: str
    origin: str = BUILT_IN
    clash: str = ""

    @property
    def builtin(self) -> bool:
        """Whether the entry is a line of :data:`REGISTRY`."""
        return self.origin == BUILT_IN

    @property
    def verdict(self) -> str:
        """What an unusable entry is called: a built-in is unavailable, a plug-in refused."""
        return "is unavailable" if self.builtin else "is refused"

    def describe(self) -> str:
        """Where the entry comes from, in words."""
        if self.builtin:
            return f"built-in engine {self.name!r} ({self.target})"
        return f"plug-in engine {self.name!r} from distribution {self.origin} ({self.target})"

    def load(self) -> type[Adapter]:
        """The adapter class; raises :class:`RefusedEngine` naming the origin and the reason."""
        found, reason = self._checked()
        if found is None:
            raise RefusedEngine(f"{self.describe()} {self.verdict}: {reason}")
        return found

    def problem(self) -> str | None:
        """Why the entry cannot be used (None: it can); imports its module."""
        return self._checked()[1] or None

    def _checked(self) -> tuple[type[Adapter] | None, str]:
        from crosscheck.core.contract import Adapter

        if self.clash:
            return None, self.clash
        try:
            found = _resolve(self.target)
        except Exception as exc:  # any failure of a plug-in's import is its reason
            return None, f"import failed: {type(exc).__name__}: {exc}"
        wrong = _wrong_class(found, self.name)
        if wrong or not (isinstance(found, type) and issubclass(found, Adapter)):
            return None, wrong
        return found, ""


def _resolve(target: str) -> object:
    module_name, _, attribute = target.partition(":")
    found: object = importlib.import_module(module_name)
    for part in attribute.split("."):
        found = getattr(found, part)
    return found


def _wrong_class(found: object, name: str) -> str:
    """What is wrong with ``found`` as the adapter class of engine ``name`` ('' if nothing)."""
    from crosscheck.core.contract import Adapter

    if not (isinstance(found, type) and issubclass(found, Adapter)):
        return f"it is not an Adapter subclass (it is {type(found).__name__} {found!r})"
    if inspect.isabstract(found):
        missing = ", ".join(sorted(getattr(found, "__abstractmethods__", ())))
        return f"it is abstract: it does not define {missing}"
    declared = getattr(found, "name", None)
    if declared != name:
        return (f"its class declares the name {declared!r}, not {name!r}: its results would "
                f"not be under the name it is chosen by")
    return ""


def _origin(point: EntryPoint) -> str:
    dist = point.dist
    return f"{dist.name} {dist.version}" if dist is not None else "an unknown distribution"


def plugins() -> list[Entry]:
    """Every adapter a distribution declares in :data:`ENTRY_POINT_GROUP`, sorted by name.

    A name that is a built-in's, or that more than one plug-in declares, is
    refused (``clash``); nothing is imported.
    """
    points = sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda p: (p.name, _origin(p)))
    counts = Counter(p.name for p in points)
    found = []
    for point in points:
        clash = ""
        if point.name in REGISTRY:
            clash = f"its name clashes with the built-in engine {point.name!r}, which keeps it"
        elif counts[point.name] > 1:
            others = [_origin(p) for p in points if p.name == point.name and p is not point]
            clash = f"{', '.join(others)} also declare(s) {point.name!r}: neither is used"
        found.append(Entry(point.name, f"{point.module}:{point.attr}", _origin(point), clash))
    return found


def entries() -> list[Entry]:
    """Every entry: the built-ins in registry order, then the plug-ins (clashing ones too)."""
    builtins = [Entry(name, f"{module}:{cls}") for name, (module, cls) in REGISTRY.items()]
    return builtins + plugins()


def names() -> list[str]:
    """Every built-in adapter name, in registry order."""
    return list(REGISTRY)


def all_names() -> list[str]:
    """Every engine name: built-ins, then plug-ins (a refused plug-in too, so that asking
    for it says why it is refused)."""
    return list(dict.fromkeys(entry.name for entry in entries()))


def find(name: str) -> Entry:
    """The entry that answers to ``name``: the built-in, else the one plug-in of that name."""
    if name in REGISTRY:
        module, cls = REGISTRY[name]
        return Entry(name, f"{module}:{cls}")
    candidates = [entry for entry in plugins() if entry.name == name]
    if not candidates:
        raise UnknownEngine(f"unknown engine {name!r}; known: {', '.join(all_names())}")
    return candidates[0]


def adapter_class(name: str) -> type[Adapter]:
    """The adapter class called ``name``; raises UnknownEngine or RefusedEngine."""
    return find(name).load()


def get(name: str) -> Adapter:
    """Instantiate the adapter called ``name``; raises UnknownEngine or RefusedEngine."""
    return adapter_class(name)()
