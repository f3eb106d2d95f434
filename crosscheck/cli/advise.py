"""``crosscheck advise``: which engine for my scene, from a stored run.

The library is :mod:`crosscheck.report.advise.recommend`; this module parses options and prints.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING

from rich.text import Text

from crosscheck.cli.console import fail, say, stdout, wrapped
from crosscheck.core.model import Kind
from crosscheck.core.options import QUICK_SCENE_STEPS

if TYPE_CHECKING:
    from crosscheck.report.advise.recommend import Advice, EngineAdvice, Envelope
    from crosscheck.results.run import Run


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``advise``."""
    p = sub.add_parser("advise", help="which engine for my scene: a graded, ranked answer "
                                      "from a stored run")
    p.add_argument("run_dir", type=Path, metavar="RUN_DIR", help="a stored run folder")
    p.add_argument("--dim", action="append", metavar="2|3",
                   help="dimension of the scene (repeatable; default: all)")
    p.add_argument("--kind", action="append", metavar="K",
                   help="kind of query (repeatable; default: every pair kind in the run)")
    p.add_argument("--scale", metavar="LO:HI",
                   help="body sizes: every radius and half-width within LO:HI (default: any "
                        "positive size; 0:HI admits zero-size bodies)")
    p.add_argument("--offset", metavar="MAX", help="largest |coordinate| of any centre")
    p.add_argument("--speed", metavar="MAX",
                   help="largest speed |v| of any body (responses, times of impact, scenes)")
    p.add_argument("--mass-ratio", metavar="MAX",
                   help="largest max(m)/min(m) (responses, scenes)")
    p.add_argument("--dt", metavar="[MIN:]MAX",
                   help="a scene's time step in seconds, e.g. 1/60 or 1/240:1/60")
    p.add_argument("--step-travel", metavar="MAX",
                   help="largest per-step travel |vb - va| dt / 2(ra + rb) of a scene's "
                        "fastest pair (beyond 1 a head-on pair can cross between two steps; "
                        "an r 0.05 ball at 300 m/s, dt 1/60: 25)")
    p.add_argument("--interval", metavar="[MIN:]MAX",
                   help="a time of impact's interval length in seconds")
    p.add_argument("--tag", action="append", metavar="TAG",
                   help="only cases carrying this tag (repeatable: every one), e.g. a scene "
                        "family: resting, bounce, gas")
    p.add_argument("--duration", metavar="MIN",
                   help="scenes simulating at least MIN seconds")
    p.add_argument("--tolerance", metavar="T",
                   help="absolute accuracy needed on lengths, m: hit (a verdict, on pairs "
                        "whose exact |gap| exceeds it), distance, settle")
    p.add_argument("--angle-tolerance", metavar="A",
                   help="absolute accuracy needed on angles, rad: normal")
    p.add_argument("--velocity-tolerance", metavar="V",
                   help="absolute accuracy needed on velocities, m/s: v1, v2, jitter")
    p.add_argument("--time-tolerance", metavar="S",
                   help="absolute accuracy needed on times, s: toi, bounce_time")
    p.add_argument("--fraction-tolerance", metavar="F",
                   help="accuracy needed on scene quantities measured as a share of their "
                        "own scale: positions (mean radii), velocities, momentum, energy, "
                        "energy_drift (per s), apex, divergence")
    p.add_argument("--rtol", metavar="R",
                   help="accuracy needed on lengths relative to the smallest body extent")
    p.add_argument("--quantities", metavar="Q,Q",
                   help="the quantities that matter (default: all), e.g. hit,distance; "
                        "scenes: settle, jitter, energy_drift, apex, bounce_time, divergence")
    p.add_argument("--touching-contact", action="store_true",
                   help="touching must count as contact (a touching rule then fails)")
    p.add_argument("--strict-conventions", action="store_true",
                   help="judge declared definitions (touching rules, the reading of an "
                        "input) like any answer; behaviours (damping, soft contact) always are")
    p.add_argument("--no-float32", action="store_true", help="float32 is not acceptable")
    p.add_argument("--json", action="store_true", help="print the advice as JSON")
    p.set_defaults(func=cmd_advise)


class OptionError(ValueError):
    """A command-line value that cannot be used; the message names the option."""


def _number(option: str, text: str | None) -> float | None:
    """A number, or a fraction such as 1/60 (None: not given)."""
    if text is None:
        return None
    try:
        value = float(Fraction(text.strip())) if "/" in text else float(text)
    except (ValueError, ZeroDivisionError):
        raise OptionError(f"{option}: not a number: {text!r}") from None
    if math.isnan(value):
        raise OptionError(f"{option}: not a number: {text!r}")
    return value


def _range(option: str, text: str | None, shape: str = "[MIN:]MAX") -> tuple[float, float] | None:
    """``MIN:MAX``, or ``MAX`` alone (from 0) where ``shape`` allows it."""
    if text is None:
        return None
    parts = text.split(":")
    if len(parts) == 1 and shape.startswith("["):
        parts = ["0", *parts]
    if len(parts) != 2:
        raise OptionError(f"{option}: expected {shape}, got {text!r}")
    lo, hi = (_number(option, part) for part in parts)
    assert lo is not None and hi is not None
    return lo, hi


