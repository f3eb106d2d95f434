"""Cached environments, one per (package, version) of an engine: the version matrix's interpreters.

``crosscheck run --engine pymunk@6.11.1`` runs the ``pymunk`` variant in a worker whose
interpreter has pymunk 6.11.1 (:mod:`crosscheck.run.pinned`).  That interpreter is a virtual
environment built on first use and kept:

- ``python -m venv --without-pip`` from the harness's own interpreter (same Python, same
  ABI: the worker speaks the same pickles);
- a ``.pth`` file that adds the harness's site-packages *after* the environment's own, so
  the harness, numpy and every other dependency come from the harness's environment while
  the pinned package shadows the harness's version;
- ``pip --python <env> install <package>==<version>`` from the package index: pip resolves
  the package's dependencies against what the harness already has and installs only what
  is missing or different (it says "Not uninstalling ... outside environment" about the
  harness's copy, which it leaves alone);
- a check, in the new interpreter, that the installed version is the one asked for; then
  the folder is renamed into place and a ``crosscheck-env.json`` marks it ready.

The cache is ``$CROSSCHECK_ENVS`` if set, else ``$XDG_CACHE_HOME/crosscheck/envs``, else
``~/.cache/crosscheck/envs``; one folder per environment, named
``<package>-<version>-py<major.minor>``.  Deleting a folder (or the whole cache) clears it:
it is built again on next use.  ``crosscheck engines --envs`` lists them.  A build holds a lock
file, so two runs asking for one version at once build it once.

>>> cache_root({"CROSSCHECK_ENVS": "/tmp/x"}).as_posix()
'/tmp/x'
>>> cache_root({"XDG_CACHE_HOME": "/c"}).as_posix()
'/c/crosscheck/envs'
>>> env_name("mujoco-core", "4.0.1").startswith("mujoco-core-4.0.1-py3.")
True
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

MARKER = "crosscheck-env.json"
"""The file that marks an environment complete, with what it holds."""

VERSION = re.compile(r"^[0-9][0-9A-Za-z.+!_-]*$")
"""What a requested version may look like (a PEP 440 version; no spaces, no specifiers)."""

PIP_TIMEOUT_S = 900.0
"""Time allowed for one ``pip install`` (downloading a large wheel on a slow network)."""


class EnvError(Exception):
    """An environment could not be built or used; the message says why (pip's last lines)."""


def cache_root(environ: Mapping[str, str] | None = None) -> Path:
    """The folder that holds every cached environment."""
    environ = os.environ if environ is None else environ
    if environ.get("CROSSCHECK_ENVS"):
        return Path(environ["CROSSCHECK_ENVS"])
    base = environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "crosscheck" / "envs"


def env_name(package: str, version: str) -> str:
    """The folder name of (package, version) for this Python."""
    return f"{package}-{version}-py{sys.version_info.major}.{sys.version_info.minor}"


@dataclass(frozen=True)
class PinnedEnv:
    """One cached environment: ``package`` at ``version``, in ``path``."""

    package: str
    version: str
    path: Path

    @property
    def python(self) -> Path:
        """The environment's interpreter."""
        return self.path / "bin" / "python"

    @property
    def site_packages(self) -> Path:
        """Where the environment's own packages are (first on its ``sys.path``)."""
        return site_packages(self.path)

    def ready(self) -> bool:
        """Whether the environment is complete (its marker written)."""
        return (self.path / MARKER).is_file() and self.python.exists()


def site_packages(prefix: Path) -> Path:
    """The purelib folder of an environment whose prefix is ``prefix``."""
    return Path(sysconfig.get_path("purelib", vars={"base": str(prefix),
                                                    "platbase": str(prefix)}))


def check_version(version: str) -> str | None:
    """Why ``version`` is not a version pip can be asked for exactly, or None.

    >>> check_version("6.11.1") is None, check_version(">=6")
    (True, "'>=6' is not a version number (write NAME@6.11.1: an exact version)")
    """
    if VERSION.match(version):
        return None
    return f"{version!r} is not a version number (write NAME@6.11.1: an exact version)"


def find(package: str, version: str, root: Path | None = None) -> PinnedEnv:
    """The environment of (package, version) in the cache (it may not be built yet)."""
    root = cache_root() if root is None else root
    return PinnedEnv(package, version, root / env_name(package, version))


def ensure(package: str, version: str, say: Callable[[str], None] = lambda _: None,
           root: Path | None = None) -> PinnedEnv:
    """The environment of (package, version), built first if it is not in the cache.

    Raises :class:`EnvError` (with pip's message) when pip cannot install that version.
    """
    problem = check_version(version)
    if problem:
        raise EnvError(problem)
    env = find(package, version, root)
    if env.ready():
        return env
    env.path.parent.mkdir(parents=True, exist_ok=True)
    with _locked(env.path.parent / f".{env.path.name}.lock"):
        if not env.ready():  # another run may have built it while we waited
            say(f"building the environment of {package} {version} in {env.path} "
                "(once; it is cached)")
            _build(env)
    return env


@contextlib.contextmanager
def _locked(path: Path) -> Iterator[None]:
    with open(path, "a", encoding="ascii") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _build(env: PinnedEnv) -> None:
    """Build ``env`` in a temporary folder, check it, and move it into place."""
    staging = env.path.with_name(env.path.name + ".building")
    shutil.rmtree(staging, ignore_errors=True)
    shutil.rmtree(env.path, ignore_errors=True)  # an incomplete one (no marker)
    try:
        _run([sys.executable, "-m", "venv", "--without-pip", str(staging)], "venv")
        own = site_packages(staging)
        own.mkdir(parents=True, exist_ok=True)
        harness = [str(Path(p)) for p in sys.path if p.endswith("site-packages")
                   and Path(p).is_dir()]
        (own / "zz-crosscheck-harness.pth").write_text(
            "import site; " + "; ".join(f"site.addsitedir({p!r})" for p in harness) + "\n",
            encoding="utf-8")
        python = staging / "bin" / "python"
        _run([sys.executable, "-m", "pip", "--python", str(python), "install",
              "--disable-pip-version-check", "--no-input", f"{env.package}=={env.version}"],
             f"pip install {env.package}=={env.version}")
        found = _run([str(python), "-c", "import sys; from importlib.metadata import version; "
                      f"print(version({env.package!r}))"], "the version check").strip()
        if found != env.version:
            raise EnvError(f"asked pip for {env.package} {env.version}, the environment has "
                           f"{found}")
        staging.rename(env.path)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    # the venv's absolute paths name the staging folder only in its activate scripts (unused)
    (env.path / MARKER).write_text(json.dumps({
        "package": env.package, "version": env.version, "python": sys.version.split()[0],
        "harness": sys.prefix}, indent=1) + "\n", encoding="utf-8")


def _run(command: list[str], what: str) -> str:
    """Run ``command``; its stdout, or EnvError with the last lines of its output."""
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=PIP_TIMEOUT_S,
                              check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise EnvError(f"{what} failed: {exc}") from None
    if done.returncode != 0:
        tail = "\n".join((done.stderr or done.stdout).strip().splitlines()[-6:])
        raise EnvError(f"{what} failed (exit {done.returncode}):\n{tail}")
    return done.stdout


def cached(root: Path | None = None) -> list[PinnedEnv]:
    """Every complete environment in the cache, by name."""
    root = cache_root() if root is None else root
    found = []
    for marker in sorted(root.glob(f"*/{MARKER}")):
        try:
            data = json.loads(marker.read_text(encoding="utf-8"))
            found.append(PinnedEnv(str(data["package"]), str(data["version"]), marker.parent))
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return found
