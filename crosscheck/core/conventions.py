"""An engine's declared conventions: its documented rules, each a definition or a behaviour.

:class:`Conventions` is what an adapter declares (``Adapter.conventions``, see
:mod:`crosscheck.core.contract`): each field a rule of the engine that differs from the
textbook's, with its source.  The rules feed the report's conventions table and the
category of every disagreement (:mod:`crosscheck.truth.categories`).

Every field also says what kind of rule it is (:class:`Nature`, in the field's metadata,
with the reason): a *definition* settles what a question means where the textbook's reading
is one choice among several (what counts as touching at zero gap, which way a normal points,
how an input is read); a *behaviour* is what the engine does, and changes the answer to a
question with one meaning (damping, soft contact, a restitution threshold, a speed cap).  A
reader judging whether an answer is good enough for a use (``crosscheck advise``) excuses a
disagreement only where a definition explains it.

>>> nature_of("touching"), nature_of("damping")
(<Nature.DEFINITION: 'definition'>, <Nature.BEHAVIOUR: 'behaviour'>)
>>> why("damping")
'velocities shrink every second: speed and energy are lost'
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from enum import StrEnum
from typing import Any

TEXTBOOK_TOUCHING: dict[str, bool] = {"sphere": False, "face": True, "edge": True,
                                      "corner": True}
"""The textbook's rule: touching boxes overlap (any feature); touching spheres do not collide."""
FEATURES = tuple(TEXTBOOK_TOUCHING)
"""Where two bodies meet: a sphere, or a box's face, edge or corner."""
SPEED_CAP_STAGES = ("", "step", "per coordinate", "before restitution",
                    "before the contact solve")
"""Where a declared speed cap acts (see :class:`Conventions`; '': no cap)."""
TUPLES = ("no_value", "rest_gap", "sources")
"""The fields that are tuples (JSON writes them as lists)."""
RESTITUTION_MODELS = ("", "soft", "predictive")
"""How a bounce is set (see :class:`Conventions`): the case's e, a soft contact's own, or a
predictive contact's (restitution 0 first).  The last two can only lose a bounce."""


class Nature(StrEnum):
    """What a declared convention is (see the module docstring)."""

    DEFINITION = "definition"
    """What the question means: a row it explains is right by the engine's definition."""
    BEHAVIOUR = "behaviour"
    """What the engine does: it changes the answer, and a row it explains is still off."""


def _definition(why: str) -> dict[str, Any]:
    return {"nature": Nature.DEFINITION, "why": why}


def _behaviour(why: str) -> dict[str, Any]:
    return {"nature": Nature.BEHAVIOUR, "why": why}


