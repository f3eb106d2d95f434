"""No test reads a clock or holds a measured time to a bound: the timing rule, checked on the
sources of the tests.

Measured speed belongs in ``crosscheck bench``.  A test whose verdict hangs on a measured
duration, a measured speed ratio or a measured count of pairs flagged slower passes or fails
with the machine's load, so a test injects time instead (a fake ``clock`` through a parameter,
a replaced ``best_of``), counts the work (calls, instructions), or asserts the outcome without
the clock (a hang is a ``timeout`` row naming its limit, and the run goes on).

The rules, checked on the syntax tree of every Python file under tests/ and of the doctest
examples in crosscheck/, adapters/, reference_impl/ and tools/ (pytest runs those,
``--doctest-modules``):

1. **No clock is read.**  No ``time.perf_counter``, ``monotonic``, ``time``, ``process_time``,
   ``thread_time`` or ``clock_gettime`` (nor their ``_ns`` forms), called or handed on as a
   clock; no ``from time import`` of them; no ``timeit``; no ``datetime.now()`` or
   ``utcnow()``.  Stricter than "a clock's reading reaches an assert", and simpler to check
   and to obey: a test that cannot read a clock cannot assert what it measured, and no data
   flow has to be followed through variables, helpers and fixtures.  The one exception is
   :data:`SAFETY_BOUNDS`: :func:`tests.conftest.wait_until` polls for a condition and gives
   up after a generous limit, so that a broken guarantee fails instead of hanging; nothing
   asserts how long the wait took.  ``time.sleep`` reads no clock, and a ``timeout=`` given
   to ``subprocess.run``, ``join`` or ``communicate`` is a safety bound of the same kind.
2. **No measured time from the library is held to a number.**  No ``<``, ``<=``, ``>`` or
   ``>=`` between a number and an expression that names a time or a speed (a name,
   attribute or string key such as ``wall_s``, ``query_s``, ``elapsed``, ``duration``,
   ``cases_per_s``: :func:`names_a_time`).  This is the other way a measurement reaches a
   test: the library timed something (``SceneRun.wall_s``, a run's ``query_s``) and the test
   bounds it.  Injected times are checked with ``==`` or ``pytest.approx``, which this allows.

The rules cover every test, ``slow`` ones included (``make test-long`` must not flake either).
Two measured values compared with each other (``prepare_s > idle.wall_s``) pass rule 2, but
one of them was read from a clock in the test, which rule 1 forbids.
"""

from __future__ import annotations

import ast
import doctest
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.conftest import ROOT

CLOCKS = frozenset(
    name + suffix
    for name in ("perf_counter", "monotonic", "time", "process_time", "thread_time",
                 "clock_gettime")
    for suffix in ("", "_ns"))
"""The clocks of the ``time`` module."""

SAFETY_BOUNDS = frozenset({("tests/conftest.py", "wait_until")})
"""(file, function) where a test may read a clock: waiting with a limit, never measuring."""

DOCTEST_ROOTS = ("crosscheck", "adapters", "reference_impl", "tools")
"""Library folders whose docstrings pytest runs as doctests (pyproject's testpaths)."""

TIME_WORDS = frozenset({"elapsed", "duration", "durations", "seconds", "wall", "walls"})
TIME_UNITS = frozenset({"s", "ms", "us", "ns"})
ORDERING = (ast.Lt, ast.LtE, ast.Gt, ast.GtE)


@dataclass(frozen=True)
class Violation:
    """One broken rule: where, and what."""

    path: str
    line: int
    what: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.what}"


def names_a_time(identifier: str) -> bool:
    """Whether an identifier or a column name reads as a time or a speed: one of its words is
    :data:`TIME_WORDS`, or its last word is a unit of time (``_s``, ``_ms``, ``_us``, ``_ns``).

    >>> [names_a_time(n) for n in ("wall_s", "query_s", "elapsed", "cases_per_s", "raw_us")]
    [True, True, True, True, True]
    >>> [names_a_time(n) for n in ("status", "loops", "peak_lanes_mb", "ratios", "s")]
    [False, False, False, False, False]
    """
    words = identifier.lower().split("_")
    return bool(TIME_WORDS.intersection(words)) or (len(words) > 1 and words[-1] in TIME_UNITS)


def is_number(node: ast.expr) -> bool:
    """A numeric literal, signed or not (``1e-3``, ``-1``), not a bool."""
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        node = node.operand
    return (isinstance(node, ast.Constant) and isinstance(node.value, int | float)
            and not isinstance(node.value, bool))


