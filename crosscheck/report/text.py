"""How the report writes a number: one rule book for the page, the advise answer and the CLI.

Every median with its spread is written one way, on the page, in the advise tables and on
the command line (:func:`median_iqr`): the median to three significant digits in ns, µs, ms
or s, then ``±`` the IQR to two in the same unit.  A count of instructions per query
(``crosscheck run --timer instructions``) is written the same way with a decimal prefix
(:func:`instructions_iqr`): ``93.3 ± 4.1 k instr``.  A share is a whole percentage
(:func:`percent`), an error three significant digits (:func:`error`), and a number in a few
words of an advise answer at most about five characters (:func:`short`).

The page's script formats no number: every figure reaches it written by these functions.

>>> seconds(2e-05), median_iqr(1.2845e-05, 1.2e-06), instructions_iqr(93349.0, 4100.0)
('20 µs', '12.8 ± 1.2 µs', '93.3 ± 4.1 k instr')
>>> percent(0.5), percent(None), error(1.23456e-07), short(4.2e-05)
('50%', '-', '1.23e-07', '4e-05')
"""

from __future__ import annotations

import math
from collections.abc import Callable

from crosscheck.results.timings import Spread

UNITS = ((1.0, "s"), (1e-3, "ms"), (1e-6, "µs"), (1e-9, "ns"))
"""The units a time is written in, largest first (below 1 ns: ns with decimals)."""
COUNT_UNITS = ((1e9, "G instr"), (1e6, "M instr"), (1e3, "k instr"), (1.0, "instr"))
"""The units a count of instructions is written in, largest first."""


def _unit(value: float, units: tuple[tuple[float, str], ...]) -> tuple[float, str]:
    """The largest of ``units`` in which ``value`` is at least 1 (after rounding to 3 digits)."""
    return next(((scale, unit) for scale, unit in units if value >= scale * 0.9995), units[-1])


def _digits(value: float, significant: int) -> str:
    """``value`` to ``significant`` digits without an exponent (whole from 10**digits on;
    below 0.01: '<0.01').

    >>> _digits(12.84, 3), _digits(1.25, 2), _digits(99.7, 2), _digits(0.004, 2), _digits(0.0, 2)
    ('12.8', '1.2', '100', '<0.01', '0')
    """
    if value == 0:
        return "0"
    if value < 0.01:
        return "<0.01"
    if value >= 10 ** significant - 0.5:
        return f"{value:.0f}"
    return f"{value:.{significant}g}"


def _scaled(value: float, units: tuple[tuple[float, str], ...]) -> str:
    if math.isnan(value):
        return "n/a"
    scale, unit = _unit(value, units)
    return f"{_digits(value / scale, 3)} {unit}"


def seconds(value: float) -> str:
    """A duration with an SI prefix, to three significant digits: 2e-05 -> '20 µs'.

    >>> seconds(1.2845e-05), seconds(9.9996e-04), seconds(3e-10), seconds(float("nan"))
    ('12.8 µs', '1 ms', '0.3 ns', 'n/a')
    """
    return _scaled(value, UNITS)


def instructions(value: float) -> str:
    """A count of instructions with a decimal prefix, to three significant digits.

    >>> instructions(93349.0), instructions(850.0), instructions(1.2e6), instructions(math.nan)
    ('93.3 k instr', '850 instr', '1.2 M instr', 'n/a')
    """
    return _scaled(value, COUNT_UNITS)


def _spread_text(median: float | None, iqr: float | None,
                 units: tuple[tuple[float, str], ...]) -> str:
    """The median to three significant digits, ``±`` the IQR to two, in the median's unit."""
    if median is None or math.isnan(median):
        return "n/a"
    scale, unit = _unit(median, units)
    if iqr is None or math.isnan(iqr):
        return f"{_digits(median / scale, 3)} {unit}"
    return f"{_digits(median / scale, 3)} \u00b1 {_digits(iqr / scale, 2)} {unit}"


def median_iqr(median: float | None, iqr: float | None) -> str:
    """A median time and its interquartile range, in the one format of the page and the CLI.

    >>> median_iqr(1.2845e-05, 1.2e-06), median_iqr(8.5e-07, 3e-08), median_iqr(2e-3, None)
    ('12.8 ± 1.2 µs', '850 ± 30 ns', '2 ms')
    >>> median_iqr(None, None), median_iqr(float("nan"), 1.0)
    ('n/a', 'n/a')
    """
    return _spread_text(median, iqr, UNITS)


def instructions_iqr(median: float | None, iqr: float | None) -> str:
    """A median count of instructions and its interquartile range, as :func:`median_iqr`
    writes a time.

    >>> instructions_iqr(93349.0, 4100.0), instructions_iqr(850.0, 30.0)
    ('93.3 ± 4.1 k instr', '850 ± 30 instr')
    >>> instructions_iqr(1.2e6, None), instructions_iqr(None, None)
    ('1.2 M instr', 'n/a')
    """
    return _spread_text(median, iqr, COUNT_UNITS)


def with_iqr(s: Spread) -> str:
    """A spread of times as :func:`median_iqr` writes it: '2 ± 1 µs'.

    >>> with_iqr(Spread(2e-6, 1.5e-6, 2.5e-6, 5))
    '2 ± 1 µs'
    """
    return median_iqr(s.median, s.iqr)


def or_dash(written: Callable[[float, float | None], str], median: float | None,
            iqr: float | None) -> str:
    """``written(median, iqr)``, or '-' when there is no median (not timed, not counted).

    >>> or_dash(median_iqr, None, None), or_dash(median_iqr, 1e-6, 0.0)
    ('-', '1 ± 0 µs')
    """
    return "-" if median is None else written(median, iqr)


def percent(share: float | None) -> str:
    """A share as a whole percentage (ties to even, as Python rounds); '-': none.  Only a
    whole share reads 100%: one short of it that would round up is cut to a tenth of a per
    cent (99.5% to 99.9%), so a failing row (a share below 1) never shows 100%.

    >>> percent(1.0), percent(0.9996), percent(0.995), percent(0.994), percent(0.5)
    ('100%', '99.9%', '99.5%', '99%', '50%')
    """
    if share is None:
        return "-"
    whole = f"{share:.0%}"
    if share >= 1 or whole != "100%":
        return whole
    return f"{math.floor(share * 1000 + 1e-9) / 10:.1f}%"  # the nudge undoes 0.995 * 1000 = 994.99…


def error(value: float | None) -> str:
    """An error or a tolerance to three significant digits ('' for none): how the page's
    tables write one.

    >>> error(0.0), error(0.012345), error(None), error(float("inf"))
    ('0', '0.0123', '', 'inf')
    """
    return "" if value is None or math.isnan(value) else f"{value:.3g}"


def short(value: float) -> str:
    """A number in at most about five characters: 0.42, 1e-04, 3e+08.

    >>> short(0.42), short(1.234e-4), short(3e8)
    ('0.42', '1e-04', '3e+08')
    """
    text = f"{value:.2g}"
    return text if len(text) <= 5 else f"{value:.0e}"
