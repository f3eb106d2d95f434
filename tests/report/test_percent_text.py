"""How a share is written (:func:`crosscheck.report.text.percent`, the one place that writes
an advise row's share within the accuracy): only a whole share reads 100%, so a failing row
(some answer not within: a share below 1) never shows "100% within"."""

from __future__ import annotations

from crosscheck.report.text import percent


def test_a_share_short_of_one_never_reads_100_percent() -> None:
    for answered in (200, 1000, 2001, 2496, 9999, 123_457):
        assert percent((answered - 1) / answered) != "100%", answered
    assert percent(1.0) == "100%"


def test_a_share_that_would_round_up_to_100_is_cut_to_a_tenth_of_a_per_cent() -> None:
    assert [percent(s) for s in (0.9996, 0.9995, 0.995, 0.9949, 0.74, 0.0)] == [
        "99.9%", "99.9%", "99.5%", "99%", "74%", "0%"]