def time_named(node: ast.expr) -> str | None:
    """The first name, attribute or string key in ``node`` that names a time, if any."""
    for sub in ast.walk(node):
        name = (sub.id if isinstance(sub, ast.Name) else sub.attr
                if isinstance(sub, ast.Attribute) else None)
        if (isinstance(sub, ast.Subscript) and isinstance(sub.slice, ast.Constant)
                and isinstance(sub.slice.value, str)):
            name = sub.slice.value
        if name is not None and names_a_time(name):
            return name
    return None


class Checker(ast.NodeVisitor):
    """Collects the :class:`Violation` s of one source (a module, or one docstring's examples)."""

    def __init__(self, path: str, line_offset: int = 0) -> None:
        self.path, self.offset = path, line_offset
        self.time_names = {"time"}  # names bound to the time module
        self.functions: list[str] = []
        self.found: list[Violation] = []

    def flag(self, node: ast.AST, what: str) -> None:
        self.found.append(Violation(self.path, self.offset + getattr(node, "lineno", 0), what))

    def in_safety_bound(self) -> bool:
        return any((self.path, name) in SAFETY_BOUNDS for name in self.functions)

    def visit_FunctionDef(self, node: ast.FunctionDef | ast.AsyncFunctionDef) -> None:
        self.functions.append(node.name)
        self.generic_visit(node)
        self.functions.pop()

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_Import(self, node: ast.Import) -> None:
        for alias in node.names:
            if alias.name == "time":
                self.time_names.add(alias.asname or "time")
            elif alias.name.split(".")[0] == "timeit":
                self.flag(node, "imports timeit (a clock)")

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        clocks = sorted(a.name for a in node.names if a.name in CLOCKS)
        if node.module == "time" and clocks:
            self.flag(node, f"imports a clock: from time import {', '.join(clocks)}")
        elif (node.module or "").split(".")[0] == "timeit":
            self.flag(node, "imports from timeit (a clock)")

    def visit_Attribute(self, node: ast.Attribute) -> None:
        owner = node.value
        of_time = ((isinstance(owner, ast.Name) and owner.id in self.time_names)
                   or (isinstance(owner, ast.Attribute) and owner.attr == "time"))
        of_datetime = ((isinstance(owner, ast.Name) and owner.id == "datetime")
                       or (isinstance(owner, ast.Attribute) and owner.attr == "datetime"))
        clock = ((of_time and node.attr in CLOCKS)
                 or (of_datetime and node.attr in ("now", "utcnow")))
        if clock and not self.in_safety_bound():
            self.flag(node, f"reads a clock: {ast.unparse(node)} (inject the time, or "
                            f"wait with tests.conftest.wait_until)")
        self.generic_visit(node)

    def visit_Compare(self, node: ast.Compare) -> None:
        operands = [node.left, *node.comparators]
        for op, left, right in zip(node.ops, operands, operands[1:], strict=False):
            if not isinstance(op, ORDERING):
                continue
            for number, other in ((left, right), (right, left)):
                name = time_named(other) if is_number(number) else None
                if name is not None:
                    self.flag(node, f"holds a measured time to a bound ({name!r}): "
                                    f"{ast.unparse(node)}")
                    break
        self.generic_visit(node)


def check_source(source: str, path: str, line_offset: int = 0) -> list[Violation]:
    """The violations in ``source``, reported as ``path`` (which decides the safety bounds)."""
    checker = Checker(path, line_offset)
    checker.visit(ast.parse(source, filename=path))
    return checker.found


