"""One rule book: the rules of cost and text each have one definition, and the page none.

Rank-by-counts (which measure ranks a group, and the ranking itself), the quantile and the
median ± IQR text are defined once (:data:`OWNERS`); every other module of ``crosscheck/``
and ``tools/`` calls them.  The page's script lives in one static file with one global
(``window.crosscheck``) and formats, ranks and judges nothing: the templates hold no script
of their own, and no Python module writes one.  A second definition anywhere fails here, by
name or by body: a function named for a rule, an f-string writing a ``±``, a quantile of
numpy or pandas called outside its owner, a script function that ranks or formats numbers.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterable
from pathlib import Path

import pytest

from tests.conftest import ROOT

OWNERS = {
    "quantile": "crosscheck/results/timings.py",
    "rank by counts": "crosscheck/report/cost.py",
    "median ± IQR text": "crosscheck/report/text.py",
}
"""Each rule and the one module that defines it."""

NAMES = {
    "quantile": re.compile(r"quantile|percentile", re.I),
    "rank by counts": re.compile(r"by_?counts|cost_key|rank_by", re.I),
    "median ± IQR text": re.compile(r"iqr_text|median_iqr|with_iqr|instructions_iqr|spread_text",
                                    re.I),
}
"""A function named so defines the rule (unless it only calls the owner's)."""
QUANTILE_CALLS = {"percentile", "quantile", "nanpercentile", "nanquantile"}
"""numpy's and pandas' quantiles: called only by the owner."""
PLUS_MINUS = "\u00b1"
TEMPLATES = ROOT / "crosscheck" / "report" / "templates"
STATIC = ROOT / "crosscheck" / "report" / "static"
SCRIPT = re.compile(r"<script\b([^>]*)>(.*?)</script>", re.S)
JS_RULES = re.compile(r"quantile|percentile|bycounts|by_counts|median|iqr|toPrecision|toFixed|"
                      r"toExponential|\.sort\(", re.I)
"""What the page's script never does in its code (its strings are words of the page): rank,
take a quantile, or write a number."""
JS_STRING = re.compile(r"\"(?:[^\"\\\n]|\\.)*\"|'(?:[^'\\\n]|\\.)*'")
JS_PLUS_MINUS = re.compile(r"\\u00b1|" + PLUS_MINUS)
"""A ``±`` anywhere in the script, strings too: a median ± IQR written by the page."""


def _called(node: ast.AST) -> set[str]:
    """The names of the functions ``node`` calls (``a.b(...)``: ``b``)."""
    return {c.func.attr if isinstance(c.func, ast.Attribute) else getattr(c.func, "id", "")
            for c in ast.walk(node) if isinstance(c, ast.Call)}


def _names(node: ast.AST) -> set[str]:
    return {n.id if isinstance(n, ast.Name) else n.attr for n in ast.walk(node)
            if isinstance(n, ast.Name | ast.Attribute)}


def _all_counted(function: ast.AST) -> bool:
    """Whether ``function`` asks if every engine of a group was counted: an ``all(...)`` over
    counts (instructions) alone, no time beside them."""
    for call in ast.walk(function):
        if isinstance(call, ast.Call) and getattr(call.func, "id", "") == "all":
            names = {n.lower() for arg in call.args for n in _names(arg)}
            if any("counted" in n or "instructions" in n for n in names) and not any(
                    "query_s" in n or "wall" in n or "time" in n for n in names):
                return True
    return False


def python_copies(path: str, source: str) -> list[str]:
    """Every definition of a rule in one module's ``source`` (``path`` relative to the root),
    unless the module is the rule's owner."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            calls = _called(node)
            for rule, name in NAMES.items():
                if name.search(node.name) and not any(name.search(c) for c in calls):
                    found.append(f"{rule}: {path}:{node.lineno} def {node.name}")
            if _all_counted(node) and "by_counts" not in calls:
                found.append(f"rank by counts: {path}:{node.lineno} def {node.name} "
                             "(every engine counted?)")
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                and node.func.attr in QUANTILE_CALLS:
            found.append(f"quantile: {path}:{node.lineno} .{node.func.attr}(...)")
        elif isinstance(node, ast.JoinedStr) and any(
                isinstance(v, ast.Constant) and PLUS_MINUS in str(v.value) for v in node.values) \
                and any(isinstance(v, ast.FormattedValue) for v in node.values):
            found.append(f"median ± IQR text: {path}:{node.lineno} an f-string writing ±")
    return [f for f in found if OWNERS[f.split(":")[0]] != path]


def script_copies(path: str, script: str) -> list[str]:
    """Every rule a piece of the page's script ranks, takes or writes."""
    code = JS_STRING.sub(lambda m: " " * len(m.group(0)), script)
    return [f"page script: {path}:{script[:m.start()].count(chr(10)) + 1} {m.group(0)!r}"
            for rules, text in ((JS_RULES, code), (JS_PLUS_MINUS, script))
            for m in rules.finditer(text)]


def _python_files() -> Iterable[Path]:
    for folder in ("crosscheck", "tools"):
        yield from sorted((ROOT / folder).rglob("*.py"))


def _relative(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def test_each_rule_of_cost_and_text_has_one_definition() -> None:
    copies = [c for path in _python_files()
              for c in python_copies(_relative(path), path.read_text(encoding="utf-8"))]
    assert copies == []


def test_the_page_script_ranks_takes_quantiles_of_and_writes_no_number() -> None:
    pieces = [(_relative(p), p.read_text(encoding="utf-8")) for p in sorted(STATIC.glob("*.js"))]
    pieces += [(_relative(p), m.group(2)) for p in sorted(TEMPLATES.glob("*.j2"))
               for m in SCRIPT.finditer(p.read_text(encoding="utf-8"))
               if "octet-stream" not in m.group(1)]
    assert [c for path, script in pieces for c in script_copies(path, script)] == []


def test_the_page_script_is_one_static_file_with_one_global() -> None:
    files = sorted(p.name for p in STATIC.iterdir())
    script = (STATIC / "report.js").read_text(encoding="utf-8")
    inline = [f"{_relative(p)}: {m.group(2).strip()[:40]}" for p in sorted(TEMPLATES.glob("*.j2"))
              for m in SCRIPT.finditer(p.read_text(encoding="utf-8"))
              if "octet-stream" not in m.group(1)]
    written = [_relative(p) for p in _python_files() if "<script>" in p.read_text(encoding="utf-8")
               .replace("``<script>``", "")]
    assert files == ["report.js"]
    assert re.findall(r"window\.(\w+)\s*=(?!=)", script) == ["crosscheck"]
    assert inline == ["crosscheck/report/templates/_page_head.html.j2: {{ report_js() | safe }}"]
    assert written == []


PLANTED = '''
import numpy as np

def p95(values):
    return np.percentile(values, 95)

def counted_first(grades):
    return all(g.median_query_instructions is not None for g in grades)

def quantile_of(values, q):
    return sorted(values)[int(q * len(values))]

def cost(m, iqr):
    return f"{m:.3g} \u00b1 {iqr:.2g} s"
'''


@pytest.mark.parametrize("owner", [None, *OWNERS.values()])
def test_a_planted_copy_of_each_rule_is_found(owner: str | None) -> None:
    found = {c.split(":")[0] for c in python_copies(owner or "crosscheck/x.py", PLANTED)}
    assert found == set(OWNERS) - {r for r, o in OWNERS.items() if o == owner}
    script = "function byCounts(list) { return list; }\nvar t = (x).toPrecision(3) + ' \u00b1 ';"
    assert len(script_copies("report.js", script)) == 3
