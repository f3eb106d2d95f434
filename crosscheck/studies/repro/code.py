"""What every engine part of a repro script is made of: :class:`EngineCode`, exact literals, guards.

An engine part (an adapter's calls module with its call,
:mod:`~crosscheck.studies.repro.calls`) is the Python text that makes the adapter's calls
and leaves the engine's answer in variables named after the case's quantities;
:mod:`~crosscheck.studies.repro.script` puts the inputs and the printing around it.

A *guard* is an input the adapter does not pass to the engine (a NaN the engine would take
without a word, a size it would misread): the adapter raises, or records every quantity as
undefined.  The script does the same, in plain sight, and one flag (``ASK_ANYWAY``) makes
the engine's calls instead, to see what the engine itself answers.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class EngineCode:
    """The engine-specific part of a script: its imports and the statements of the query."""

    imports: tuple[str, ...]
    code: str
    notes: tuple[str, ...] = ()
    """Lines for the script's header (how to run it, what it leaves out)."""
    tail: str = ""
    """Statements after the answer is printed (a call the run recorded as hanging)."""
    resolved_at: bool = False
    """Whether the statements set ``resolved_at`` (a stepped response: where it resolved)."""
    model: str = ""
    """The engine's own model text the script loads (MuJoCo's MJCF), for a bug report."""
    inputs: tuple[tuple[str, str, str, str], ...] = ()
    """(constant, source, label, plain text) of inputs that are not a pair's (a scene's bodies);
    empty: the pair case's centres, sizes, masses and velocities."""


def literal(x: float) -> str:
    """Python source for exactly ``x``: a ``float.fromhex`` literal, or ``float("nan")``...

    >>> literal(0.1), literal(-0.0), literal(float("-inf")), literal(-float("nan"))
    ('float.fromhex("0x1.999999999999ap-4")', 'float.fromhex("-0x0.0p+0")', \
'-float("inf")', '-float("nan")')
    """
    x = float(x)
    if math.isfinite(x):
        return f'float.fromhex("{x.hex()}")'
    sign = "-" if math.copysign(1.0, x) < 0 else ""
    return f'{sign}float("{"nan" if math.isnan(x) else "inf"}")'


def vector(v: Sequence[float]) -> str:
    """Python source for a tuple of exact floats.

    >>> vector((1.0, 0.5))
    '(float.fromhex("0x1.0000000000000p+0"), float.fromhex("0x1.0000000000000p-1"))'
    """
    return "(" + ", ".join(literal(x) for x in v) + ("," if len(v) == 1 else "") + ")"


def number(x: float) -> str:
    """A constant for the script: the shortest text that reads back to ``x`` (``repr``), or
    ``float("inf")``/``float("nan")``.

    >>> number(0.1), number(float("inf"))
    ('0.1', 'float("inf")')
    """
    return repr(x) if math.isfinite(x) else literal(x)


ASK = "ASK_ANYWAY = False  # True: make the engine's calls anyway, to see its own answer\n"


def raising(exception: BaseException, engine: str, code: str) -> str:
    """``code`` behind the guard that raises ``exception`` as the adapter does."""
    name = type(exception).__name__
    return (f"# crosscheck's adapter does not ask {engine} here: it raises (recorded as an "
            f"error row).\n{ASK}if not ASK_ANYWAY:\n"
            f"    raise {name}({str(exception)!r})\n{code}")


def undefined(reason: str, quantities: Sequence[str], engine: str, code: str) -> str:
    """``code`` behind the guard that records every quantity as undefined, for ``reason``."""
    names = " = ".join(quantities)
    return (f"# crosscheck's adapter does not ask {engine} here: {reason}.\n# It records "
            f"every quantity as undefined (null).\n{ASK}if not ASK_ANYWAY:\n"
            f'    {names} = "undefined"\nelse:\n{textwrap.indent(code, "    ")}')