def relative(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def sources_of_tests() -> list[str]:
    """Every Python file under tests/ (test modules, conftests, helpers, fakes, data)."""
    return [relative(p) for p in sorted((ROOT / "tests").rglob("*.py"))]


def doctest_examples(path: str) -> list[tuple[str, int]]:
    """The examples of each docstring of ``path`` that has some, as one source (each example
    on its own line of the docstring), with the line the docstring starts on."""
    parser = doctest.DocTestParser()
    tree = ast.parse((ROOT / path).read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            examples = parser.get_examples(ast.get_docstring(node, clean=False) or "")
            if examples:
                line = node.body[0].lineno if node.body else 0
                lines: list[str] = []
                for example in examples:
                    lines += [""] * (example.lineno - len(lines))
                    lines += example.source.splitlines()
                found.append(("\n".join(lines) + "\n", line))
    return found


def sources_with_doctests() -> list[str]:
    """Every Python file of :data:`DOCTEST_ROOTS` with a doctest example."""
    return [relative(p) for folder in DOCTEST_ROOTS for p in sorted((ROOT / folder).rglob("*.py"))
            if doctest_examples(relative(p))]


def violations_in(path: str) -> list[Violation]:
    """A test source whole; a library source by its doctest examples."""
    if path.startswith("tests/"):
        return check_source((ROOT / path).read_text(encoding="utf-8"), path)
    return [v for source, line in doctest_examples(path)
            for v in check_source(source, f"{path} (doctest)", line - 1)]


# ------------------------------------------------------------ the tree obeys the rules

CHECKED = [*sources_of_tests(), *sources_with_doctests()]


@pytest.mark.parametrize("path", CHECKED)
def test_reads_no_clock_and_bounds_no_measured_time(path: str) -> None:
    found = violations_in(path)
    assert not found, "\n".join(map(str, found))


def test_the_scan_reaches_the_tests_and_the_doctests() -> None:
    assert {"tests/conftest.py", "tests/reference_impl/test_events.py",
            "tests/adapters/test_scene_stepping.py", "tests/run/test_isolation.py",
            "reference_impl/events.py", "crosscheck/run/execute.py"} <= set(CHECKED)
    assert len(sources_of_tests()) > 100 and len(sources_with_doctests()) > 50


def test_the_safety_bound_is_where_the_allow_list_says_and_the_only_reader() -> None:
    """The allow-list is not stale: ``wait_until`` exists and does read a clock (so the rule
    would flag it anywhere else)."""
    for path, function in SAFETY_BOUNDS:
        tree = ast.parse((ROOT / path).read_text(encoding="utf-8"))
        [found] = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == function]
        alone = ast.unparse(ast.Module(body=[ast.Import([ast.alias("time")]), found],
                                       type_ignores=[]))
        assert check_source(alone, "elsewhere.py"), f"{path}: {function} reads no clock"
        assert check_source(alone, path) == []


# ------------------------------------------------------------ the checker can fail

BAD = {
    "a measured duration": "import time\nt0 = time.perf_counter()\nwork()\n"
                           "assert time.perf_counter() - t0 < 1\n",
    "an elapsed bound": "import time\nstart = time.monotonic()\nrun()\nelapsed = "
                        "time.monotonic() - start\nassert elapsed < 10\n",
    "an aliased module": "import time as t\nx = t.time()\n",
    "a clock handed on": "import time\nrun(clock=time.perf_counter)\n",
    "a clock imported by name": "from time import perf_counter\n",
    "a nanosecond clock": "import time\nx = time.process_time_ns()\n",
    "timeit": "import timeit\nassert timeit.timeit(f, number=3) < 0.1\n",
    "datetime": "import datetime\nstart = datetime.datetime.now()\n",
    "a library-measured wall time": "run = run_scene(p, 0)\nassert run.wall_s < 1e-3\n",
    "a measured column": "assert (timed['query_s'] > 0).all()\n",
    "a measured speed, number first": "assert 0 < figure['cases_per_s']\n",
    "a chained bound": "assert 0.0 <= result.elapsed_s <= 10\n",
}

GOOD = {
    "injected time": "readings = iter([1.0, 2.5])\nrun = f(clock=lambda: next(readings))\n"
                     "assert run.wall_s == 1.5\n",
    "approx on injected times": "assert d['raw_us'] == pytest.approx(500.0)\n",
    "an outcome": "assert frame['status'].eq('timeout').all()\n",
    "a sleep": "import time\ntime.sleep(0.05)\n",
    "a subprocess limit": "subprocess.run(cmd, timeout=60)\n",
    "counted work": "assert calls[0] == n * (n - 1) // 2\n",
    "a bound on a count": "assert len(rows) >= 100 and memory['bodies_left'] <= 64\n",
    "a time column filled": "assert timed['query_s'].notna().all()\n",
    "the time module's other names": "import time\nx = time.strftime('%Y')\n",
}


@pytest.mark.parametrize("source", BAD.values(), ids=BAD.keys())
def test_a_bad_example_is_caught(source: str) -> None:
    assert check_source(source, "tests/test_example.py")


@pytest.mark.parametrize("source", GOOD.values(), ids=GOOD.keys())
def test_a_good_example_passes(source: str) -> None:
    assert check_source(source, "tests/test_example.py") == []


WAIT = """
import time

def wait_until(condition, what, timeout_s=60.0):
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, what
        time.sleep(0.05)
"""


def test_the_safety_bound_may_read_a_clock_only_in_its_own_file() -> None:
    assert check_source(WAIT, "tests/conftest.py") == []
    found = check_source(WAIT, "tests/run/test_example.py")
    assert [v.line for v in found] == [5, 7]
    assert "tests.conftest.wait_until" in found[0].what


def test_a_violation_names_its_file_and_line() -> None:
    [found] = check_source("x = 1\nassert run.wall_s < 1\n", "tests/test_example.py")
    assert str(found).startswith("tests/test_example.py:2: holds a measured time to a bound")
    assert "'wall_s'" in found.what
