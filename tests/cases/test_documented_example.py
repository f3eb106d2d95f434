"""cases/README.md documents every field of the published schema."""

from __future__ import annotations

from typing import Any

from crosscheck.core.schema import json_schema
from tests.conftest import ROOT


def schema_fields(schema: dict[str, Any]) -> set[str]:
    fields: set[str] = set()
    for definition in [schema, *schema.get("$defs", {}).values()]:
        fields |= set(definition.get("properties", {}))
    return fields


def test_every_schema_field_is_documented() -> None:
    text = (ROOT / "cases" / "README.md").read_text()
    fields = schema_fields(json_schema())
    assert {"id", "half", "mass_ratio", "logspace", "swap"} <= fields
    missing = sorted(f for f in fields if f"`{f}" not in text)
    assert missing == []


def test_every_case_file_is_a_listed_family() -> None:
    text = (ROOT / "cases" / "README.md").read_text()
    files = sorted(p.name for p in (ROOT / "cases").glob("*.toml"))
    assert [name for name in files if f"`{name}`" not in text] == []
