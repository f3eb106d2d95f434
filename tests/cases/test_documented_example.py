"""docs/adding-a-case.md documents every field of the published schema, every case file,
and shows a first case and an error message that are the loader's own."""

from __future__ import annotations

import re
import shlex
from pathlib import Path
from typing import Any

import pytest

from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.core.schema import json_schema
from tests.conftest import ROOT

PAGE = ROOT / "docs" / "adding-a-case.md"


def schema_fields(schema: dict[str, Any]) -> set[str]:
    fields: set[str] = set()
    for definition in [schema, *schema.get("$defs", {}).values()]:
        fields |= set(definition.get("properties", {}))
    return fields


def test_every_schema_field_is_documented() -> None:
    text = PAGE.read_text(encoding="utf-8")
    fields = schema_fields(json_schema())
    assert {"id", "half", "mass_ratio", "logspace", "swap"} <= fields
    missing = sorted(f for f in fields if f"`{f}" not in text)
    assert missing == []


def test_every_case_file_is_a_listed_family() -> None:
    text = PAGE.read_text(encoding="utf-8")
    files = sorted(p.name for p in (ROOT / "cases").glob("*.toml"))
    assert [name for name in files if f"`{name}`" not in text] == []


def test_the_first_example_is_a_valid_case_and_the_shown_error_is_the_loaders(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    text = PAGE.read_text(encoding="utf-8")
    first = re.findall(r"```toml\n(.*?)```", text, flags=re.DOTALL)[0]
    (tmp_path / "first.toml").write_text(first, encoding="utf-8")
    loaded = load_paths([tmp_path / "first.toml"], cache=False)
    assert loaded.errors == []
    assert "sphere-touch-x" in {case.id for case in loaded.cases}
    # The error shown is the loader's on the page's new-case file with A's radius negated.
    command = re.search(r"\n(crosscheck new-case .*?)\n```", text, flags=re.DOTALL)
    shown = re.search(r"```\n(cases/mine\.toml:.*)\n```", text)
    assert command and shown
    monkeypatch.chdir(tmp_path)
    (tmp_path / "cases").mkdir()
    assert main(shlex.split(command.group(1).replace("\\\n", " "))[1:]) == 0
    written = Path("cases/mine.toml").read_text(encoding="utf-8")
    assert "a = { center = [0.0, 0.0, 0.0], radius = 0.5 }" in written
    Path("cases/mine.toml").write_text(written.replace("radius = 0.5", "radius = -0.5", 1),
                                       encoding="utf-8")
    errors = load_paths([Path("cases/mine.toml")], cache=False).errors
    assert [e.message for e in errors] == [shown.group(1)]
