"""The dynamics tables read at 1,024 px: no scene name, engine name or number breaks inside
itself (the table scrolls sideways in its frame instead), checked in headless Chromium on the
section as the report renders it, over the head every page shares."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from markupsafe import Markup

from crosscheck.report.style import templates
from tests.report.browser import needs_chromium, opened

pytestmark = pytest.mark.browser

ENGINES = ["pybullet", "pybullet-default", "pybullet-ccd", "pymunk", "pymunk-default", "mujoco",
           "mujoco-default", "box2d", "box2d-default", "box2d-bullet", "rapier", "rapier-default",
           "rapier-ccd", "fcl", "fcl-ccd-naive", "coal", "coal-default", "reference"]
"""As many engines as a full run steps scenes with."""
SCENES = ["fast-head-on-3d", "rest-3d-sphere-moved", "drop-3d-elastic-scaled",
          "scene-2d-cradle-5-iterations", "scene-2d-cluster-30-iterations", "drop-2d-e0.5"]

BROKEN = """(selector) => {
  const broken = [];
  for (const cell of document.querySelectorAll(selector)) {
    const walker = document.createTreeWalker(cell, NodeFilter.SHOW_TEXT);
    while (walker.nextNode()) {
      const node = walker.currentNode, words = /\\S+/g;
      let word;
      while ((word = words.exec(node.data))) {
        const range = document.createRange();
        range.setStart(node, word.index);
        range.setEnd(node, word.index + word[0].length);
        const lines = new Set([...range.getClientRects()].map(r => Math.round(r.top)));
        if (lines.size > 1) broken.push(word[0]);
      }
    }
  }
  return broken;
}"""
"""The words (runs of non-space characters) of the cells matching ``selector`` that the
browser laid out over more than one line."""


def best(i: int) -> dict[str, Any]:
    return {"case_id": f"case-{i}", "status": "disagree", "top": i % 5 == 0,
            "position_error": 7.27e-4 * (i + 1) if i % 3 else 8e-05, "step": "1/240 s",
            "iterations": 50 if i % 2 else None, "factor": f"{14250 + i:,}"}


def context() -> dict[str, Any]:
    scenes = [{"scene": s, "summary": "as accurate: rapier", "runs": [], "chart": Markup(""),
               "aligned": 0, "best": {e: best(i) for i, e in enumerate(ENGINES)}}
              for s in SCENES]
    cells = {e: {"beyond": i % 2 == 0, "first": "offset 1e+05" if i % 2 else "none to 1e+07",
                 "largest": "inf at 1e+05 (apex: 265 values here, 299 at the origin)"}
             for i, e in enumerate(ENGINES)}
    meta = {"blocks": [{"block": s, "coords": "dt 0.0167", "cells": cells} for s in SCENES],
            "engines": ENGINES, "points": [], "tolerance": 1e-6}
    return {"dynamics": {"runs": 4836, "engines": ENGINES, "scenes": scenes, "energy": None,
                         "metamorphic": meta}}


def test_no_name_or_number_of_the_dynamics_tables_breaks_at_1024_px(tmp_path: Path) -> None:
    needs_chromium()
    page_file = tmp_path / "dynamics.html"
    env = templates()
    page_file.write_text(
        '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
        + env.get_template("_page_head.html.j2").render() + "</head><body>"
        + env.get_template("_dynamics.html.j2").render(**context()) + "</body></html>",
        encoding="utf-8")
    with opened(page_file, width=1024) as page:
        page.wait_for_load_state("load")
        broken = {table: page.evaluate(BROKEN, f"#{table} td, #{table} th")
                  for table in ("dynamics-best", "dynamics-metamorphic-table")}
    assert broken == {"dynamics-best": [], "dynamics-metamorphic-table": []}
