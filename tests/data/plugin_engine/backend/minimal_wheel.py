"""A minimal in-tree PEP 517 build backend, for the test plug-in only.

The shared test venv has setuptools 65 without ``wheel`` (so ``setuptools.build_meta``
cannot build a wheel there) and the test installs with ``--no-build-isolation``, which
downloads nothing.  This backend builds a pure-Python wheel from ``pyproject.toml``'s
``[project]`` table (name, version, dependencies, entry points) and the project's
``*.py`` files outside ``backend/`` (top-level modules and packages).  A real plug-in
uses setuptools, hatchling or flit instead.
"""

from __future__ import annotations

import base64
import hashlib
import tomllib
import zipfile
from pathlib import Path
from typing import Any

WHEEL = "Wheel-Version: 1.0\nGenerator: minimal_wheel\nRoot-Is-Purelib: true\nTag: py3-none-any\n"


def _metadata(project: dict[str, Any]) -> dict[str, str]:
    """The dist-info files: METADATA, WHEEL and entry_points.txt."""
    lines = ["Metadata-Version: 2.1", f"Name: {project['name']}",
             f"Version: {project['version']}"]
    lines += [f"Requires-Dist: {d}" for d in project.get("dependencies", [])]
    points = []
    for group, entries in project.get("entry-points", {}).items():
        points += [f"[{group}]", *(f"{k} = {v}" for k, v in entries.items()), ""]
    return {"METADATA": "\n".join(lines) + "\n", "WHEEL": WHEEL,
            "entry_points.txt": "\n".join(points)}


def _record(path: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{path},sha256={digest},{len(data)}"


def build_wheel(wheel_directory: str, config_settings: Any = None,
                metadata_directory: Any = None) -> str:
    """Write ``<name>-<version>-py3-none-any.whl`` into ``wheel_directory``; its file name."""
    project = tomllib.loads(Path("pyproject.toml").read_text(encoding="utf-8"))["project"]
    stem = f"{project['name'].replace('-', '_')}-{project['version']}"
    files = {p.as_posix(): p.read_bytes() for p in sorted(Path().rglob("*.py"))
             if p.parts[0] != "backend" and "__pycache__" not in p.parts}
    files |= {f"{stem}.dist-info/{k}": v.encode() for k, v in _metadata(project).items()}
    record = [_record(path, data) for path, data in files.items()]
    record.append(f"{stem}.dist-info/RECORD,,")
    files[f"{stem}.dist-info/RECORD"] = "\n".join([*record, ""]).encode()
    name = f"{stem}-py3-none-any.whl"
    with zipfile.ZipFile(Path(wheel_directory) / name, "w") as wheel:
        for path, data in files.items():
            wheel.writestr(path, data)
    return name


def build_sdist(sdist_directory: str, config_settings: Any = None) -> str:
    """Not needed to install from the source folder."""
    raise NotImplementedError("minimal_wheel builds wheels only")
