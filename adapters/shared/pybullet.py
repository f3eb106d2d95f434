"""What everything that drives pybullet shares (its pairs' calls, the scene runner, the bench):
the quiet import, the redirect of C-level output and a new client; plain, the standard
library only, so a repro script holds this source (until the scenes are calls of
:mod:`adapters.pybullet.calls`, which then holds it).

- ``engine()``: the pybullet module, imported once, lazily (importing this module does not
  import it; the import prints a banner);
- ``quiet()``: pybullet's banner and ``b3Warning`` lines go to the C-level stdout/stderr,
  so what prints them runs with file descriptors 1 and 2 on /dev/null (a redirect costs
  ~8 us);
- ``connect(settings)``: a new DIRECT client (no GUI) with gravity 0 and ``settings``.
"""

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator
from typing import Any

_MODULE: list[Any] = []


@contextlib.contextmanager
def quiet() -> Iterator[None]:
    """Send C-level stdout and stderr to /dev/null (the banner, b3Warning lines)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = (os.dup(1), os.dup(2))
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        ctypes.CDLL(None).fflush(None)  # C stdio buffers empty into /dev/null
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, null):
            os.close(fd)


def engine() -> Any:
    """The pybullet module, imported quietly once (its import prints a banner)."""
    if not _MODULE:
        with quiet():
            import pybullet
        _MODULE.append(pybullet)
    return _MODULE[0]


def connect(settings: dict[str, float]) -> int:
    """A new DIRECT client with gravity 0 and ``settings``."""
    bt = engine()
    with quiet():
        cid: int = bt.connect(bt.DIRECT)
        bt.setGravity(0.0, 0.0, 0.0, physicsClientId=cid)
        if settings:
            bt.setPhysicsEngineParameter(**settings, physicsClientId=cid)
    return cid
