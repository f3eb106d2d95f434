"""An engine variant at another version of its package: ``crosscheck run --engine NAME@VERSION``.

:func:`pin` makes, from an adapter class and a cached environment
(:mod:`crosscheck.run.envs`), a subclass that differs only in what a run records and where
it runs:

- its ``name`` and ``engine`` carry the version (``pymunk@6.11.1``), so its rows, its
  worker and its timings are its own, beside the unpinned variant's in the same run;
- its ``version()`` is the engine's version string as the environment's interpreter reports
  it (asked once, when the class is made);
- :class:`~crosscheck.run.worker.WorkerPool` starts its worker with the environment's
  interpreter (:func:`environment`), whose ``sys.path`` puts the pinned package first;
- in that worker, ``available()`` checks that the package imported is the pinned version,
  so a row can never be labelled with a version that did not answer it.

Everything else (capabilities, conventions, settings, the queries themselves) is the base
class's: the same adapter code drives the other version of the engine.  A pinned class
pickles by reference like any adapter class: its qualified name encodes the base class and
the version and the environment's folder, and this module's ``__getattr__`` makes it again
in a worker or a Dask process.

>>> _encode("adapters.pymunk_engine", "PymunkTuned", "pymunk", "6.11.1", "/e")
'Pinned__adapters-2epymunk-5fengine__PymunkTuned__pymunk__6-2e11-2e1__-2fe'
>>> _decode(_encode("adapters.pymunk_engine", "PymunkTuned", "pymunk", "6.11.1", "/e"))
('adapters.pymunk_engine', 'PymunkTuned', 'pymunk', '6.11.1', '/e')
"""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from importlib import metadata
from pathlib import Path
from typing import Any

from crosscheck.core.contract import Adapter
from crosscheck.run import envs

PREFIX = "Pinned"
SEPARATOR = "__"
_CLASSES: dict[str, type[Adapter]] = {}
_VERSIONS: dict[tuple[str, str, str], str] = {}


def _escape(text: str) -> str:
    """``text`` as an identifier fragment without ``.`` or ``_`` (pickle splits a qualified
    name on dots; the parts are joined by ``__``): every character outside [A-Za-z0-9] is
    written as its UTF-8 bytes, ``-XX`` each."""
    return "".join(c if c.isascii() and c.isalnum() else
                   "".join(f"-{byte:02x}" for byte in c.encode()) for c in text)


def _unescape(text: str) -> str:
    out, i = bytearray(), 0
    while i < len(text):
        if text[i] == "-":
            out.append(int(text[i + 1:i + 3], 16))
            i += 3
        else:
            out += text[i].encode()
            i += 1
    return out.decode()


def _encode(module: str, qualname: str, package: str, version: str, path: str) -> str:
    return SEPARATOR.join([PREFIX, *(_escape(p) for p in (module, qualname, package, version,
                                                          path))])


def _decode(name: str) -> tuple[str, str, str, str, str]:
    parts = name.split(SEPARATOR)
    if len(parts) != 6 or parts[0] != PREFIX:
        raise AttributeError(name)
    module, qualname, package, version, path = (_unescape(p) for p in parts[1:])
    return module, qualname, package, version, path


def split(name: str) -> tuple[str, str | None]:
    """An engine name as ``--engine`` takes it: the variant and the version (None: pinned by
    the harness's own environment).

    >>> split("pymunk@6.11.1"), split("fcl")
    (('pymunk', '6.11.1'), ('fcl', None))
    """
    base, at, version = name.partition("@")
    return (base, version) if at else (base, None)


def pin(base: type[Adapter], env: envs.PinnedEnv) -> type[Adapter]:
    """``base`` run at the version of its package that ``env`` holds (made once per process).

    Raises :class:`~crosscheck.run.envs.EnvError` if the environment's interpreter cannot
    make the adapter or report its version.
    """
    if not base.package:
        raise envs.EnvError(f"{base.name} names no package on the index, so it has no "
                            "version to choose")
    if base.package != env.package:
        raise envs.EnvError(f"{base.name} runs {base.package}, not {env.package}")
    key = _encode(base.__module__, base.__qualname__, env.package, env.version, str(env.path))
    made = _CLASSES.get(key)
    if made is None:
        made = _CLASSES[key] = _make(base, env, key)
    return made


def _make(base: type[Adapter], env: envs.PinnedEnv, key: str) -> type[Adapter]:
    label = f"{base.name}@{env.version}"
    reported = _reported_version(base, env)

    def version(self: Adapter) -> str:
        return reported

    def available(self: Adapter) -> str | None:
        if Path(sys.prefix).resolve() != env.path.resolve():
            return None if env.ready() else f"the environment {env.path} is not built"
        try:
            found = metadata.version(env.package)
        except metadata.PackageNotFoundError:
            found = "none"
        if found != env.version:
            return f"{label}: this worker has {env.package} {found}, not {env.version}"
        return base.available(self)

    namespace: dict[str, Any] = {
        "__module__": __name__, "__qualname__": key, "name": label,
        "engine": f"{base.engine}@{env.version}", "pinned": env,
        "version": version, "available": available,
        "__doc__": f"{base.__doc__ or base.name} -- with {env.package} {env.version}."}
    made: type[Adapter] = type(key, (base,), namespace)  # ABCMeta, from the base
    return made


def _reported_version(base: type[Adapter], env: envs.PinnedEnv) -> str:
    """``base().version()`` as the environment's interpreter answers it; EnvError if the
    engine cannot run there (``available()`` gives a reason: a wheel built against another
    numpy, say), before any case runs."""
    cache_key = (base.__module__, base.__qualname__, str(env.path))
    if cache_key in _VERSIONS:
        return _VERSIONS[cache_key]
    if "." in base.__qualname__:
        raise envs.EnvError(f"{base.__qualname__}: a nested adapter class cannot be pinned")
    script = (f"import json; from {base.__module__} import {base.__qualname__} as m; "
              "a = m(); print(json.dumps([a.version(), a.available()]))")
    try:
        done = subprocess.run([str(env.python), "-c", script], capture_output=True, text=True,
                              timeout=120, check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise envs.EnvError(f"{env.python} cannot start: {exc}") from None
    label = f"{base.name} with {env.package} {env.version}"
    if done.returncode != 0:
        tail = "\n".join(done.stderr.strip().splitlines()[-4:])
        raise envs.EnvError(f"{label} fails: {tail}")
    version, problem = json.loads(done.stdout.strip().splitlines()[-1])
    if problem:
        raise envs.EnvError(f"{label} cannot run in {env.path}: {problem}")
    _VERSIONS[cache_key] = str(version)
    return _VERSIONS[cache_key]


def environment(adapter: Adapter | type[Adapter]) -> envs.PinnedEnv | None:
    """The environment a pinned adapter runs in; None for any other adapter."""
    env = getattr(adapter, "pinned", None)
    return env if isinstance(env, envs.PinnedEnv) else None


def __getattr__(name: str) -> type[Adapter]:
    """A pinned class by its qualified name (how pickle finds it in a worker)."""
    if name in _CLASSES:
        return _CLASSES[name]
    if not name.startswith(PREFIX + SEPARATOR):
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module, qualname, package, version, path = _decode(name)
    base = getattr(importlib.import_module(module), qualname)
    env = envs.PinnedEnv(package, version, Path(path))
    _VERSIONS.setdefault((module, qualname, str(env.path)), "")  # a worker never reports it
    return pin(base, env)

