"""The version matrix: ``--engine NAME@VERSION`` runs a variant in the interpreter of a cached
environment holding that version of its package (crosscheck.run.envs, crosscheck.run.pinned).

The package is a fake one, ``crosscheck-fake-engine`` at 1.0 and 2.0, written as wheels into
a folder that pip is pointed at (``PIP_NO_INDEX``, ``PIP_FIND_LINKS``): no network, and the
harness's own environment never has it, so an answer can only come from a pinned worker.
"""

from __future__ import annotations

import base64
import hashlib
import json
import pickle
import zipfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER
from crosscheck.results.run import read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run import envs, pinned
from crosscheck.run.launch import launch, new_info
from tests.run.versioned_fake import MODULE, PACKAGE, VersionedFake

OFFSETS = {"1.0": 0.0, "2.0": 0.5}
BROKEN = "0.9"
"""A version that installs but cannot be imported (as a wheel built against another numpy)."""
CASE = CASE_ADAPTER.validate_python({
    "id": "spheres-apart", "description": "a gap of 0.5", "kind": "sphere", "dim": 3,
    "a": {"center": [0, 0, 0], "radius": 0.5}, "b": {"center": [1.5, 0, 0], "radius": 0.5}})


def wheel(folder: Path, version: str, module: str) -> Path:
    """A pure-Python wheel of the fake package (PEP 427: a zip with its dist-info)."""
    dist = f"{PACKAGE.replace('-', '_')}-{version}"
    files = {
        f"{MODULE}.py": module,
        f"{dist}.dist-info/METADATA": (f"Metadata-Version: 2.1\nName: {PACKAGE}\n"
                                       f"Version: {version}\n"),
        f"{dist}.dist-info/WHEEL": ("Wheel-Version: 1.0\nGenerator: crosscheck-tests\n"
                                    "Root-Is-Purelib: true\nTag: py3-none-any\n"),
    }
    record = []
    for name, text in files.items():
        digest = base64.urlsafe_b64encode(hashlib.sha256(text.encode()).digest()).rstrip(b"=")
        record.append(f"{name},sha256={digest.decode()},{len(text.encode())}")
    files[f"{dist}.dist-info/RECORD"] = "\n".join([*record, f"{dist}.dist-info/RECORD,,"]) + "\n"
    path = folder / f"{dist}-py3-none-any.whl"
    with zipfile.ZipFile(path, "w") as archive:
        for name, text in files.items():
            archive.writestr(name, text)
    return path


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A cache root, with pip pointed at a folder holding the fake package's two wheels."""
    wheels = tmp_path_factory.mktemp("wheels")
    for version, offset in OFFSETS.items():
        wheel(wheels, version, f"OFFSET = {offset!r}\n")
    wheel(wheels, BROKEN, 'raise ImportError("built against another numpy")\n')
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("PIP_NO_INDEX", "1")
        patch.setenv("PIP_FIND_LINKS", str(wheels))
        root = tmp_path_factory.mktemp("envs")
        patch.setenv("CROSSCHECK_ENVS", str(root))
        yield root


def test_an_environment_holds_the_version_asked_for_and_is_reused(cache: Path) -> None:
    env = envs.ensure(PACKAGE, "1.0")
    assert env.path.parent == cache and env.ready()
    marker = json.loads((env.path / envs.MARKER).read_text())
    assert (marker["package"], marker["version"]) == (PACKAGE, "1.0")
    said: list[str] = []
    assert envs.ensure(PACKAGE, "1.0", said.append) == env and said == []  # cached: no build
    assert [e.version for e in envs.cached() if e.package == PACKAGE] == ["1.0"]


def test_a_version_pip_cannot_find_is_an_error_that_leaves_nothing(cache: Path) -> None:
    with pytest.raises(envs.EnvError, match=r"crosscheck-fake-engine==9\.9"):
        envs.ensure(PACKAGE, "9.9")
    assert not [path for path in cache.glob("*9.9*") if path.is_dir()]


