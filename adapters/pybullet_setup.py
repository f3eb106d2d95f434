"""PyBullet setup shared by everything that drives pybullet: quiet import, clients, tuned settings.

What it is for: one place for what the pair adapter (:mod:`adapters.pybullet_engine`), the
scene runner (:mod:`adapters.pybullet_scene`), the raw engine loops
(:mod:`crosscheck.studies.bench.rawloops`) and the bench (:mod:`crosscheck.studies.bench`) all
need, so none of them imports another for it:

- ``engine()``: the pybullet module, imported once, lazily (pybullet is an optional engine:
  importing this module does not import it);
- ``quiet()``: pybullet's banner and ``b3Warning`` lines go to the C-level stdout/stderr,
  so what prints them runs with file descriptors 1 and 2 on /dev/null (a redirect costs
  ~8 us);
- ``connect(settings)``: a new DIRECT client (no GUI) with gravity 0 and ``settings``;
- ``TUNED_WORLD`` and ``TUNED_BODY``: the settings of the tuned variant (``pybullet``), per
  client and per body; the default variant (``pybullet-default``) sets neither.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator
from typing import Any

__all__ = ["TUNED_BODY", "TUNED_WORLD", "connect", "engine", "quiet"]

TUNED_WORLD: dict[str, float] = {
    "fixedTimeStep": 1.0 / 240.0, "restitutionVelocityThreshold": 0.0,
    "contactSlop": 0.0, "contactERP": 0.0}
"""The tuned variant's ``setPhysicsEngineParameter`` settings: fixed time step 1/240 s set
explicitly, restitutionVelocityThreshold 0, contactSlop 0, contactERP 0 (erp and
frictionERP do not act: no joints, no friction)."""
TUNED_BODY: dict[str, float] = {
    "lateralFriction": 0.0, "rollingFriction": 0.0, "spinningFriction": 0.0,
    "linearDamping": 0.0, "angularDamping": 0.0}
"""The tuned variant's per-body ``changeDynamics`` settings: lateral, rolling and spinning
friction 0, linear and angular damping 0."""

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
