"""The report's results table: every case x engine once, as compact JSON the page renders itself.

One row per case x engine, with its quantities as columns (status, category, error and
value of each), plus the case's inputs for the details the page builds on demand when a
case link (``#case-<id>``) is followed.  A pair the repeat check found nondeterministic
(:mod:`crosscheck.run.repeat`) carries its second answer (``again``: per quantity
``[status, value]``), for the badge in its status cell.  A swapped twin (``twin_of``) whose
statuses and categories equal its original's, quantity by quantity (and that is
nondeterministic only if its original is), is folded under the original (still in the data,
for its details; not a row of its own); one that differs keeps its own row.

Every number is written here (:mod:`crosscheck.report.text`: errors and tolerances to three
significant digits, a pair's query time as its median ± IQR) and every judgement made here
(a row's worst status, whether it breaks, a case with a breaking row): the page only shows
them.  The JSON is packed (gzip + base64, :func:`crosscheck.report.style.packed`): the page
unpacks it with the browser's ``DecompressionStream`` and shows it with DataTables (from
``itables``).

>>> frame = pd.DataFrame([
...     {"case_id": "c", "engine": "e", "quantity": "hit", "value": "true", "truth": "true",
...      "error": 0.0, "tolerance": 0.0, "status": "agree", "category": "", "reason": "",
...      "query_s": 1e-6, "query_iqr_s": float("nan"), "twin_of": ""},
...     {"case_id": "c.swapped", "engine": "e", "quantity": "hit", "value": "true",
...      "truth": "true", "error": 0.0, "tolerance": 0.0, "status": "agree", "category": "",
...      "reason": "", "query_s": 1e-6, "query_iqr_s": float("nan"), "twin_of": "c"}])
>>> data = results_data(frame, {}, set())
>>> [(r["case"], r["engine"], r["folded"], r["twins"]) for r in data["rows"]]
[(0, 'e', False, [1]), (1, 'e', True, [])]
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Collection, Mapping
from typing import Any

import numpy as np
import pandas as pd

from crosscheck.core.model import Status
from crosscheck.core.schema import BAD_INPUT_TAG, AnyCase
from crosscheck.report import repro_links, text
from crosscheck.report.style import datatables, packed
from crosscheck.report.summary_tables import case_group
from crosscheck.results.jsonlines import each_distinct

INPUTS = {"a", "b", "restitution", "tolerance"}
"""The fields of a case shown as its inputs in its details."""
SEVERITY = {str(s): s.severity for s in Status}
"""Lower is worse: a row's status is the worst of its quantities'."""


def _number(value: Any) -> float | None:
    """A finite float, or None (JSON has no NaN: the page sorts None last)."""
    number = float(value)
    return number if math.isfinite(number) else None


def _case(case_id: str, case: AnyCase | None, first: Mapping[str, Any]) -> dict[str, Any]:
    return {"id": case_id, "description": case.description if case else "",
            "kind": case.kind if case else str(first.get("kind", "")),
            "dim": case.dim if case else first.get("dim", ""),
            "tags": " ".join(case.tags) if case else str(first.get("tags", "")),
            "source": case.source if case else str(first.get("source", "")),
            "group": case_group(case.source if case else str(first.get("source", ""))),
            "inputs": json.dumps(case.model_dump(include=INPUTS)) if case else "{}",
            "twin_of": str(first.get("twin_of", "") or ""), "breaking": False}


def results_data(frame: pd.DataFrame, cases: Mapping[str, AnyCase],
                 repros: Collection[str], run_dir: str = "") -> dict[str, Any]:
    """The table's data: ``run`` (the run folder, ``run_dir``: the page builds each breaking
    row's repro command from it, :mod:`crosscheck.report.repro_links`), ``quantities`` (in
    run order), ``severity`` (each status's rank, lower worse), ``cases`` (inputs, by index;
    ``breaking``: some row of it breaks) and ``rows`` (one per case x engine: worst status,
    whether it breaks, largest error, repro link when its script is in the folder, query time
    as median ± IQR, per quantity ``[status, category, error, value, truth, tolerance,
    reason]``, and for a nondeterministic pair its second answer, ``again``)."""
    quantities = [str(q) for q in dict.fromkeys(frame["quantity"])] if len(frame) else []
    index: dict[str, int] = {}
    case_list: list[dict[str, Any]] = []
    rows: dict[tuple[str, str], dict[str, Any]] = {}
    whole: dict[str, list[Any]] = {}  # every column, read only for a case the run lacks
    columns = [_written(frame, name) if name in _WRITTEN else _column(frame, name)
               for name in _READ]
    for i, (case_id, engine, quantity, status, category, error, value, truth, tolerance,
            reason, query_s, query_iqr_s, again, repeat_status, repeat_value,
            twin_of) in enumerate(zip(*columns, strict=True)):
        case_id, engine = str(case_id), str(engine)
        if case_id not in index:
            index[case_id] = len(case_list)
            case = cases.get(case_id)
            if case is None and not whole:
                whole = {str(name): frame[name].tolist() for name in frame.columns}
            first = ({name: values[i] for name, values in whole.items()} if case is None
                     else {"twin_of": twin_of})
            case_list.append(_case(case_id, case, first))
        row = rows.get((case_id, engine))
        if row is None:
            row = rows[(case_id, engine)] = {
                "case": index[case_id], "engine": engine, "q": {},
                "repro": repro_links.link(case_id, engine, repros),
                "time": None if _number(query_s) is None else text.median_iqr(
                    float(query_s), _number(query_iqr_s)),
                "folded": False, "twins": []}
        row["q"][str(quantity)] = [str(status), category, error, str(value), str(truth),
                                   tolerance, reason]
        if again is True:
            row.setdefault("again", {})[str(quantity)] = [str(repeat_status), str(repeat_value)]
    for row in rows.values():
        statuses = [q[0] for q in row["q"].values()]
        errors = [q[2] for q in row["q"].values()
                  if q[2] is not None and q[0] in Status.members("scored")]
        row["status"] = min(statuses, key=lambda s: SEVERITY.get(s, 99)) if statuses else ""
        row["breaking"] = row["status"] in Status.members("breaking")
        row["error"] = text.error(max(errors) if errors else None)
        for q in row["q"].values():
            q[2] = text.error(q[2])
        if row["breaking"]:
            case_list[row["case"]]["breaking"] = True
    for (_, engine), row in rows.items():
        original = rows.get((case_list[row["case"]]["twin_of"], engine))
        if original is not None and _verdicts(original) == _verdicts(row):
            row["folded"] = True
            original["twins"].append(row["case"])
    return {"run": run_dir, "quantities": quantities, "severity": SEVERITY, "cases": case_list,
            "rows": opening_order(list(rows.values()), case_list)}


def opening_order(rows: list[dict[str, Any]],
                  case_list: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """``rows`` in the order the table opens on (the page keeps the data's order until a
    header is clicked): the engines' answers, most severe status first and the largest error
    first within one, then the rows of bad-input cases in the same order, so that the table
    opens on what the engines get wrong, not on their crashes on NaN input (robustness)."""
    def key(row: dict[str, Any]) -> tuple[bool, int, bool, float]:
        error = _error_value(row["error"])
        return (BAD_INPUT_TAG in str(case_list[row["case"]]["tags"]).split(),
                SEVERITY.get(row["status"], 99), error is None, -(error or 0.0))
    return sorted(rows, key=key)


def _error_value(error: Any) -> float | None:
    """A row's largest error as a number, written or not (None: it has none)."""
    try:
        value = float(error)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(value) else value