def _dims(texts: list[str] | None) -> tuple[int, ...]:
    dims = tuple(text.strip() for text in texts or [])
    for text in dims:
        if text not in ("2", "3"):
            raise OptionError(f"--dim: must be 2 or 3, got {text!r}")
    return tuple(sorted({int(text) for text in dims}))


def _kinds(texts: list[str] | None) -> tuple[str, ...]:
    known = [str(k) for k in Kind]
    for text in texts or []:
        if text not in known:
            raise OptionError(f"--kind: unknown kind {text!r} (choose from {', '.join(known)})")
    return tuple(dict.fromkeys(texts or []))


def _quantities(text: str | None) -> tuple[str, ...]:
    from crosscheck.core.model import quantities_of

    known = list(dict.fromkeys(q for k in Kind for q in quantities_of(k)))
    names = tuple(dict.fromkeys(q.strip() for q in (text or "").split(",") if q.strip()))
    for name in names:
        if name not in known:
            raise OptionError(f"--quantities: unknown quantity {name!r} "
                              f"(choose from {', '.join(known)})")
    return names


def _tags(texts: list[str] | None) -> tuple[str, ...]:
    tags = tuple(dict.fromkeys(text.strip() for text in texts or []))
    if any(not tag for tag in tags):
        raise OptionError("--tag: must not be empty")
    return tags


def envelope_of(args: argparse.Namespace) -> Envelope:
    """The envelope the options state; OptionError or EnvelopeError naming a bad option (an
    option that applies to none of the asked kinds among them)."""
    from crosscheck.report.advise.recommend import Envelope

    envelope = Envelope(
        dims=_dims(args.dim), kinds=_kinds(args.kind), scale=_range("--scale", args.scale, "LO:HI"),
        offset=_number("--offset", args.offset), speed=_number("--speed", args.speed),
        mass_ratio=_number("--mass-ratio", args.mass_ratio),
        dt=_range("--dt", args.dt), step_travel=_number("--step-travel", args.step_travel),
        interval=_range("--interval", args.interval),
        tolerance=_number("--tolerance", args.tolerance), rtol=_number("--rtol", args.rtol),
        angle_tolerance=_number("--angle-tolerance", args.angle_tolerance),
        velocity_tolerance=_number("--velocity-tolerance", args.velocity_tolerance),
        time_tolerance=_number("--time-tolerance", args.time_tolerance),
        fraction_tolerance=_number("--fraction-tolerance", args.fraction_tolerance),
        quantities=_quantities(args.quantities), touching_contact=args.touching_contact,
        strict_conventions=args.strict_conventions, float32=not args.no_float32,
        tags=_tags(args.tag), duration=_number("--duration", args.duration))
    envelope.check()
    return envelope


def _stored(directory: Path) -> Run:
    from crosscheck.results.run import read_run

    if not directory.is_dir():
        raise OptionError(f"RUN_DIR: {directory} is not a folder")
    run = read_run(directory)
    if run.results.empty:
        raise OptionError(f"RUN_DIR: {directory} holds no results")
    return run


def cmd_advise(args: argparse.Namespace) -> int:
    from crosscheck.report.advise.recommend import EnvelopeError, advise
    from crosscheck.results.store import StoreError

    try:
        envelope = envelope_of(args)
        run = _stored(args.run_dir)
        advice = advise(run, envelope)
    except (OptionError, EnvelopeError) as exc:
        fail(str(exc))
        return 2
    except StoreError as exc:
        fail(f"RUN_DIR: {exc}")
        return 2
    if args.json:
        print(json.dumps(advice.to_json(), indent=2))  # whole lines: never wrapped
        return 0 if advice.cases else 1
    if not advice.cases:
        unasked = (f" ({advice.not_asked} would, but this --quick run did not ask them)"
                   if advice.not_asked else "")
        fail(f"no case of the run lies inside this envelope{unasked}: widen it")
        return 1
    print_advice(advice)
    return 0


TIER_STYLES = {"passes": "green", "partial": "yellow", "fails": "red", "unsupported": ""}
"""Each tier's colour in the table."""


