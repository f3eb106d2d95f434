"""The report's "Which engine for my scene" section: the command line and Python's answers.

The page judges nothing.  Its form writes the ``crosscheck advise`` command of the profile
its fields state (each field is one option of the command, :data:`FIELDS`; the page's script
only joins the filled ones, quoted as ``shlex`` quotes), and below it the section shows the
answers of the standard profiles (:data:`STANDARD`), computed here at render time by
:func:`crosscheck.report.advise.recommend.advise` and laid out by
:mod:`crosscheck.report.advise.table`, exactly as the command prints them.  A profile the
form states that is one of them opens its answer; any other is answered by the command.

>>> word(1e-09), word(1000.0), word(1 / 60)
('1e-09', '1000', '0.016666666666666666')
>>> command_words(Envelope(dims=(3,), kinds=("sphere",), scale=(0.01, 10.0), tolerance=1e-9))
['--dim', '3', '--kind', 'sphere', '--scale', '0.01:10', '--tolerance', '1e-09']
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass
from typing import Any

from crosscheck.report import repro_links
from crosscheck.report.advise import table
from crosscheck.report.advise.grade import EngineAdvice
from crosscheck.report.advise.profile import Envelope, EnvelopeError
from crosscheck.report.advise.recommend import Advice, advise
from crosscheck.results.run import Run


@dataclass(frozen=True)
class Field:
    """One field of the form: its name, the ``advise`` option it writes, what it reads,
    and the :class:`Envelope` attribute the option sets."""

    name: str
    option: str
    label: str
    placeholder: str
    attribute: str
    flag: bool = False


FIELDS = (
    Field("dim", "--dim", "dim", "2 or 3", "dims"),
    Field("kind", "--kind", "kind", "every pair kind", "kinds"),
    Field("scale", "--scale", "body size", "lo:hi", "scale"),
    Field("offset", "--offset", "|coordinate| up to", "inf", "offset"),
    Field("speed", "--speed", "body speed up to", "inf", "speed"),
    Field("ratio", "--mass-ratio", "mass ratio up to", "inf", "mass_ratio"),
    Field("dt", "--dt", "dt", "[min:]max", "dt"),
    Field("travel", "--step-travel", "step travel up to", "inf", "step_travel"),
    Field("lasts", "--duration", "lasting at least", "0 s", "duration"),
    Field("interval", "--interval", "interval", "[min:]max", "interval"),
    Field("tag", "--tag", "tag", "any", "tags"),
    Field("tolerance", "--tolerance", "tolerance (m)", "0", "tolerance"),
    Field("rtol", "--rtol", "rtol", "none", "rtol"),
    Field("angle", "--angle-tolerance", "angle (rad)", "0", "angle_tolerance"),
    Field("velocity", "--velocity-tolerance", "velocity (m/s)", "0", "velocity_tolerance"),
    Field("time", "--time-tolerance", "time (s)", "0", "time_tolerance"),
    Field("fraction", "--fraction-tolerance", "share", "0", "fraction_tolerance"),
    Field("quantities", "--quantities", "quantities", "all", "quantities"),
    Field("touching", "--touching-contact", "touching must count as contact", "",
          "touching_contact", flag=True),
    Field("strict", "--strict-conventions", "judge definitions like any answer", "",
          "strict_conventions", flag=True),
    Field("nof32", "--no-float32", "float32 not acceptable", "", "float32", flag=True),
)
"""The form's fields, one ``crosscheck advise`` option each, in the command's order."""

STANDARD = (
    ("every pair kind, exact answers", Envelope()),
    ("3-D spheres at float64 accuracy", Envelope(
        dims=(3,), kinds=("sphere",), scale=(0.01, 10.0), offset=10.0, tolerance=1e-9,
        angle_tolerance=1e-9)),
    ("3-D boxes far from the origin", Envelope(
        dims=(3,), kinds=("aabb",), scale=(0.1, 10.0), offset=1e4, tolerance=1e-4,
        angle_tolerance=1e-4)),
    ("2-D spheres", Envelope(
        dims=(2,), kinds=("sphere",), scale=(0.1, 10.0), offset=1e3, tolerance=1e-6,
        angle_tolerance=1e-6)),
    ("responses with a large mass ratio", Envelope(
        kinds=("sphere_response",), mass_ratio=1e3, speed=10.0, offset=1e3,
        velocity_tolerance=1e-9)),
    ("responses with a large mass ratio, zero-size bodies too", Envelope(
        kinds=("sphere_response",), mass_ratio=1e3, speed=10.0, offset=1e3,
        velocity_tolerance=1e-9, scale=(0.0, 10.0))),
)
"""The standard profiles the section answers: the exact answers on every pair kind, the four
scene profiles of ``docs/comparing-and-advice.md``, and the fourth again with ``--scale
0:10``, which admits zero-size bodies (without ``--scale`` every body has a positive size)."""


def word(value: float) -> str:
    """A number as an option's word: short when that reads back exactly."""
    short = f"{value:g}"
    return short if float(short) == value else repr(value)


