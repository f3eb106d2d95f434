"""The conformance kit's checks of the answers: one (kind, dim) an adapter claims at a time.

:class:`Answers` asks the adapter the kit's samples (:mod:`crosscheck.testing.samples`)
and reports each broken promise through the ``fail`` it is given (see
:mod:`crosscheck.testing.conformance` for the list of checks).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import fields, replace
from typing import TypeGuard

from crosscheck.core.contract import Adapter
from crosscheck.core.kinds import spec
from crosscheck.core.model import Kind, Observation, Undefined, quantities_of
from crosscheck.testing import samples
from crosscheck.testing.samples import Sample
from crosscheck.truth.bounds import UNIT_LENGTH

UNIT_TOLERANCE = UNIT_LENGTH
"""How far from 1 a normal's length may be (the scoring's own test of a unit vector)."""

Fail = Callable[[str, str, str, object], None]
"""``fail(check, case, expected, got)``: record one broken promise."""


def plain(observation: Observation) -> Observation:
    """The observation without its wall time (which no two runs share)."""
    return replace(observation, wall_s=None)


def _is_float(value: object) -> TypeGuard[float]:
    return isinstance(value, float) and not isinstance(value, bool)


def _typed(value: object) -> str:
    kind = type(value)
    where = "" if kind.__module__ == "builtins" else f"{kind.__module__}."
    return f"{value!r} ({where}{kind.__qualname__})"


def _vector(value: object, dim: int) -> TypeGuard[tuple[float, ...]]:
    return isinstance(value, tuple) and len(value) == dim and all(map(_is_float, value))


class Answers:
    """The checks of one adapter's answers, reporting through ``fail``."""

    def __init__(self, adapter: Adapter, fail: Fail) -> None:
        self.adapter, self.fail = adapter, fail

    def capability(self, kind: Kind, dim: int) -> None:
        """Every check of one (kind, dim) the adapter claims."""
        if kind is Kind.SPHERE_SCENE:
            self.scene(samples.scene(dim))
            return
        main = samples.first(kind, dim)
        if kind is Kind.SPHERE_RESPONSE:
            self.response(main)
        elif kind is Kind.SPHERE_TOI:
            self.impact(main)
        else:
            self.detection(kind, dim)
        self.repeat(main)
        self.hangs(main)

    def observe(self, sample: Sample) -> Observation | None:
        """``observe()`` of the sample, if it is an Observation with only its kind's
        quantities and the required ones (else None, failures recorded): the kind's spec says
        which (:class:`crosscheck.core.kinds.KindSpec`)."""
        observation = self.adapter.observe(sample.case)
        if not isinstance(observation, Observation):
            self.fail("observe", sample.label, "an Observation", repr(observation))
            return None
        kind = spec(sample.case.kind_enum)
        allowed = set(kind.names) | kind.extras
        extra = [f.name for f in fields(Observation)
                 if f.name not in allowed and getattr(observation, f.name) is not None]
        missing = [q for q in kind.required if observation.get(q) is None]
        if extra:
            self.fail("observe", sample.label, f"only quantities of {kind.kind} "
                      f"({', '.join(kind.names)})", f"also {', '.join(extra)}")
        if missing:
            self.fail("observe", sample.label, f"{', '.join(kind.required)} given",
                      f"no {', '.join(missing)}")
        return None if missing else observation

    def normal(self, check: str, sample: Sample, normal: object) -> None:
        """A normal given is a unit vector from A to B (``sample``'s axis and sign)."""
        if normal is None:
            return
        dim = sample.case.dim
        direction = f"{'+' if sample.sign > 0 else '-'}{samples.AXES[sample.axis]}"
        expected = f"normal None or a unit vector from A to B ({direction})"
        if not _vector(normal, dim):
            self.fail(check, sample.label, expected + f" of {dim} floats", repr(normal))
            return
        assert isinstance(normal, tuple)
        length = math.sqrt(sum(x * x for x in normal))
        if abs(length - 1.0) > UNIT_TOLERANCE or normal[sample.axis] * sample.sign <= 0.99:
            self.fail(check, sample.label, expected, repr(normal))

    def detection(self, kind: Kind, dim: int) -> None:
        """The verdict, sign of the distance and normal on a clear overlap and clear gaps."""
        sample = samples.overlap(kind, dim)
        seen = self.observe(sample)
        if seen is not None:
            if seen.hit is not True:
                self.fail("overlap", sample.label, "hit True (a bool)", _typed(seen.hit))
            if seen.distance is not None and not (
                    _is_float(seen.distance) and seen.distance < 0.0):
                self.fail("overlap", sample.label, "a negative float distance (-0.25), or none "
                          "(an engine without penetration depth)", repr(seen.distance))
            self.normal("overlap", sample, seen.normal)
        for sample in (samples.gap(kind, dim), samples.gap(kind, dim, axis=1, sign=-1.0)):
            seen = self.observe(sample)
            if seen is None:
                continue
            if seen.hit is not False:
                self.fail("gap", sample.label, "hit False (a bool)", _typed(seen.hit))
            if seen.distance is not None and not (
                    _is_float(seen.distance) and seen.distance > 0.0):
                self.fail("gap", sample.label, "distance None or a positive float (0.5)",
                          repr(seen.distance))
            self.normal("gap", sample, seen.normal)

    def response(self, sample: Sample) -> None:
        """After a head-on elastic impact of equal masses, A moves back (-x) and B on (+x)."""
        seen = self.observe(sample)
        if seen is None:
            return
        dim = sample.case.dim
        v1, v2 = seen.v1, seen.v2
        if not (_vector(v1, dim) and _vector(v2, dim)):
            self.fail("response", sample.label, f"v1 and v2 vectors of {dim} floats",
                      f"v1 {v1!r}, v2 {v2!r}")
        elif not (v1[0] < 0.0 < v2[0]):
            self.fail("response", sample.label, "v1 along -x and v2 along +x (about -1 and +1)",
                      f"v1 {v1!r}, v2 {v2!r}")

    def impact(self, sample: Sample) -> None:
        """A time of impact: a contact verdict; with a contact, a time within the interval
        and a normal from A to B (+x); an engine that cannot compute one says so with
        Undefined values, never a made-up time."""
        seen = self.observe(sample)
        if seen is None or isinstance(seen.hit, Undefined):
            return
        if not isinstance(seen.hit, bool):
            self.fail("impact", sample.label, "hit a bool (or Undefined)", _typed(seen.hit))
            return
        if not seen.hit:
            return
        if not (_is_float(seen.toi) and 0.0 <= seen.toi <= 1.0):
            self.fail("impact", sample.label, "toi a float in [0, 1] (about 0.75)", repr(seen.toi))
        self.normal("impact", sample, seen.normal)

    def scene(self, sample: Sample) -> None:
        """Two runs of a scene: the same bodies, moved as they should, each timed."""
        runs = [self.observe(sample) for _ in range(2)]
        first, second = runs
        if first is None or second is None:
            return
        dim = sample.case.dim
        positions, velocities = first.positions, first.velocities
        if not (isinstance(positions, tuple) and len(positions) == 2
                and all(_vector(p, dim) for p in positions)):
            self.fail("scene", sample.label, f"positions of 2 bodies, {dim} floats each",
                      repr(positions))
        if not (isinstance(velocities, tuple) and len(velocities) == 2
                and all(_vector(v, dim) for v in velocities) and velocities[0][0] < 0.0):
            self.fail("scene", sample.label, "velocities of 2 bodies, the first along -x "
                      "(they exchanged velocities)", repr(velocities))
        if not (_is_float(first.wall_s) and first.wall_s > 0.0):
            self.fail("scene", sample.label, "wall_s > 0 (the stepping loop's seconds)",
                      repr(first.wall_s))
        if (first.positions, first.velocities) != (second.positions, second.velocities):
            self.fail("repeat", sample.label, "two runs with the same positions and velocities",
                      f"{first.positions!r} then {second.positions!r}")

    def repeat(self, sample: Sample) -> None:
        """One answer from prepare, query, query, query_without nothing, release, and again."""
        prepared = self.adapter.prepare(sample.case)
        try:
            answers = [self.adapter.query(prepared), self.adapter.query(prepared),
                       self.adapter.query_without(prepared, frozenset())]
        finally:
            self.adapter.release(prepared)
        answers.append(self.adapter.observe(sample.case))
        if any(plain(a) != plain(answers[0]) for a in answers):
            self.fail("repeat", sample.label, "the same answer from query, query again, "
                      "query_without(nothing) and a new prepare", answers)

    def hangs(self, sample: Sample) -> None:
        """Declared hanging quantities are the kind's, and declared with a reason."""
        hanging = self.adapter.hanging_quantities(sample.case)
        reason = self.adapter.known_hang(sample.case)
        if not hanging <= set(quantities_of(sample.case.kind_enum)):
            self.fail("hangs", sample.label, "hanging quantities among the kind's", hanging)
        if (reason is None) != (not hanging):
            self.fail("hangs", sample.label, "hanging quantities exactly when known_hang "
                      "names a reason", f"known_hang {reason!r}, hanging {sorted(hanging)}")
