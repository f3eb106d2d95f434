"""Which rows the verdict's headline failure modes set aside: bad-input cases and zero-size
bodies.

An engine's top failure modes are what a reader takes from the verdict.  Two kinds of case
would crowd them with answers that say little about the engine's accuracy on ordinary
bodies: a *bad-input* case (tagged ``bad-input``: NaN, infinities, negative sizes; its
answers are robustness, judged apart) and a case with a *zero-size* body (a point, a flat
slab: a radius or a half-width of exactly 0, which some engines' compilers refuse).  Their
rows keep their status and count in every score; only the headline lists leave their modes
out, and say how many rows they hold (the list of all failure modes keeps them, labelled).

>>> import pandas as pd
>>> rows = pd.DataFrame({"case_id": ["nan", "point", "plain"],
...                      "tags": ["bad-input edge", "degenerate", ""]})
>>> list(labels(rows, {"point"}))
['bad input', 'zero size', '']
"""

from __future__ import annotations

from collections.abc import Collection, Mapping

import numpy as np
import pandas as pd

from crosscheck.core.schema import BAD_INPUT_TAG, AnyCase
from crosscheck.report.advise.profile import extents

BAD_INPUT = "bad input"
ZERO_SIZE = "zero size"


def bad_input(frame: pd.DataFrame) -> pd.Series:
    """Which rows are of bad-input cases: tagged ``bad-input``, as
    :attr:`~crosscheck.core.schema.AabbCase.bad_input` says of a case (rows carry the
    case's tags, space-separated; a frame without tags: none)."""
    if "tags" not in frame.columns:
        return pd.Series(False, index=frame.index, dtype=bool)
    tags = frame["tags"].fillna("").astype(str)
    codes, texts = pd.factorize(tags)  # each distinct tag list split once, not every row
    flags = np.array([BAD_INPUT_TAG in str(text).split() for text in texts], dtype=bool)
    return pd.Series(flags[codes], index=frame.index, dtype=bool)


def zero_size(cases: Mapping[str, AnyCase]) -> frozenset[str]:
    """The ids of the cases with a zero-size body: a radius or a half-width of exactly 0."""
    return frozenset(case_id for case_id, case in cases.items()
                     if any(size == 0 for size in extents(case)))


def labels(frame: pd.DataFrame, zero_sized: Collection[str] = ()) -> pd.Series:
    """Per row, why the headline sets it aside: :data:`BAD_INPUT`, :data:`ZERO_SIZE` (its
    case is in ``zero_sized``, from :func:`zero_size`) or ``""`` (kept)."""
    out = pd.Series("", index=frame.index, dtype=object)
    if zero_sized:
        out[frame["case_id"].astype(str).isin(list(zero_sized)).to_numpy()] = ZERO_SIZE
    out[bad_input(frame).to_numpy()] = BAD_INPUT
    return out
