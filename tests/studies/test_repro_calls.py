"""Any adapter whose engine calls are a module gets a repro script: a plug-in's too.

A toy engine (spheres in plain Python) is declared the way a plug-in would be, outside the
harness: a calls module of plain functions and a :class:`CallsAdapter` naming it.  Its script
is that module's source with the case's exact inputs; run in a fresh process, in a folder
where the module cannot be imported, it prints what the adapter answers, string for string.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import ClassVar

import pytest

from crosscheck.core.contract import (
    Call,
    CallsAdapter,
    Capability,
    Conventions,
    all_capabilities,
)
from crosscheck.core.model import Kind, Undefined, quantities_of
from crosscheck.core.schema import AabbCase, ResponseCase, SphereCase
from crosscheck.core.values import encode
from crosscheck.studies.repro.calls import included
from crosscheck.studies.repro.script import ReproError, engine_part, script_text
from tests.conftest import aabb, sphere

TOY_CALLS = '''\
"""Toy spheres: the distance between two spheres, plain Python."""

import math

from adapters.shared import to3


def spheres(a_center, a_radius, b_center, b_radius):
    return {"d": [y - x for x, y in zip(to3(a_center), to3(b_center))],
            "radii": a_radius + b_radius, "dim": len(a_center)}


def distance(built):
    length = math.sqrt(math.fsum(x * x for x in built["d"]))
    if not length > 0:
        return {"hit": True, "distance": -built["radii"], "normal": "coincident centres"}
    normal = tuple(x / length for x in built["d"][:built["dim"]])
    return {"hit": length < built["radii"], "distance": length - built["radii"],
            "normal": normal}
'''


class ToySpheres(CallsAdapter):
    """A plug-in's adapter: its calls are the module ``toy_spheres_calls``."""

    name: ClassVar[str] = "toy-spheres"
    engine: ClassVar[str] = "toy"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE)
    conventions: ClassVar[Conventions] = Conventions(rtol=2.0**-50, sources=("https://x.org",))
    calls: ClassVar[str] = "toy_spheres_calls"

    def version(self) -> str:
        return "0"

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        assert isinstance(case, SphereCase)
        return Call("spheres", "distance", {
            "a_center": case.a.center, "a_radius": case.a.radius,
            "b_center": case.b.center, "b_radius": case.b.radius})


@pytest.fixture
def toy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> ToySpheres:
    plugin = tmp_path / "plugin"
    plugin.mkdir()
    (plugin / "toy_spheres_calls.py").write_text(TOY_CALLS, encoding="utf-8")
    monkeypatch.syspath_prepend(str(plugin))
    monkeypatch.delitem(sys.modules, "toy_spheres_calls", raising=False)
    return ToySpheres()


@pytest.mark.parametrize("case", [
    sphere(0.0, 0.1 + 0.2, ra=0.15, rb=0.15),
    sphere(0.0, 3.0, dim=2),
    sphere(1.0, 1.0),
], ids=["float-trap", "apart-2d", "coincident"])
def test_a_plugins_script_prints_what_its_adapter_answers(
        toy: ToySpheres, case: SphereCase, tmp_path: Path) -> None:
    info = {"name": toy.name, "engine": toy.engine, "settings": toy.settings}
    text = script_text(case, engine_part(toy, case), info, [], [], "test")
    assert "import toy_spheres_calls" not in text
    assert not [line for line in text.splitlines() if line.startswith("from adapters")]
    path = tmp_path / "repro.py"
    path.write_text(text, encoding="utf-8")
    elsewhere = tmp_path / "cwd"
    elsewhere.mkdir()
    done = subprocess.run([sys.executable, str(path)], cwd=elsewhere, capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    printed = {}
    for line in done.stdout.splitlines():
        name, _, value = line.partition(" = ")
        if name in quantities_of(Kind.SPHERE):
            printed[name] = json.loads(value)
    observed = toy.observe(case)
    want = {}
    for q in quantities_of(Kind.SPHERE):
        value = observed.get(q)
        want[q] = None if isinstance(value, Undefined) else json.loads(encode(value))
    assert printed == want


def test_a_shared_helper_is_included_as_source(toy: ToySpheres) -> None:
    text, helpers = included(toy.calls_module())
    assert [m.__name__ for m in helpers] == ["adapters.shared"]
    assert "from adapters.shared import to3" not in text
    assert "def to3(" in engine_part(toy, sphere(0.0, 3.0)).code


class ToyResponses(CallsAdapter):
    """A calls adapter of responses only: no pair protocol."""

    name: ClassVar[str] = "toy-responses"
    engine: ClassVar[str] = "toy"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE_RESPONSE)
    conventions: ClassVar[Conventions] = ToySpheres.conventions
    calls: ClassVar[str] = "toy_spheres_calls"

    def version(self) -> str:
        return "0"

    def response_call(self, case: ResponseCase) -> Call:
        return Call("spheres", "distance")


def test_a_kind_the_adapter_makes_no_call_for_has_no_script(toy: ToySpheres) -> None:
    box = aabb([0.0, 0.0], [1.0, 1.0], [3.0, 0.0], [1.0, 1.0])
    with pytest.raises(AssertionError):
        toy.call(box)  # its pair call takes spheres only
    with pytest.raises(NotImplementedError, match="no call for sphere"):
        ToyResponses().call(sphere(0.0, 3.0))
    with pytest.raises(ReproError, match="no call for sphere"):
        engine_part(ToyResponses(), sphere(0.0, 3.0))