def _words(field: Field, value: Any) -> list[str]:
    if field.flag:
        wanted = not value if field.attribute == "float32" else bool(value)
        return [field.option] if wanted else []
    if value is None or value == ():
        return []
    if field.attribute == "quantities":
        return [field.option, ",".join(value)]
    if isinstance(value, tuple) and field.attribute in ("dims", "kinds", "tags"):
        return [w for v in value for w in (field.option, str(v))]
    if isinstance(value, tuple):
        return [field.option, ":".join(word(v) for v in value)]
    return [field.option, word(float(value))]


def command_words(envelope: Envelope) -> list[str]:
    """The ``crosscheck advise`` options that state ``envelope``, in :data:`FIELDS` order."""
    return [w for field in FIELDS for w in _words(field, getattr(envelope, field.attribute))]


def command(run_dir: str, envelope: Envelope) -> str:
    """The whole command, quoted for a POSIX shell."""
    return shlex.join(["crosscheck", "advise", run_dir, *command_words(envelope)])


def _row(cells: tuple[str, ...], engine: EngineAdvice, run: Run) -> dict[str, Any]:
    worst = engine.worst
    return {"cells": cells, "engine": engine.engine, "tier": engine.tier,
            "worst": table.worst_text(engine),
            "case": worst.case_id if worst else None,
            "repro": repro_links.link(worst.case_id, engine.engine, run.repros) if worst else "",
            "repro_command": worst.repro_command if worst else ""}


def _lines(advice: Advice) -> list[str]:
    """What the command prints around the table: who answers nothing, who passes."""
    lines = []
    if advice.unsupported:
        lines.append(f"Answer no case (not ranked): {table.engines_text(advice.unsupported)}")
    if advice.excluded:
        lines.append(f"float32, not accepted: {table.engines_text(advice.excluded)}")
    if advice.passing:
        lines.append(f"Passing ({advice.passing_order}): {table.engines_text(advice.passing)}")
    else:
        lines.append(f"Nothing passes the whole envelope; closest: {advice.closest or '-'}, "
                     f"decided by {'; '.join(advice.deciding) or '-'}")
    return lines


def answer(run: Run, title: str, envelope: Envelope) -> dict[str, Any]:
    """One standard profile's answer as the section shows it: its command, and its table and
    lines, or why the run gives none (``refused``)."""
    shown = {"title": title, "command": command(str(run.directory), envelope),
             "options": shlex.join(command_words(envelope))}
    try:
        advice = advise(run, envelope)
    except EnvelopeError as exc:
        return shown | {"refused": f"No answer from this run: {exc}."}
    if not advice.cases:
        return shown | {"refused": "No case of this run lies inside this envelope."}
    head, rows = table.table(advice)
    dims = ", ".join(f"{d}-D" for d in advice.dims)
    return shown | {"refused": "", "head": head, "rows": [_row(c, e, run) for c, e in rows],
                    "cases": f"{advice.cases} cases inside the envelope "
                             f"({', '.join(advice.kinds)}; {dims}).",
                    "lines": _lines(advice)}


def section(run: Run, kinds: list[str], quantities: list[str]) -> dict[str, Any]:
    """The section's context: the form's fields (with the run's kinds and quantities), the
    run folder the command names and every standard profile's answer."""
    return {"fields": FIELDS, "kinds": kinds, "quantities": quantities,
            "run_dir": str(run.directory),
            "answers": [answer(run, title, envelope) for title, envelope in STANDARD]}
