"""The timing samples of a run (``timings.jsonl``) and their spread: what speed figures stand on.

The timing phase of a run (:mod:`crosscheck.run.timing_phase`) appends one
:class:`TimingRecord` per timed case x engine: every kept sample, not only a
median, so that a report can show the spread and ``compare`` can test whether
two runs differ.  A sample is the time of one call (net of the timing loop's
own cost, ``unit = "call"``) or of one whole scene run (``unit = "scene"``).

The phase takes one sample per pair per round (:mod:`crosscheck.run.rounds`), and
each record keeps, aligned with its samples, the machine yardstick of the round
each was taken in (``yardstick``, seconds): a sample divided by its round's
yardstick (:attr:`TimingRecord.normalised`) no longer carries the machine's drift
during the run.  Lines written before the rounds (up to format 5) have no
``yardstick`` key and read as having none (``()``: not normalised); a round
without a yardstick is stored as ``null`` and read as NaN.

>>> s = spread([1.0, 1.1, 0.9, 1.0, 1.05])
>>> (s.median, round(s.iqr, 3), s.n, s.unstable)
(1.0, 0.05, 5, False)
>>> spread([1.0, 2.0, 1.0, 2.0]).unstable
True
>>> r = TimingRecord("c", "e", "sphere", "call", 10, 0.0, (2.0, 3.0), (1.0, 1.5))
>>> r.normalised, TimingRecord.from_json(r.to_json()) == r
((2.0, 2.0), True)
>>> old = '{"case_id": "c", "engine": "e", "kind": "sphere", "unit": "call", "loops": 10, '
>>> TimingRecord.from_json(old + '"overhead_s": 0.0, "values": [2.0]}').yardstick
()
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd

from crosscheck.results import jsonlines

UNSTABLE_SPREAD = 0.10
"""A measurement whose interquartile range exceeds this share of its median is unstable."""
MIN_SAMPLES = 10
"""Fewer kept samples than this: too few to judge a spread or a change ("unknown")."""
FILE = "timings.jsonl"


@dataclass(frozen=True, slots=True)
class Spread:
    """Median and quartiles of a set of timing samples (seconds)."""

    median: float
    q1: float
    q3: float
    n: int

    @property
    def iqr(self) -> float:
        return self.q3 - self.q1

    @property
    def unstable(self) -> bool:
        """IQR above :data:`UNSTABLE_SPREAD` of the median (or no positive median)."""
        return not self.median > 0 or self.iqr > UNSTABLE_SPREAD * self.median


def quantiles(values: Sequence[float], at: Sequence[float],
              nearest: bool = False) -> list[float]:
    """The quantiles ``at`` (shares, 0 to 1) of ``values``: numpy's linear interpolation, or
    with ``nearest`` the nearest rank (the smallest value with at least that share of the
    values at or below it); NaN each if none.  The one quantile rule of the harness: the
    report's spreads and cost ranks, ``compare``, the bench and the tools all read it.

    >>> quantiles([1.0, 2.0, 3.0, 4.0], [0.25, 0.5]), quantiles([1.0, 2.0], [0.95], nearest=True)
    ([1.75, 2.5], [2.0])
    >>> quantiles([], [0.5])
    [nan]
    """
    if not len(values):
        return [math.nan] * len(at)
    method: Literal["inverted_cdf", "linear"] = "inverted_cdf" if nearest else "linear"
    return [float(x) for x in np.quantile(np.asarray(values, dtype=float), list(at),
                                          method=method)]


def quantile_rows(samples: Sequence[Sequence[float]], at: Sequence[float]) -> np.ndarray:
    """:func:`quantiles` (linear) of each of many sample lists at once, as rows (one column
    per share in ``at``; NaN for an empty list): one numpy call per list length, not per list.

    >>> quantile_rows([[1.0, 2.0, 3.0, 4.0], [], [2.0, 4.0, 6.0, 8.0], [5.0]], [0.25, 0.5])
    array([[1.75, 2.5 ],
           [ nan,  nan],
           [3.5 , 5.  ],
           [5.  , 5.  ]])
    """
    out = np.full((len(samples), len(at)), np.nan)
    by_length: dict[int, list[int]] = {}
    for i, values in enumerate(samples):
        if len(values):
            by_length.setdefault(len(values), []).append(i)
    for rows in by_length.values():
        matrix = np.asarray([samples[i] for i in rows], dtype=float)
        out[rows] = np.quantile(matrix, list(at), axis=1, method="linear").T
    return out


def spread(values: Sequence[float]) -> Spread:
    """The median and quartiles (:func:`quantiles`) of ``values``; NaN if none."""
    q1, median, q3 = quantiles(values, (0.25, 0.5, 0.75))
    return Spread(median, q1, q3, len(values))


def geomean(values: Sequence[float]) -> float:
    """The geometric mean of the finite positive ``values`` (NaN: none): how ratios and the
    yardstick's workloads are averaged.

    >>> geomean([1.0, 4.0]), geomean([2.0, math.nan]), geomean([])
    (2.0, 2.0, nan)
    """
    known = [v for v in values if v > 0 and math.isfinite(v)]
    return float(np.exp(np.mean(np.log(known)))) if known else math.nan


@dataclass(frozen=True, slots=True)
class TimingRecord:
    """Every kept timing sample of one case x engine."""

    case_id: str
    engine: str
    kind: str
    unit: str
    """``"call"``: seconds per query call; ``"scene"``: seconds per whole stepped scene run."""
    loops: int
    """Calls per sample (1 for scenes)."""
    overhead_s: float
    """The timing loop's own cost per call, already subtracted from every sample."""
    values: tuple[float, ...] = field(default=())
    yardstick: tuple[float, ...] = field(default=())
    """Per sample, the yardstick of the round it was taken in (seconds; NaN: none that
    round); empty for a record of a run before the rounds."""

    @property
    def spread(self) -> Spread:
        return spread(self.values)

    @property
    def normalised(self) -> tuple[float, ...]:
        """Every sample over its round's yardstick; empty unless each sample has one."""
        return normalised(self.values, self.yardstick)

    def to_json(self) -> str:
        sticks = [y if math.isfinite(y) else None for y in self.yardstick]
        return json.dumps(asdict(self) | {"values": list(self.values), "yardstick": sticks})

    @classmethod
    def from_json(cls, line: str) -> TimingRecord:
        """A record from its line in ``timings.jsonl`` (of any format: see the module)."""
        data = _upgraded(json.loads(line))
        return cls(**{k: data[k] for k in COLUMNS[:6]}, values=tuple(data["values"]),
                   yardstick=tuple(data["yardstick"]))


