"""Rows of ``results.jsonl`` written straight from judged columns, without a Record per row.

:class:`ColumnLines` gives, case after case, byte for byte the line that
``json.dumps(record.row())`` gives for the record :func:`crosscheck.run.runner.score_case`
would build (``tests/truth/test_columnar.py`` compares them): keys in
:data:`~crosscheck.core.model.COLUMNS` order, strings escaped by json's own escaper,
floats as ``float.__repr__`` and NaN and the infinities as json.dumps' bare tokens.
"""

from __future__ import annotations

import json
import math

from crosscheck.core.model import Observation, Status, Value, quantities_of
from crosscheck.core.schema import AnyCase
from crosscheck.core.values import encode
from crosscheck.run.execute import Outcome
from crosscheck.truth.columnar import Columns

_text = json.encoder.encode_basestring_ascii  # what json.dumps writes a str with


def _number(x: float) -> str:
    """A float as json.dumps writes it (NaN and the infinities as bare tokens)."""
    if math.isfinite(x):
        return float.__repr__(x)
    return "NaN" if x != x else ("Infinity" if x > 0 else "-Infinity")


def _short(text: str) -> str:
    """:data:`_text` of a category or reason (most are empty)."""
    return _text(text) if text else '""'


def _value(value: Value | None) -> str:
    """``_text(encode(value))``, by a shorter way for a finite float or vector of them (a
    float's repr holds an 'n' only when it is not finite: 'nan', 'inf')."""
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
    return _text(encode(value))


_STATUS = {status: _text(str(status)) for status in Status}


class ColumnLines:
    """The JSON lines of judged columns, case after case, in :data:`COLUMNS` order:
    byte for byte what ``json.dumps(record.row())`` gives."""

    def __init__(self, columns: Columns) -> None:
        self.quantity, self.status, self.category = columns.quantity, columns.status, \
            columns.category
        self.reason = columns.reason
        self.error, self.tolerance = columns.error.tolist(), columns.tolerance.tolist()
        self.at_contact = columns.error_at_contact.tolist()
        self.row = 0

    def lines(self, case: AnyCase, engine: str, outcome: Outcome,
              truth: Observation) -> list[str]:
        """The lines of ``case`` (the next case of the columns) on ``engine``."""
        timing, observation = outcome.timing, outcome.observation
        assert observation is not None
        head = (f'{{"case_id": {_text(case.id)}, "source": {_text(case.source)}, "kind": '
                f'{_text(case.kind)}, "dim": {int(case.dim)}, "tags": '
                f'{_text(" ".join(case.tags))}, "engine": {_text(engine)}, "quantity": ')
        timed = (f'"setup_s": {_number(outcome.setup_s)}, "query_s": '
                 f'{_number(timing.median_s if timing else math.nan)}, "query_iqr_s": '
                 f'{_number(timing.iqr_s if timing else math.nan)}, "loops": '
                 f'{int(timing.loops) if timing else 0}, "unstable": '
                 f'{"true" if timing and timing.unstable else "false"}, "origin": '
                 f'{_text(case.origin)}, "coords": '
                 f'{_text(json.dumps(case.coords) if case.coords else "")}, "twin_of": '
                 f'{_text(case.twin_of)}, "error_at_contact": ')
        out = []
        for quantity in quantities_of(case.kind_enum):
            r = self.row
            assert self.quantity[r] == quantity
            out.append(
                f'{head}"{quantity}", "value": {_value(observation.get(quantity))}'
                f', "truth": {_value(truth.get(quantity))}, "error": '
                f'{_number(self.error[r])}, "tolerance": {_number(self.tolerance[r])}, '
                f'"status": {_STATUS[self.status[r]]}, "category": '
                f'{_short(self.category[r])}, "reason": {_short(self.reason[r])}, {timed}'
                f'{_number(self.at_contact[r])}}}\n')
            self.row += 1
        return out