def test_pinned_variants_answer_with_their_own_versions_side_by_side(
        cache: Path, tmp_path: Path) -> None:
    engines = [pinned.pin(VersionedFake, envs.ensure(PACKAGE, v))() for v in OFFSETS]
    assert [e.name for e in engines] == ["fake-versioned@1.0", "fake-versioned@2.0"]
    assert [e.version() for e in engines] == ["1.0", "2.0"]
    options = RunOptions(quick=True, jobs=1)
    folder = tmp_path / "run"
    launch(ResultsStore(folder), [CASE], engines, options,
           new_info(folder, "test", options, engines, [CASE]))
    stored = read_run(folder)
    rows = stored.results.set_index(["engine", "quantity"])
    assert rows.loc[("fake-versioned@1.0", "distance"), "status"] == "agree"
    assert rows.loc[("fake-versioned@2.0", "distance"), "status"] == "disagree"
    gap = float(rows.loc[("fake-versioned@2.0", "distance"), "value"]) - float(
        rows.loc[("fake-versioned@1.0", "distance"), "value"])
    assert gap == OFFSETS["2.0"] - OFFSETS["1.0"]
    recorded = {e["name"]: e["version"] for e in json.loads(
        (folder / "run.json").read_text())["engines"]}
    assert recorded == {"fake-versioned@1.0": "1.0", "fake-versioned@2.0": "2.0"}


def test_a_worker_whose_environment_has_another_version_answers_nothing(
        cache: Path, tmp_path: Path) -> None:
    # an environment folder holding 1.0, presented as 3.0: the worker finds out and says so
    real = envs.ensure(PACKAGE, "1.0")
    liar = pinned.pin(VersionedFake, envs.PinnedEnv(PACKAGE, "3.0", real.path))()
    options = RunOptions(quick=True, jobs=1)
    folder = tmp_path / "run"
    launch(ResultsStore(folder), [CASE], [liar], options,
           new_info(folder, "test", options, [liar], [CASE]))
    rows = read_run(folder).results
    assert set(rows["status"]) == {"skip"}
    assert rows["reason"].str.contains(f"has {PACKAGE} 1.0, not 3.0").all()


def test_a_version_that_installs_but_cannot_run_is_refused_before_any_case(cache: Path) -> None:
    env = envs.ensure(PACKAGE, BROKEN)
    with pytest.raises(envs.EnvError, match=r"cannot run in .*built against another numpy"):
        pinned.pin(VersionedFake, env)


def test_a_pinned_class_pickles_by_reference(cache: Path) -> None:
    cls = pinned.pin(VersionedFake, envs.ensure(PACKAGE, "2.0"))
    assert pickle.loads(pickle.dumps(cls)) is cls
    assert pinned.environment(cls) == envs.find(PACKAGE, "2.0")
    assert pinned.environment(VersionedFake) is None


@pytest.mark.parametrize("parts", [
    ("adapters.pymunk_engine", "PymunkTuned", "pymunk", "6.11.1", "/root/.cache/e"),
    ("tests.run.versioned_fake", "VersionedFake", "crosscheck-fake-engine", "1.0rc1+local_2",
     "/tmp/a b/é/水"),
    ("a__b", "C_", "x-y", "1!2.0.post3", "_"),
])
def test_a_pinned_class_name_decodes_to_what_made_it(parts: tuple[str, ...]) -> None:
    name = pinned._encode(*parts)
    assert "." not in name and name.count(pinned.SEPARATOR) == 5
    assert pinned._decode(name) == parts


def test_an_engine_without_a_package_cannot_be_pinned(cache: Path) -> None:
    from crosscheck.testing.fakes import AlwaysRight

    with pytest.raises(envs.EnvError, match="names no package"):
        pinned.pin(AlwaysRight, envs.find(PACKAGE, "1.0"))


@pytest.mark.parametrize(("argv", "message"), [
    (["--engine", "pymunk@>=6"], "is not a version number"),
    (["--engine", "nosuch@1.0"], "invalid choice: 'nosuch'"),
    (["--engine", "pymunk@6.11.1", "--no-isolation"], "cannot be combined with --no-isolation"),
])
def test_run_refuses_a_bad_pinned_engine_before_any_work(
        argv: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cases = tmp_path / "c.toml"
    cases.write_text("")
    with pytest.raises(SystemExit) as stopped:
        code = main(["run", str(cases), "--out", str(tmp_path / "out"), *argv])
        raise SystemExit(code)
    assert stopped.value.code == 2
    assert message in capsys.readouterr().err.replace("\n", " ")
    assert not (tmp_path / "out").exists()
