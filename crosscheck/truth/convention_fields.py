"""The declared conventions behind a ``convention`` row, from its case and whether it has a value.

A row keeps the category of its disagreement and a reason built from the rule that fired,
not the name of the declared convention (the field of
:class:`~crosscheck.core.conventions.Conventions`) that rule read.  Each module of rules
names the conventions its rules read to give ``convention``
(:data:`~crosscheck.truth.categories.DETECTION_CONVENTIONS`,
:data:`~crosscheck.truth.categories.RESPONSE_CONVENTIONS`,
:data:`crosscheck.truth.toi.CONVENTIONS`, :data:`crosscheck.truth.scene_rules.CONVENTIONS`);
:func:`behind` narrows them to those that can have fired on one row:

- an answer with no value is judged by the ``no_value`` rule before any other (pairs; a time
  of impact's also by the rules of the verdict that left it without one);
- a response's rules that read the case alone are tried first, in their order
  (:data:`~crosscheck.truth.response_rules.CASE_RULES`): the first that fires on the case
  is the one; when none does, the speed cap or the contact model spoke;
- of what is left, those the engine declares otherwise than the textbook.

What the row rests on, a definition or a behaviour (:func:`nature`), follows: every kind's
candidates are all of one nature, except a response's, which the case's own inputs settle.

>>> from crosscheck.testing.samples import sphere_pair
>>> behind(sphere_pair(0.0, 1.0), Conventions(touching={"sphere": True}), no_value=False)
('touching',)
>>> nature(sphere_pair(0.0, 1.0), Conventions(touching={"sphere": True}), no_value=False)
<Nature.DEFINITION: 'definition'>
"""

from __future__ import annotations

from dataclasses import fields

from crosscheck.core.conventions import Conventions, Nature, nature_of
from crosscheck.core.schema import AnyCase, ResponseCase, SceneCase, ToiCase
from crosscheck.truth import contact_model, response_rules, scene_rules, toi
from crosscheck.truth.categories import DETECTION_CONVENTIONS

_TEXTBOOK = Conventions()
_DEFAULTS = {f.name: getattr(_TEXTBOOK, f.name) for f in fields(Conventions)}


def _candidates(case: AnyCase, conv: Conventions, no_value: bool) -> tuple[str, ...]:
    """The conventions whose rule can have made a row of ``case`` a ``convention``."""
    if isinstance(case, SceneCase):
        return scene_rules.CONVENTIONS
    if isinstance(case, ToiCase):  # a row with no value: its no-value rule, or the verdict's
        return tuple(name for name in toi.CONVENTIONS if no_value or name != "no_value")
    if no_value:
        return ("no_value",)
    if isinstance(case, ResponseCase):
        fired = response_rules.case_rule(case, conv)
        return (fired,) if fired else ("max_speed", *contact_model.CONVENTIONS)
    return tuple(name for name in DETECTION_CONVENTIONS if name != "no_value")


def behind(case: AnyCase, conv: Conventions, no_value: bool) -> tuple[str, ...]:
    """The declared conventions a ``convention`` row of ``case`` rests on (see the module
    docstring); ``no_value``: the engine's answer has no finite value."""
    candidates = _candidates(case, conv, no_value)
    declared = tuple(name for name in candidates if getattr(conv, name) != _DEFAULTS[name])
    return declared or candidates


def nature(case: AnyCase, conv: Conventions, no_value: bool) -> Nature:
    """A definition when every convention the row rests on is one, else a behaviour."""
    natures = {nature_of(name) for name in behind(case, conv, no_value)}
    return Nature.DEFINITION if natures == {Nature.DEFINITION} else Nature.BEHAVIOUR