def normalised(values: Sequence[float], yardstick: Sequence[float]) -> tuple[float, ...]:
    """Each value over its yardstick; empty unless every yardstick is finite and positive.

    >>> normalised([2.0, 4.0], [1.0, 2.0]), normalised([2.0], []), normalised([2.0], [math.nan])
    ((2.0, 2.0), (), ())
    """
    if len(yardstick) != len(values) or not all(y > 0 and math.isfinite(y) for y in yardstick):
        return ()
    return tuple(v / y for v, y in zip(values, yardstick, strict=True))


def _upgraded(data: dict[str, Any]) -> dict[str, Any]:
    """A line's content in the current form: ``yardstick`` (absent before the rounds, null
    for a round without one) as floats."""
    sticks = data.get("yardstick") or []
    return data | {"yardstick": [math.nan if y is None else float(y) for y in sticks]}


COLUMNS = ["case_id", "engine", "kind", "unit", "loops", "overhead_s", "n", "median_s",
           "q1_s", "q3_s", "iqr_s", "unstable", "values", "yardstick", "normalised_median"]
"""The columns of :func:`read_timings`; ``normalised_median``: the median of the samples over
their rounds' yardsticks (a ratio; NaN without them)."""


_READ: dict[tuple[str, int, int, int], pd.DataFrame] = {}
"""The last ``timings.jsonl`` read, by path, inode, size and modification time: a report reads
it twice (joined to the results, then on its own), and it takes a quartile pass per line."""


def read_timings(directory: Path) -> pd.DataFrame:
    """The timing records of a run, one row per case x engine, with their spread (a file read
    again unchanged is not parsed again: a copy of the last read is returned)."""
    path = directory / FILE
    try:
        stat = path.stat()
    except OSError:
        return _read_timings(path)
    key = (str(path.absolute()), stat.st_ino, stat.st_size, stat.st_mtime_ns)
    if key not in _READ:
        _READ.clear()
        _READ[key] = _read_timings(path)
    return _READ[key].copy()


def _read_timings(path: Path) -> pd.DataFrame:
    """Every line's samples with their spread (:func:`spread`, each line's quartiles and
    its normalised median taken together: :func:`quantile_rows`)."""
    lines = [_upgraded(line) for line in jsonlines.parse_lines(path)]  # whole lines only
    q1, median, q3 = quantile_rows([d["values"] for d in lines], (0.25, 0.5, 0.75)).T
    (normalised_median,) = quantile_rows(
        [normalised(d["values"], d["yardstick"]) for d in lines], (0.5,)).T
    rows = [data | {"n": len(data["values"]), "median_s": float(median[i]),
                    "q1_s": float(q1[i]), "q3_s": float(q3[i]),
                    "iqr_s": Spread(float(median[i]), float(q1[i]), float(q3[i]), 0).iqr,
                    "unstable": Spread(float(median[i]), float(q1[i]), float(q3[i]),
                                       0).unstable,
                    "normalised_median": float(normalised_median[i])}
            for i, data in enumerate(lines)]
    frame = pd.DataFrame(rows, columns=COLUMNS)
    return frame.drop_duplicates(["case_id", "engine"], keep="last").reset_index(drop=True)


def drift(timing: dict[str, Any]) -> dict[str, float]:
    """End / start median of each yardstick workload (1.0: the machine kept its speed).

    >>> drift({"yardstick": {"start": {"numpy": {"median_s": 2.0}},
    ...                      "end": {"numpy": {"median_s": 2.2}}}})
    {'numpy': 1.1}
    """
    start, end = timing["yardstick"]["start"], timing["yardstick"]["end"]
    return {name: round(end[name]["median_s"] / start[name]["median_s"], 12)
            if start[name]["median_s"] > 0 else math.nan for name in start}