_READ = ("case_id", "engine", "quantity", "status", "category", "error", "value", "truth",
         "tolerance", "reason", "query_s", "query_iqr_s",
         "nondeterministic", "repeat_status", "repeat_value", "twin_of")
"""The columns the table reads, in the order its loop unpacks them."""
_ABSENT = {"tolerance": math.nan, "query_s": math.nan, "query_iqr_s": math.nan,
           "nondeterministic": None, "repeat_status": None, "repeat_value": None, "twin_of": ""}
"""What a column the frame lacks reads as on every row."""


def _text(value: Any) -> str:
    return str(value or "")


def _tolerance(value: Any) -> str:
    return text.error(_number(value))


_WRITTEN: dict[str, Callable[[Any], Any]] = {
    "category": _text, "error": _number, "tolerance": _tolerance, "reason": _text}
"""The columns the table writes as it reads them (a quantity's category, error, tolerance and
reason), by the function that writes a value; a column the frame lacks reads as ``_ABSENT``
says, written on each row."""


def _written(frame: pd.DataFrame, name: str) -> list[Any]:
    """A column of :data:`_WRITTEN` as written, each distinct value once (a number by its
    bits: -0.0 is not 0.0)."""
    write = _WRITTEN[name]
    if name not in frame.columns:
        return [write(value) for value in _column(frame, name)]
    column = frame[name]
    if column.dtype != np.float64:
        return list(each_distinct(column, write).tolist())
    codes, bits = pd.factorize(column.to_numpy().view(np.int64))
    written = [write(float(value)) for value in bits.view(np.float64)]
    return [written[code] for code in codes]


def _column(frame: pd.DataFrame, name: str) -> list[Any]:
    """A column's values as Python objects (``_ABSENT``'s value on every row when missing)."""
    if name in frame.columns:
        return list(frame[name].tolist())
    return [_ABSENT[name]] * len(frame)


def _verdicts(row: Mapping[str, Any]) -> tuple[dict[str, tuple[str, str]], bool]:
    return {q: (v[0], v[1]) for q, v in row["q"].items()}, "again" in row


def results_table(frame: pd.DataFrame, cases: Mapping[str, AnyCase],
                  repros: Collection[str], run_dir: str = "") -> dict[str, Any]:
    """The section's context: the packed data, the packed DataTables bundle and CSS, and the
    counts its heading shows (``repros``: the run's repro scripts, by file name; ``run_dir``:
    the run folder, in each breaking row's repro command)."""
    data = results_data(frame, cases, repros, run_dir)
    dt_js, dt_css = datatables()
    shown = sum(not row["folded"] for row in data["rows"])
    return {"packed": packed(json.dumps(data, separators=(",", ":"), allow_nan=False)),
            "dt_js": dt_js, "dt_css": dt_css,
            "rows": shown, "pairs": len(data["rows"]),
            "breaking": sum(row["breaking"] and not row["folded"] for row in data["rows"]),
            "nondeterministic": sum("again" in row and not row["folded"] for row in data["rows"]),
            "quantities": data["quantities"], "cases": len(data["cases"])}
