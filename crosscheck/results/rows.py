"""The rows of ``results.jsonl``: the one definition of a row's keys, their order and the
encoding of its values, used by every writer of rows.

A row is one :class:`~crosscheck.core.model.Record` as a JSON object: its fields as keys in
:data:`~crosscheck.core.model.COLUMNS` order, ``", "`` and ``": "`` between them, each value
as :func:`json.dumps` writes it (strings by json's own ASCII escaper, floats as
``float.__repr__``, NaN and the infinities as the bare tokens ``NaN``, ``Infinity``,
``-Infinity``), then a newline.  That is byte for byte ``json.dumps(record.row()) + "\\n"``
(``tests/truth/test_columnar.py`` compares them on the whole suite), and what every reader
parses with :func:`json.loads`.

Two writers share that definition (the key texts, their order and the value encoders below):

- :func:`line`: the line of one Record (the store's :meth:`~crosscheck.results.store.
  ResultsStore.append`, the rows of scenes and of failed outcomes);
- :class:`ColumnLines`: the lines of judged columns (:mod:`crosscheck.truth.columnar`)
  written straight from them, without a Record per row (the fast path of a run).  The
  fields that are the same for every quantity of a case x engine (:data:`CASE_FIELDS`)
  are encoded once per case, with their keys, into the text between the others
  (:func:`gaps`); each quantity puts its verdict (:data:`ROW_FIELDS`) between them.

>>> from crosscheck.core.model import Record, Status
>>> record = Record(case_id="c", source="s.toml", kind="sphere", dim=2, tags="", engine="e",
...     quantity="hit", value="true", truth="true", error=0.0, tolerance=0.0,
...     status=Status.AGREE, category="", reason="", setup_s=float("nan"), query_s=1e-06,
...     query_iqr_s=0.0, loops=3, unstable=False)
>>> line(record) == json.dumps(record.row()) + "\\n"
True
>>> line(record)[:54]
'{"case_id": "c", "source": "s.toml", "kind": "sphere",'
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from typing import Any

from crosscheck.core.model import COLUMNS, Kind, Observation, Record, Status, Value, quantities_of
from crosscheck.core.values import encode
from crosscheck.truth.columnar import Columns

text = json.encoder.encode_basestring_ascii
"""A string as json.dumps writes it (ASCII, quoted, escaped)."""


def number(x: float) -> str:
    """A float as json.dumps writes it (NaN and the infinities as bare tokens).

    >>> number(0.1), number(float("nan")), number(-math.inf), number(3)
    ('0.1', 'NaN', '-Infinity', '3')
    """
    if type(x) is not float:
        return json.dumps(x)  # an int where a float was declared: as json.dumps writes it
    if math.isfinite(x):
        return float.__repr__(x)
    return "NaN" if x != x else ("Infinity" if x > 0 else "-Infinity")


def field(value: Any) -> str:
    """Any field of a Record as json.dumps writes it (the common types by a short way)."""
    kind = type(value)
    if kind is str:
        return text(value) if value else '""'
    if kind is float:
        return number(value)
    if kind is bool:
        return "true" if value else "false"
    if kind is int:
        return int.__repr__(value)
    if isinstance(value, str):  # a str enum: a status, a category
        return text(value)
    return json.dumps(value)


def value_text(value: Value | None) -> str:
    """The ``value`` or ``truth`` field of a quantity's answer: ``field(encode(value))``, by a
    shorter way for a finite float or vector of them (a float's repr holds an 'n' only when
    it is not finite: 'nan', 'inf')."""
    try:
        if type(value) is tuple:
            body = ", ".join(map(float.__repr__, value))  # TypeError unless floats
            if "n" not in body:
                return f'"[{body}]"'
        elif type(value) is float:
            body = float.__repr__(value)
            if "n" not in body:
                return f'"{body}"'
    except TypeError:
        pass  # nested tuples (a scene's bodies), bools inside a vector: encode says
    return text(encode(value))


ROW_FIELDS = ("quantity", "value", "truth", "error", "tolerance", "status", "category",
              "reason", "error_at_contact")
"""The fields that differ between the quantities of one case x engine (its verdicts), in
:data:`~crosscheck.core.model.COLUMNS` order."""
CASE_FIELDS = tuple(name for name in COLUMNS if name not in ROW_FIELDS)
"""The fields every quantity of a case x engine shares (the case, the engine, the timing)."""
_KEYS = {name: ("{" if k == 0 else ", ") + text(name) + ": " for k, name in enumerate(COLUMNS)}
"""What comes before each value: the separator and the key."""


def _plan() -> tuple[tuple[tuple[tuple[str, str], ...], str], ...]:
    """The line cut at each of :data:`ROW_FIELDS`: per cut, the (key text, name) of the
    :data:`CASE_FIELDS` before it, then the key text of that row field ("}" and the newline
    after the last one)."""
    cuts: list[tuple[tuple[tuple[str, str], ...], str]] = []
    group: list[tuple[str, str]] = []
    for name in COLUMNS:
        if name in ROW_FIELDS:
            cuts.append((tuple(group), _KEYS[name]))
            group = []
        else:
            group.append((_KEYS[name], name))
    cuts.append((tuple(group), "}\n"))
    return tuple(cuts)


_PLAN = _plan()
assert tuple(n for n in COLUMNS if n in ROW_FIELDS) == ROW_FIELDS
_STATUS = {status: text(str(status)) for status in Status}
_BY_TYPE: dict[str, Callable[[Any], str]] = {
    "str": text, "float": number, "int": int.__repr__, "bool": lambda b: "true" if b else "false"}
_FILLED = tuple(
    (k, "".join(key.replace("%", "%%") + "%s" for key, _ in group),
     tuple((name, _BY_TYPE[str(Record.__dataclass_fields__[name].type)]) for _, name in group))
    for k, (group, _) in enumerate(_PLAN) if group)
"""Per cut with case fields before it: its index, its keys as a ``%`` format, and the fields'
names and encoders (by the Record field's declared type)."""
_AFTER = [after for _, after in _PLAN]
_EVERY = "%s".join(_KEYS[name].replace("%", "%%") for name in COLUMNS) + "%s}\n"
"""The line of a row as a ``%`` format, a ``%s`` for each value."""


def gaps(fixed: Mapping[str, Any]) -> list[str]:
    """The text between the :data:`ROW_FIELDS` of a line, with ``fixed`` (the
    :data:`CASE_FIELDS`, of the types a Record declares) encoded in: the values of the row
    fields go between consecutive gaps.

    >>> fixed = dict.fromkeys(CASE_FIELDS, "") | {"dim": 2, "loops": 0, "unstable": False}
    >>> len(gaps(fixed | dict.fromkeys(("setup_s", "query_s", "query_iqr_s"), 0.0)))
    10
    """
    out = _AFTER.copy()
    for k, form, group in _FILLED:
        out[k] = form % tuple([encoder(fixed[name]) for name, encoder in group]) + out[k]
    return out


def line(record: Record) -> str:
    """The JSON line of one record, ending in a newline."""
    return _EVERY % tuple([field(getattr(record, name)) for name in COLUMNS])


class ColumnLines:
    """The JSON lines of judged columns, case after case: byte for byte what :func:`line`
    gives for the records of the same verdicts."""

    def __init__(self, columns: Columns) -> None:
        self.quantity, self.status, self.category = columns.quantity, columns.status, \
            columns.category
        self.reason = columns.reason
        self.error, self.tolerance = columns.error.tolist(), columns.tolerance.tolist()
        self.at_contact = columns.error_at_contact.tolist()
        self.row = 0

    def lines(self, fixed: Mapping[str, Any], observation: Observation,
              truth: Observation) -> list[str]:
        """The lines of the next case of the columns: ``fixed`` holds its
        :data:`CASE_FIELDS` (as a Record has them), ``observation`` the engine's answer."""
        g = gaps(fixed)
        out = []
        for quantity in quantities_of(Kind(fixed["kind"])):
            r = self.row
            assert self.quantity[r] == quantity
            out.append(  # the ROW_FIELDS in order, between the gaps
                f"{g[0]}{text(quantity)}{g[1]}{value_text(observation.get(quantity))}"
                f"{g[2]}{value_text(truth.get(quantity))}{g[3]}{number(self.error[r])}"
                f"{g[4]}{number(self.tolerance[r])}{g[5]}{_STATUS[self.status[r]]}"
                f"{g[6]}{field(self.category[r])}{g[7]}{field(self.reason[r])}"
                f"{g[8]}{number(self.at_contact[r])}{g[9]}")
            self.row += 1
        return out
