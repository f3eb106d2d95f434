"""The stated-number rule: no page outside docs/generated/ (and no part of README outside its
generated blocks) states a measured count, size or time; and the checker itself."""

from __future__ import annotations

import pytest

from tools import stated_numbers
from tools.stated_numbers import findings


@pytest.mark.parametrize(("sentence", "stated"), [
    ("The full run took 130 s on this machine.", "130 s"),
    ("The report is 2.8 MB.", "2.8 MB"),
    ("It has 934 cases after sweep expansion.", "934 cases"),
    ("pybullet agrees on 43% of them.", "43%"),
    ("The suite of 1,654 items", "1,654 items"),
    ("a load event after 0.51 s (0.44-0.59)", "0.51 s"),
    ("about 1e6 pairs per second", "1e6 pairs"),
    ("it is 4.2x faster", "4.2x"),
    ("3 \u00d7 faster than the naive loop", "3 \u00d7"),
    ("the page takes 1400 px", "1400 px"),
    ("a 20 µs query", "20 µs"),
    ("took 9 minutes", "9 minutes"),
    ("541 cases/s per lane", "541 cases"),
    ("42.0 M pairs/s", "42.0 M pairs"),
    ("| pymunk | 7.05 µs |", "7.05 µs"),
])
def test_a_measured_number_in_prose_is_flagged(sentence: str, stated: str) -> None:
    assert [f.match for f in findings(sentence)] == [stated]


@pytest.mark.parametrize("sentence", [
    "Set `--timeout 30` to allow more time per case.",
    "pybullet is pinned at version 3.2.7.",
    "Both bodies move at 1 m/s towards each other.",
    "```sh\nmake run  # took 130 s\n```",
    "~~~\n934 cases\n~~~",
    "a 1400 x 1000 view of the page; at most 2 x jobs cases in flight",
    "2-D and 3-D cases, float32 rows, Python 3.11",
    "<!-- 43% of an old measurement -->",
    "[the large page](https://example.org/2.8MB-page-10s) and <https://example.org/10s>",
    "step two, the 1 m/s head-on case",
    "the declared `0.02` prediction distance",
])
def test_settings_versions_units_and_code_are_not_flagged(sentence: str) -> None:
    assert findings(sentence) == []


def test_findings_carry_the_line_of_the_page() -> None:
    text = "# Title\n\n```\n10 s\n```\nIt took `--samples 20` and\n2.8 MB in the end.\n"
    [found] = findings(text, "page.md")
    assert (found.path, found.line, found.match) == ("page.md", 7, "2.8 MB")


def test_readme_blocks_are_left_out_and_the_rest_is_checked() -> None:
    text = ("Front page.\n<!-- generated: headline.md -->\n| fcl | 80.8% | 13.9 µs |\n"
            "<!-- end generated -->\nIt took 70 s.\n")
    prose = stated_numbers.without_generated_blocks(text)
    assert [f.match for f in findings(prose)] == ["70 s"]
    assert [f.line for f in findings(prose)] == [5]


def test_no_page_states_a_measured_number_of_its_own() -> None:
    found = stated_numbers.check(stated_numbers.pages())
    assert not found, "\n".join(str(f) for f in found)


def test_the_pages_checked_are_the_readme_and_docs_outside_generated() -> None:
    names = [p.relative_to(stated_numbers.ROOT).as_posix() for p in stated_numbers.pages()]
    assert "README.md" in names and "docs/cli.md" in names
    assert not [n for n in names if n.startswith("docs/generated/")]
