"""The engine part of a repro script, for any adapter whose engine calls are a module.

A :class:`~crosscheck.core.contract.CallsAdapter` (built-in or a plug-in's) names its module
of engine calls (``adapters/<engine>/calls.py``: plain functions of plain data importing only
the engine library, the standard library and numpy) and says which
:class:`~crosscheck.core.contract.Call` a case is.  The script holds that module's source,
verbatim, then makes the call on the case's exact inputs (``float.fromhex`` literals), as the
adapter does: ``built = <build>(**inputs)``, ``answer = <ask>(built)``; each quantity is the
answer's (absent: None, printed ``null``; a ``str``, a value with no definition, ``null``,
its reason a comment).  Where the calls module imports a shared helper (``from
adapters.shared import ...``, :mod:`adapters.shared`, plain too; or the scene measures,
:mod:`reference_impl.scene_measures`) the helper's source comes first, in place of the import
(a helper's own helpers before it).  A call the adapter refuses (``Call.refusal``) is behind a
guard that raises as the adapter does; quantities the run recorded as a declared hang are
left out (the call's ``partial`` ask), and the full ask is made last.
Nothing here knows an engine: the adapter and its module are the script.
"""

from __future__ import annotations

import importlib
import inspect
import re
from types import ModuleType
from typing import Any, TypeGuard

from crosscheck.core.contract import CallsAdapter, Impacts, Pairs, Responses, Scenes
from crosscheck.core.model import quantities_of
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SceneCase, SphereCase, ToiCase
from crosscheck.studies.repro.code import EngineCode, literal, raising, undefined

SHARED = re.compile(r"^from (adapters\.shared[\w.]*|reference_impl\.scene_measures) "
                    r"import (?:\([^)]*\)|[^\n]+)$", re.MULTILINE)
"""An import of a shared helper in a calls module (or in a helper): the script holds the
helper's source."""
NO_VALUE = """\
for quantity, value in answer.items():
    if isinstance(value, str):  # a quantity with no defined value, and why
        print(f"# {quantity}: no value: {value}")"""
HANG = """\
print("# now {ask}, which the run recorded as hanging on these inputs ...")
sys.stdout.flush()
print("# {ask} returned", {ask}(built))"""

__all__ = ["calls_code", "has_call", "source"]


def has_call(adapter: object, case: AnyCase) -> TypeGuard[CallsAdapter]:
    """Whether ``adapter`` makes ``case``'s kind as calls of its module (a script of them)."""
    if not isinstance(adapter, CallsAdapter):
        return False
    if isinstance(case, AabbCase | SphereCase):
        return isinstance(adapter, Pairs)
    if isinstance(case, ResponseCase):
        return isinstance(adapter, Responses)
    if isinstance(case, SceneCase):
        return isinstance(adapter, Scenes)
    return isinstance(case, ToiCase) and isinstance(adapter, Impacts)


def source(value: Any) -> str:
    """Python source for exactly ``value``: floats as ``float.fromhex`` literals, tuples and
    lists as tuples, a text of several lines (a model) triple-quoted, anything else (int,
    bool, str, None) as ``repr``.

    >>> source((0.5, (1.0,))), source(None), source(10)
    ('(float.fromhex("0x1.0000000000000p-1"), (float.fromhex("0x1.0000000000000p+0"),))', \
'None', '10')
    """
    if isinstance(value, float):
        return literal(value)
    if isinstance(value, str) and "\n" in value and '"""' not in value and "\\" not in value:
        return '"""' + value + '"""'  # a model text, as it reads
    if isinstance(value, tuple | list):
        return "(" + ", ".join(source(v) for v in value) + ("," if len(value) == 1 else "") + ")"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k!r}: {source(v)}" for k, v in value.items()) + "}"
    return repr(value)


def _source(module: ModuleType) -> str:
    text = inspect.getsource(module)
    if "from __future__" in text:
        raise ValueError(f"{module.__name__} has a __future__ import: a script cannot hold it")
    return text.rstrip()


def _without_helpers(text: str) -> str:
    return SHARED.sub(lambda m: f"# from {m.group(1)} import ...: its source is above", text)


def included(module: ModuleType) -> tuple[str, list[ModuleType]]:
    """A calls module's source with its shared helpers' imports taken out, and the helpers
    (each after the helpers it imports itself)."""
    helpers: list[ModuleType] = []

    def add(text: str) -> None:
        for name in dict.fromkeys(SHARED.findall(text)):
            helper = importlib.import_module(name)
            if helper not in helpers:
                add(_source(helper))
                helpers.append(helper)

    text = _source(module)
    add(text)
    return _without_helpers(text), helpers


def calls_code(adapter: CallsAdapter, case: AnyCase,
               hung: frozenset[str] = frozenset()) -> EngineCode:
    """The script's engine part for ``case``: the module's source, then the call (without
    the quantities in ``hung``, then the full ask, when the call has a ``partial`` ask)."""
    call = adapter.call(case)
    module = importlib.import_module(adapter.calls)
    text, helpers = included(module)
    clashes = [name.upper() for name in call.inputs
               if any(hasattr(m, name.upper()) for m in (module, *helpers))]
    if clashes:
        raise ValueError(f"{adapter.calls} defines {', '.join(clashes)}, a script's input")
    inputs = tuple((name.upper(), source(value), name, repr(value))
                   for name, value in call.inputs.items())
    arguments = "".join(f"\n    {name}={name.upper()}," for name in call.inputs)
    ask = call.partial if hung and call.partial else call.ask
    tail = HANG.format(ask=call.ask) if ask != call.ask else ""
    quantities = quantities_of(case.kind_enum)
    responded = isinstance(case, ResponseCase)
    lines = [f"built = {call.build}({arguments}\n)", f"answer = {ask}(built)", NO_VALUE,
             *(f"{q} = answer.get({q!r})" for q in quantities),
             *(['resolved_at = answer.get("resolved_at")'] if responded else []),
             *([f"{call.release}(built)"] if call.release and not tail else [])]
    made = "\n".join(lines)
    if call.refusal is not None:  # prepare raises first: the other guard is moot
        made = raising(call.refusal, adapter.engine, made)
    elif call.undefined:
        made = undefined(call.undefined, quantities, adapter.engine, made)
    parts = [*(f"# {m.__name__}, verbatim (shared by engines' calls).\n"
               f"{_without_helpers(_source(m))}\n\n" for m in helpers),
             f"# {adapter.calls}, verbatim: the calls crosscheck's adapter makes.", text, "", "",
             "# The adapter's call on the case's inputs: build (untimed), then ask (timed).",
             made]
    return EngineCode((), "\n".join(parts), resolved_at=responded, inputs=inputs, tail=tail,
                      model=call.model)
