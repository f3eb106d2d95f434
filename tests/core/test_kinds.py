"""One spec per kind (:mod:`crosscheck.core.kinds`): it covers every kind and every quantity an
observation carries, the schema class it names is of its kind, and no module keeps a table of
kinds of its own (the truth and judge it names: ``tests/truth/test_kind_rules.py``)."""

from __future__ import annotations

import ast
from dataclasses import fields
from pathlib import Path
from typing import get_args

import pytest

from crosscheck.core import schema
from crosscheck.core.kinds import (
    KIND_ORDER,
    SPECS,
    Kind,
    KindSpec,
    error_columns,
    every_quantity,
    quantity_named,
    spec,
)
from crosscheck.core.model import Observation
from tests.conftest import ROOT

SPEC_MODULE = ROOT / "crosscheck" / "core" / "kinds.py"
SOURCES = sorted(p for folder in ("crosscheck", "adapters", "reference_impl", "tools")
                 for p in (ROOT / folder).rglob("*.py"))


def test_every_kind_has_one_spec() -> None:
    assert sorted(s.kind for s in SPECS) == sorted(Kind)
    assert tuple(str(s.kind) for s in SPECS) == KIND_ORDER


def test_every_field_of_an_observation_is_a_quantity_or_an_extra_of_some_kind() -> None:
    carried = {name for s in SPECS for name in (*s.names, *s.extras)}
    assert carried == {f.name for f in fields(Observation)}


@pytest.mark.parametrize("kind", SPECS, ids=lambda s: str(s.kind))
def test_the_quantities_a_spec_names_are_its_own(kind: KindSpec) -> None:
    named = [*kind.required, *kind.charted, *([kind.fallback] if kind.fallback else [])]
    if kind.speed is not None:
        named += [*kind.speed.errors, *kind.speed.verdicts]
    assert set(named) <= set(kind.names)
    assert not set(kind.extras) & set(kind.names)
    assert kind.headline == kind.charted[0]


def test_a_quantity_is_the_same_in_every_kind_that_scores_it() -> None:
    for kind in SPECS:
        for quantity in kind.quantities:
            assert quantity_named(quantity.name) is quantity
    assert {q for qs in error_columns().values() for q in qs} == {
        q.name for q in every_quantity() if q.error_column}


@pytest.mark.parametrize("kind", SPECS, ids=lambda s: str(s.kind))
def test_the_schema_class_a_spec_names_is_of_its_kind(kind: KindSpec) -> None:
    case_class = schema.case_class(kind.kind)
    assert case_class.__name__ == kind.case
    assert get_args(case_class.model_fields["kind"].annotation) == (kind.kind.value,)


def test_every_schema_class_is_a_kinds() -> None:
    assert sorted(c.__name__ for c in get_args(schema.AnyCase)) == sorted(s.case for s in SPECS)


def test_a_name_that_is_no_kind_has_no_spec() -> None:
    with pytest.raises(ValueError, match="box"):
        spec("box")


# --- no table of kinds outside the spec -----------------------------------------------------


def _is_kind(node: ast.expr | None) -> bool:
    """A kind's name as a string, or a member of :class:`Kind` (``Kind.AABB``)."""
    if isinstance(node, ast.Constant):
        return node.value in KIND_ORDER
    return (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
            and node.value.id == "Kind" and node.attr in Kind.__members__)


def kind_tables(source: str) -> list[int]:
    """The lines of the dict literals keyed by two kinds or more: a table of kinds (a dict
    keyed by ``"sphere"`` alone may be keyed by features, ``"sphere"`` among ``"face"``...)."""
    return [node.lineno for node in ast.walk(ast.parse(source))
            if isinstance(node, ast.Dict) and sum(map(_is_kind, node.keys)) >= 2]


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_module_but_the_spec_keeps_a_table_of_kinds(path: Path) -> None:
    if path != SPEC_MODULE:
        assert kind_tables(path.read_text(encoding="utf-8")) == []


def test_the_table_check_can_fail() -> None:
    source = ('HEADLINE = {"aabb": "distance", "sphere": "distance"}\n'
              'REQUIRED = {Kind.AABB: ("hit",), Kind.SPHERE_TOI: ("hit",)}\n'
              'TOUCHING = {"sphere": False, "face": True}\n')
    assert kind_tables(source) == [1, 2]
