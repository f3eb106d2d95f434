"""A response's declared contact model: soft contact (no coefficient of restitution), friction.

The textbook response is a frictionless impulse along the line of centres
with the case's restitution e.  Some engines resolve a contact otherwise, and
declare it (:class:`~crosscheck.core.contract.Conventions`):

- ``restitution_model = "soft"``: the engine has no coefficient of
  restitution (MuJoCo: ``solref``/``solimp`` set a spring-damper); the
  bounce it gives has some effective e' in [0, 1], whatever e the case asks;
- ``friction = mu > 0``: Coulomb friction acts between the bodies, so an
  oblique impact also gets a tangential impulse of at most mu times the
  normal one.

:func:`explain` says whether an engine's two response velocities are such a
response: momentum kept, the impulse along the line of centres giving an e'
that the declared model allows, and a tangential impulse that the declared
friction allows.  It reads only the case, the conventions and the engine's
own answer, never the truth; its reason carries the numbers.  It judges only what the
engine's precision can record: the impulse is read from the lighter body's velocity
change (a heavy float32 body's change can be below its ulp: at a mass ratio of 1e10 a
unit velocity changes by 1e-10, which float32 cannot hold), and momentum is kept when
its drift is within the recording error of both bodies (``SLACK`` x their masses x the
velocity allowance).

>>> from crosscheck.core.contract import Conventions
>>> from crosscheck.core.model import Observation
>>> from crosscheck.core.schema import ResponseCase
>>> case = ResponseCase.model_validate({"id": "c", "kind": "sphere_response", "dim": 2,
...     "description": "head-on, equal masses",
...     "a": {"center": [0, 0], "radius": 1, "mass": 1, "velocity": [1, 0]},
...     "b": {"center": [2, 0], "radius": 1, "mass": 1, "velocity": [-1, 0]}})
>>> soft = Conventions(restitution_model="soft")
>>> explain(case, soft, Observation(v1=(-0.14, 0.0), v2=(0.14, 0.0)))[:60]
'the engine has no coefficient of restitution (soft contact):'
>>> explain(case, soft, Observation(v1=(-0.5, 0.0), v2=(0.1, 0.0)))  # momentum not kept
''
"""

from __future__ import annotations

import math

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, difference, dot, norm
from crosscheck.core.model import Observation
from crosscheck.core.schema import ResponseCase

CONVENTIONS = ("restitution_model", "friction")
"""The declared conventions :func:`explain` reads (fields of
:class:`~crosscheck.core.conventions.Conventions`)."""
SLACK = 2.0
"""How many of the engine's velocity allowances the impulse checks may be off by."""


def explain(case: ResponseCase, conv: Conventions, observation: Observation,
            tolerance: float = 0.0) -> str:
    """Why the engine's velocities are the declared contact model's answer ('' if they are not).

    ``tolerance`` is the engine's absolute velocity allowance for the case.
    """
    if conv.restitution_model != "soft" and conv.friction <= 0:
        return ""
    moved = _impulse(case, observation)
    if moved is None:
        return ""
    line, moved_a, moved_b = moved
    ma, mb = case.a.mass, case.b.mass
    slack = SLACK * max(tolerance, 1e-12 * _speed_scale(case, observation))
    drift = norm(tuple(ma * x + mb * y for x, y in zip(moved_a, moved_b, strict=True)))
    if drift > (ma + mb) * slack:
        return ""
    before = dot(difference(case.a.velocity, case.b.velocity), line)
    if not before < 0:
        return ""  # not approaching: the separating rule speaks for it
    after = dot(difference(observation.v1, observation.v2), line)  # type: ignore[arg-type]
    # The impulse on B, read from the lighter body: its velocity changes the most, so the
    # engine's precision records it best (a heavy float32 body's change may be below its ulp).
    impulse: Vec = (tuple(mb * x for x in moved_b) if mb <= ma else
                    tuple(-ma * x for x in moved_a))
    parts = [_restitution(case, conv, -after / before, slack / -before),
             _friction(conv, impulse, line, min(ma, mb) * slack)]
    if any(p is None for p in parts) or not any(parts):
        return ""
    momentum = f"momentum kept to {drift:.3g}"
    return "; ".join([p for p in parts if p] + [momentum])


def _impulse(case: ResponseCase, observation: Observation) -> tuple[Vec, Vec, Vec] | None:
    """The line of centres where the engine met the contact, and each body's velocity change."""
    v1, v2 = observation.v1, observation.v2
    if not (_vector(v1, case.dim) and _vector(v2, case.dim)):
        return None
    if not all(math.isfinite(m) and m > 0 for m in (case.a.mass, case.b.mass)):
        return None
    pa, pb = observation.resolved_at or (case.a.center, case.b.center)
    offset = difference(pa, pb)
    length = norm(offset)
    if not (math.isfinite(length) and length > 0):
        return None
    line = tuple(x / length for x in offset)
    return (line, difference(case.a.velocity, v1),  # type: ignore[arg-type]
            difference(case.b.velocity, v2))  # type: ignore[arg-type]


def _vector(value: object, dim: int) -> bool:
    return (isinstance(value, tuple) and len(value) == dim
            and all(isinstance(x, float) and math.isfinite(x) for x in value))


def _speed_scale(case: ResponseCase, observation: Observation) -> float:
    speeds = [norm(v) for v in (case.a.velocity, case.b.velocity, observation.v1,
                                observation.v2) if isinstance(v, tuple)]
    return max([s for s in speeds if math.isfinite(s)], default=0.0)


def _restitution(case: ResponseCase, conv: Conventions, effective: float,
                 slack: float) -> str | None:
    """The bounce: '' when it is the case's e, a reason when the soft model allows it, None
    when nothing declared allows it."""
    if abs(effective - case.restitution) <= slack:
        return ""
    if conv.restitution_model == "soft" and -slack <= effective <= 1 + slack:
        return (f"the engine has no coefficient of restitution (soft contact): its impulse "
                f"along the line of centres gives e' = {effective:.3g} where the case asks "
                f"e = {case.restitution:g}")
    return None


def _friction(conv: Conventions, impulse: Vec, line: Vec, slack: float) -> str | None:
    """The tangential part of the impulse on B: '' when there is none, a reason when the
    declared friction allows it, None when it exceeds it."""
    normal = dot(impulse, line)
    tangential = norm(tuple(j - normal * n for j, n in zip(impulse, line, strict=True)))
    if tangential <= slack:
        return ""
    limit = conv.friction * abs(normal)
    if conv.friction > 0 and tangential <= limit + slack:
        return (f"friction {conv.friction:g} (declared): tangential impulse {tangential:.3g} "
                f"within {conv.friction:g} x the normal impulse {abs(normal):.3g}; the textbook "
                "is frictionless")
    return None