def ranking_lines(rows: Sequence[tuple[str, EngineAdvice]], width: int) -> list[Text]:
    """The ranking (:mod:`crosscheck.report.advise.table`) as aligned columns, one line per
    engine, with its worst answer on the line below (indented, wrapped at spaces to
    ``width``, never cut): a case id is too long to share a line with the figures in 80
    columns."""
    from crosscheck.report.advise.table import cells, header, is_counted, worst_text

    counted = is_counted(engine for _, engine in rows)
    head = header(counted)
    table = [head, *(cells(rank, engine, counted) for rank, engine in rows)]
    widths = [max(len(row[i]) for row in table) for i in range(len(head))]

    def line(row: Sequence[str], tier_style: str = "", style: str = "") -> Text:
        text = Text(style=style)
        for i, (cell, size) in enumerate(zip(row, widths, strict=True)):
            text.append("  " if i else "")
            text.append(cell.ljust(size) if i < 3 else cell.rjust(size),
                        tier_style if i == 2 else "")
        return text

    lines = [line(head, style="bold"), Text("─" * (sum(widths) + 2 * (len(widths) - 1)))]
    indent = " " * (widths[0] + 2)
    for (_, engine), row in zip(rows, table[1:], strict=True):
        lines.append(line(row, TIER_STYLES[engine.tier]))
        worst = worst_text(engine)
        if worst != "-":
            lines += [Text(text) for text in wrapped(f"{indent}worst: {worst}", width)]
    return lines


def repeat_line(advice: Advice) -> str:
    """What the repeat check found in the envelope, per engine: the cases that answered
    differently when asked again (of those asked), or that none did, or that it did not run."""
    if not advice.repeat_checked:
        return "repeat check: not run (crosscheck run --repeat-check)"
    engines = advice.ranking + advice.unsupported + advice.excluded + advice.baselines
    changed = [f"{e.engine} {e.nondeterministic} of {e.repeated}" for e in engines
               if e.nondeterministic]
    if not changed:
        asked = sum(e.repeated for e in engines)
        return (f"repeat check: every case asked again answered the same "
                f"({asked} case x engine pairs)")
    return (f"answered differently when asked again (cases): {', '.join(changed)}; "
            "every other engine answered the same")


UNIT_WORDS = {"m": "lengths", "rad": "angles", "m/s": "velocities", "s": "times",
              "fraction": "shares of their scale"}
"""How the accuracy line names each unit's quantities."""


def accuracy_text(advice: Advice) -> str:
    """The accuracy asked of each unit the answer's quantities are in, e.g. 'lengths 1e-09 m
    or rtol 1e-06 x size, angles: agree only'."""
    from crosscheck.report.advise.units import UNITS

    need = advice.envelope
    parts = []
    for unit in dict.fromkeys(UNITS[q] for q in advice.quantities):
        value = need.tolerances()[unit]
        shown = "" if unit == "fraction" else f" {unit}"
        text = f"{UNIT_WORDS[unit]}" + (": agree only" if value is None else
                                        f" {value:g}{shown}")
        if unit == "m" and need.rtol is not None:
            text += f" or rtol {need.rtol:g} x size"
        parts.append(text)
    return ", ".join(parts)


def quick_line(advice: Advice) -> str | None:
    """What a ``--quick`` run left out of the answer (None: not a quick run)."""
    if not advice.quick:
        return None
    steps = QUICK_SCENE_STEPS
    skipped = (f"{advice.not_asked} cases of this profile not asked (scenes over {steps} "
               "steps), " if advice.not_asked else "")
    return (f"a --quick run: {skipped}no timing phase; rerun without --quick for "
            f"{'them and ' if advice.not_asked else ''}the costs")


def print_advice(advice: Advice) -> None:
    """A line per engine, ranked, its worst answer below; the baselines apart; whole at 80
    columns (details: --json)."""
    need = advice.envelope
    family = "".join(f"; tag {tag}" for tag in need.tags) + (
        "" if need.duration is None else f"; at least {need.duration:g} s")
    say(f"the answer rests on {advice.cases} cases ({', '.join(advice.kinds)}; "
        f"{', '.join(f'{d}-D' for d in advice.dims)}{family}); an engine's on those it "
        "answers (cases)")
    if advice.cells:
        say("cells of the configuration space they cover (docs/coverage.md), 2-way: " + ", ".join(
            f"{space} {covered} of {cells}" for space, (covered, cells) in advice.cells.items()))
    say(f"accuracy: {accuracy_text(advice)}")
    quick = quick_line(advice)
    if quick:
        say(quick)
    from crosscheck.report.advise.table import rows

    for text in ranking_lines(rows(advice), stdout.width):
        stdout.print(text, soft_wrap=True)
    for label, engines in (("answer no case (not ranked)", advice.unsupported),
                           ("float32, not accepted", advice.excluded)):
        if engines:
            say(f"{label}: {', '.join(e.engine for e in engines)}")
    broken = [f"{e.engine} {status} {n}" for e in advice.ranking + advice.baselines
              for status, n in e.robustness.items() if status in ("crash", "timeout")]
    say(repeat_line(advice))
    if advice.bad_input_cases:
        say(f"bad input, judged apart ({advice.bad_input_cases} cases): "
            + (", ".join(broken) if broken else "no crash or timeout"))
    if advice.passing:
        say(f"passing: {', '.join(e.engine for e in advice.passing)} ({advice.passing_order})")
    else:
        more = f" and {len(advice.deciding) - 3} more" if len(advice.deciding) > 3 else ""
        say(f"nothing passes the whole envelope; closest: {advice.closest or '-'}, decided by "
            f"{'; '.join(advice.deciding[:3]) or '-'}{more} (details: --json)")