@dataclass(frozen=True, slots=True)
class Conventions:
    """An engine's documented rules, each with its source; each field's metadata says
    whether it is a definition or a behaviour, and why (:data:`NATURES`).

    ``touching`` maps a touching feature (``sphere``; ``face``, ``edge`` or
    ``corner`` for boxes) to whether the engine counts exact touching there as
    contact; a feature not listed follows the textbook (boxes touching
    overlap, spheres touching do not collide).  ``margins`` maps a feature to
    an absolute distance tolerance there (collision margin, GJK tolerance,
    slop); a feature not listed has none.  ``rtol`` is a relative tolerance
    (the engine's arithmetic precision), scaled by the case's size.
    ``restitution_threshold`` is the approach speed below which the engine
    makes a bounce perfectly inelastic (0: none); ``resolves_separating`` is
    False for engines that leave bodies which are already moving apart alone
    (the textbook formula exchanges momentum anyway).  ``time_step`` is the
    fixed step (s) in which the engine resolves a response (None: it does
    not step); ``damping`` a velocity damping the engine applies per second
    of simulated time in scenes (0: none).  ``zero_mass`` says how the engine
    reads a body of mass 0 (``"static"``: immovable, infinite mass; ``""``:
    as the textbook does), ``negative_extents`` how it reads a negative
    radius or half-width (``"absolute"``: as its magnitude; ``""``: rejects
    it or reads it literally, as the textbook does).  ``restitution_model``
    is ``"soft"`` for an engine with no coefficient of restitution, whose
    contact model sets the bounce, or ``"predictive"`` for one that first meets an impact
    its continuous detection catches with a predictive contact of restitution 0 (the
    bounce keeps between 0 and e of the approach: pybullet-ccd) (``""``: the case's e, as
    declared in ``restitution``); ``friction`` the Coulomb coefficient that acts between
    the bodies in responses (0: frictionless, as the textbook).  Both are read
    by :mod:`crosscheck.truth.contact_model`.

    What acts on which quantity (:mod:`crosscheck.truth.allowance`):
    ``verdict_margins`` maps a feature to a threshold that acts on the verdict
    alone (a prediction distance, a collision threshold, a polygon skin); None
    when the verdict has the same margins as lengths.  ``response_rtol`` is the
    precision of a response's velocities relative to the case's largest speed,
    where it is not the arithmetic ``rtol`` (a contact model solved to a
    measured precision; None: ``rtol``).  ``no_value`` names the declared
    configurations in which the engine gives no value (rules of
    :mod:`crosscheck.truth.no_value`): an answer without a value anywhere else
    is an ``error``.  ``max_speed`` is a speed cap (m/s; None: none) and
    ``max_speed_at`` where it acts (always at every step, not only on the initial
    speeds): ``"per coordinate"`` on each velocity coordinate at the end of every
    step (a speed, clipped per axis: PyBullet's multibody clamp); ``"step"`` on each
    body's velocity at the end of every step, ``"before restitution"`` after the contact
    solve and before the bounce is added, ``"before the contact solve"`` on the velocities
    the contact solve starts from, the bounce then taken from the uncapped approach (Box2D
    v3: clamped in each sub-step's velocity integration).  ``sampled_contacts`` is True for
    an engine that looks for contacts only at the start of each step and pushes only
    bodies that overlap there (no continuous or predictive contact): a contact
    shorter than a step can fall between two steps.  ``speculative_contacts`` is True
    for an engine that makes a contact at a step start for any gap the step's motion
    closes (Rapier's soft CCD): the impact is met at the start of the step that holds
    it, resolved along the line of centres there, before the bodies touch.
    ``bounce_at_step_end`` is True for an engine that adds the bounce once, at the end of
    the step that meets a contact, after that step's positions are integrated (Box2D v3's
    ``b2ApplyRestitution``): the bodies part a step later than a run that resolves the
    contact where the step starts, each centre up to its share of the bounce times the step
    behind.  ``bounce_from_step_start`` is True for an engine that takes that bounce from
    the approach at the start of the step (before the step's gravity and contact solve),
    once per contact and step, and only where that approach is at least the restitution
    threshold: an impact chained within a step (a pair touching at rest when the step
    starts) gets no bounce, and a fall meets the threshold up to ``|g| dt`` slower than its
    impact: energy is lost, never gained.

    Times of impact (:mod:`crosscheck.truth.toi`): ``toi_target`` is the separation of
    the surfaces at which the engine's time-of-impact query stops (negative: an
    overlap; 0: touching, as the exact first contact), ``toi_tolerance`` how far from it
    the query may stop (its declared termination tolerance, a length) and
    ``toi_time_tolerance`` the same as a fraction of the interval (a solver that stops
    once its time step is that small); ``toi_min_centre_distance`` a distance between the
    centres closer than which the query never aims (Box2D: ``linearSlop``).  ``toi_samples``
    is 0 for a continuous query, or
    the number ``n`` of discrete tests at ``t = i T / (n - 1)`` that a sampling query makes
    (2: the interval's two ends); ``toi_end_excluded`` is True for a query that counts no
    contact exactly at the interval's end.

    Gravity and walls (:mod:`crosscheck.truth.scene_measures`): ``rest_gap`` is the band
    ``(lo, hi)`` of signed gaps (m; negative: penetration) at which the engine's contact
    model holds a sphere resting on a wall or on another sphere (its slop, skin or
    margin), from its documentation or source; ``rest_sink_steps`` how far below that band
    a resting sphere may sink because of the step, in units of ``|g| dt**2`` (an engine
    that integrates gravity before it resolves the contact); ``rest_sink_s2`` the same
    for a soft contact whose steady penetration is ``|g|`` times a time squared (s**2;
    MuJoCo's ``solref``).  ``sleeps`` is True for an engine that zeroes the velocity of a
    body at rest after a while (sleeping); ``wall_restitution`` says how a wall's bounce
    is set (``""``: with the scene's e, as between the spheres).
    """

    box_extents: str = field(default="half", metadata=_definition(
        "how a box's size is read (half- or full widths): the adapter converts it, so it "
        "names the input, never changes the answer"))
    normal: str = field(default="A to B", metadata=_definition(
        "which way a normal points: a sign, which the adapter turns to A to B"))
    touching: dict[str, bool] = field(default_factory=dict, metadata=_definition(
        "what counts as contact at exactly zero gap: a boundary the textbook itself settles "
        "one way for spheres and the other for boxes"))
    margins: dict[str, float] = field(default_factory=dict, metadata=_behaviour(
        "a collision margin or GJK tolerance moves the surface the engine measures: its "
        "distances and verdicts change by that much"))
    rtol: float = field(default=0.0, metadata=_behaviour(
        "the engine's arithmetic precision: its numbers are that far off"))
    restitution: str = field(default="case value", metadata=_definition(
        "how the engine combines two bodies' coefficients: the adapter sets them so that the "
        "pair gets the case's e"))
    restitution_threshold: float = field(default=0.0, metadata=_behaviour(
        "a slower impact is made inelastic: the velocities and the energy after it change"))
    resolves_separating: bool = field(default=True, metadata=_definition(
        "whether bodies already moving apart collide at all: the textbook's impulse acts "
        "regardless, the engine's none; there is no collision to answer for"))
    time_step: float | None = field(default=None, metadata=_behaviour(
        "the contact is met at the configuration of the engine's step, not the case's"))
    damping: float = field(default=0.0, metadata=_behaviour(
        "velocities shrink every second: speed and energy are lost"))
    zero_mass: str = field(default="", metadata=_definition(
        "how a mass of 0 is read (a static, immovable body): the engine API's way to say so"))
    negative_extents: str = field(default="", metadata=_definition(
        "how a negative radius or half-width is read (as its magnitude): an input's reading"))
    restitution_model: str = field(default="", metadata=_behaviour(
        "soft or predictive contact: the contact model sets the bounce, not the case's e, "
        "and the velocities and the energy after an impact change"))
    friction: float = field(default=0.0, metadata=_behaviour(
        "a tangential impulse the frictionless textbook does not have"))
    verdict_margins: dict[str, float] | None = field(default=None, metadata=_behaviour(
        "contact reported while the bodies are apart (a prediction distance, a collision "
        "threshold, a polygon skin): separated pairs are called touching"))
    response_rtol: float | None = field(default=None, metadata=_behaviour(
        "the precision a contact solve reaches: velocities that far off"))
    no_value: tuple[str, ...] = field(default=(), metadata=_definition(
        "where the quantity has no value in the engine's arithmetic, as the textbook formula "
        "in that precision defines none (coincident centres): the question has no answer"))
    max_speed: float | None = field(default=None, metadata=_behaviour(
        "a speed cap: faster bodies are slowed, and everything after changes"))
    max_speed_at: str = field(default="", metadata=_behaviour(
        "where the speed cap acts (declared with max_speed)"))
    sampled_contacts: bool = field(default=False, metadata=_behaviour(
        "contacts looked for only at step starts: one shorter than a step is missed"))
    speculative_contacts: bool = field(default=False, metadata=_behaviour(
        "contacts made at a step start for the gap the step's motion closes: an impact is "
        "met where the step that holds it starts, its normal taken there"))
    bounce_at_step_end: bool = field(default=False, metadata=_behaviour(
        "the bounce is added at the end of the step that meets a contact, after that step's "
        "positions are integrated: the bodies part a step late"))
    bounce_from_step_start: bool = field(default=False, metadata=_behaviour(
        "the bounce is taken from the approach at the step's start, once per contact: an "
        "impact chained within a step, or a fall slower than the threshold when its step "
        "starts, gets none: energy is lost"))
    toi_target: float = field(default=0.0, metadata=_definition(
        "what counts as the impact: the separation at which the engine's time-of-impact "
        "query calls the surfaces in contact (Box2D aims at a small overlap); its time is "
        "right for that separation"))
    toi_tolerance: float = field(default=0.0, metadata=_behaviour(
        "how far from its target the query may stop: a precision"))
    toi_time_tolerance: float = field(default=0.0, metadata=_behaviour(
        "how far from its target the query may stop, as a share of the interval: a precision"))
    toi_min_centre_distance: float = field(default=0.0, metadata=_behaviour(
        "a distance between the centres the query never aims closer than: the times of "
        "small bodies change"))
    toi_samples: int = field(default=0, metadata=_behaviour(
        "a sampling query tests a few times: a contact between two of them is missed"))
    toi_end_excluded: bool = field(default=False, metadata=_definition(
        "whether a contact exactly at the interval's end is in the interval: a boundary"))
    rest_gap: tuple[float, float] = field(default=(0.0, 0.0), metadata=_behaviour(
        "the gap at which the contact model holds a resting body (slop, skin, margin): where "
        "it settles changes"))
    rest_sink_steps: float = field(default=0.0, metadata=_behaviour(
        "a resting body sinks because of the step: where it settles changes"))
    rest_sink_s2: float = field(default=0.0, metadata=_behaviour(
        "a soft contact's steady penetration: where a body settles changes"))
    sleeps: bool = field(default=False, metadata=_behaviour(
        "a body at rest is put to sleep, its velocity zeroed: momentum and energy change"))
    wall_restitution: str = field(default="", metadata=_definition(
        "how a wall's coefficient is made from the scene's e: the adapter sets it so that "
        "the scene's e acts"))
    notes: str = ""
    sources: tuple[str, ...] = field(default=())

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Conventions:
        """Conventions as ``run.json`` records them (``asdict``: tuples as lists); a field
        this version does not know is ignored, one an older run lacks keeps its default.

        >>> Conventions.from_json({"rest_gap": [-1e-5, 0.0], "margin": 0.1}).rest_gap
        (-1e-05, 0.0)
        """
        known = {f.name for f in fields(cls)}
        values: dict[str, Any] = {k: tuple(v) if k in TUPLES and isinstance(v, list) else v
                                  for k, v in data.items() if k in known}
        return cls(**values)

    def __post_init__(self) -> None:
        if (self.max_speed is None) != (self.max_speed_at == ""):
            raise ValueError("max_speed and max_speed_at are declared together")
        if self.max_speed_at not in SPEED_CAP_STAGES:
            raise ValueError(f"max_speed_at {self.max_speed_at!r} not one of {SPEED_CAP_STAGES}")
        if self.restitution_model not in RESTITUTION_MODELS:
            raise ValueError(f"restitution_model {self.restitution_model!r} not one of "
                             f"{RESTITUTION_MODELS}")

    @property
    def bounce_may_lose(self) -> bool:
        """The declared contact model may keep less of a bounce than e (soft, predictive).

        >>> Conventions(restitution_model="predictive").bounce_may_lose
        True
        """
        return self.restitution_model in ("soft", "predictive")

    def clip(self, velocity: tuple[float, ...], cap: float) -> tuple[float, ...]:
        """``velocity`` under the declared cap ``cap`` (a speed at the step in use): each
        coordinate clipped for a cap ``"per coordinate"``, else scaled down by its norm.

        >>> Conventions(max_speed=100.0, max_speed_at="per coordinate").clip((300.0, 50.0), 100.0)
        (100.0, 50.0)
        >>> Conventions(max_speed=5.0, max_speed_at="step").clip((3.0, 4.0), 2.5)
        (1.5, 2.0)
        """
        if self.max_speed_at == "per coordinate":
            return tuple(float(max(-cap, min(cap, x))) for x in velocity)
        speed = math.sqrt(math.fsum(x * x for x in velocity))
        return velocity if speed <= cap else tuple(x * (cap / speed) for x in velocity)

    def margin_for(self, feature: str) -> float:
        """The declared distance tolerance at ``feature`` (0 where none is declared).

        >>> Conventions(margins={"face": 0.002}).margin_for("face")
        0.002
        >>> Conventions(margins={"face": 0.002}).margin_for("sphere")
        0.0
        """
        return self.margins.get(feature, 0.0)

    def verdict_margin_for(self, feature: str) -> float:
        """The declared threshold of the verdict at ``feature``: ``verdict_margins`` where
        declared, else the length margin.

        >>> Conventions(margins={"face": 1e-7}, verdict_margins={}).verdict_margin_for("face")
        0.0
        >>> Conventions(margins={"face": 1e-7}).verdict_margin_for("face")
        1e-07
        """
        if self.verdict_margins is None:
            return self.margin_for(feature)
        return self.verdict_margins.get(feature, 0.0)

    def touching_is_contact(self, feature: str) -> bool:
        """Whether the engine counts exact touching at ``feature`` as contact.

        >>> Conventions(touching={"sphere": True}).touching_is_contact("sphere")
        True
        >>> Conventions().touching_is_contact("edge")
        True
        """
        return self.touching.get(feature, TEXTBOOK_TOUCHING[feature])

    def touching_rule(self) -> str:
        """The touching rule in words, for the conventions table.

        >>> Conventions(touching={"edge": False}).touching_rule()
        'contact when touching: sphere no, face yes, edge NO, corner yes'
        """
        words = []
        for feature, textbook in TEXTBOOK_TOUCHING.items():
            rule = self.touching_is_contact(feature)
            word = "yes" if rule else "no"
            words.append(f"{feature} {word if rule == textbook else word.upper()}")
        return "contact when touching: " + ", ".join(words)


NATURES: dict[str, tuple[Nature, str]] = {
    f.name: (f.metadata["nature"], f.metadata["why"]) for f in fields(Conventions)
    if "nature" in f.metadata}
"""Every convention's nature and the reason for it, by field name (``notes`` and ``sources``
are not conventions)."""


def nature_of(name: str) -> Nature:
    """The nature of the convention ``name`` (a field of :class:`Conventions`)."""
    return NATURES[name][0]


def why(name: str) -> str:
    """Why the convention ``name`` is a definition or a behaviour."""
    return NATURES[name][1]
