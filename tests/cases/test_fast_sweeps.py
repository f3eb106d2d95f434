"""Bad fast-body and time-of-impact blocks are refused before any work, naming the case, the
field and the reason."""

from __future__ import annotations

from pathlib import Path

import pytest

from crosscheck.cases.load import load_paths

PAIR = """bodies = [
  { center = [-1.0, 0.0], radius = 0.05, mass = 1.0, velocity = [1.0, 0.0] },
  { center = [1.0, 0.0], radius = 0.05, mass = 1.0, velocity = [-1.0, 0.0] },
]
steps = { dt = [0.01] }
"""
SCENE = '[[case]]\nid = "f"\ndescription = "d"\nkind = "sphere_scene"\ndim = 2\n'


@pytest.mark.parametrize(("block", "field", "words"), [
    (SCENE + PAIR + "sweep = { step_travel = [1.0], phase = [1.0] }\n", "sweep.phase",
     "strictly between 0 and 1"),
    (SCENE + PAIR.replace("]\nsteps", "  { center = [3.0, 0.0], radius = 0.05, mass = 1.0, "
                          "velocity = [0.0, 0.0] },\n]\nsteps")
     + "sweep = { step_travel = [1.0] }\n", "sweep.step_travel", "has 3 bodies"),
    (SCENE + "duration = 1.0\n" + PAIR + "sweep = { step_travel = [1.0] }\n", "duration",
     "leave duration out"),
    (SCENE + PAIR.replace("velocity = [1.0", "velocity = [-1.0").replace(
        "velocity = [-1.0, 0.0] },\n]", "velocity = [1.0, 0.0] },\n]")
     + "sweep = { step_travel = [1.0] }\n", "bodies", "on a collision course"),
    (SCENE + PAIR, "duration", "missing"),
    ('[[case]]\nid = "s"\ndescription = "d"\nkind = "sphere"\ndim = 2\n'
     'a = { center = [0.0, 0.0], radius = 0.5 }\nb = { center = [2.0, 0.0], radius = 0.5 }\n'
     'sweep = { step_travel = [1.0] }\n', "sweep.step_travel", "sphere_scene cases only"),
    ('[[case]]\nid = "t"\ndescription = "d"\nkind = "sphere_toi"\ndim = 2\nduration = 0.0\n'
     'a = { center = [0.0, 0.0], radius = 0.5, velocity = [1.0, 0.0] }\n'
     'b = { center = [2.0, 0.0], radius = 0.5, velocity = [-1.0, 0.0] }\n', "duration",
     "must be > 0"),
], ids=["phase-on-grid", "three-bodies", "duration-given", "never-meet", "no-duration",
        "travel-on-a-pair", "toi-zero-interval"])
def test_a_bad_block_is_refused_with_its_field_and_reason(tmp_path: Path, block: str,
                                                          field: str, words: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(block, encoding="utf-8")
    result = load_paths([path], cache=False)
    assert result.cases == []
    assert [e.field for e in result.errors] == [field], result.errors
    assert words in result.errors[0].reason and str(path) in result.errors[0].message
