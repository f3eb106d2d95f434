"""The textbook formula's calls (the ``reference`` and ``reference-f32`` engines), plain data in
and out: ``reference_impl.formulas`` in the variant's precision, answers as a dict of
quantities (a ``str`` is a quantity with no defined value, and why).

Each case is one ask on its ``given`` inputs (nothing is built: the formula is the work).
A time of impact is the textbook's discrete sphere test at the interval's two ends, centres
``c + v t`` in float64, as a simulation stepping over the interval sees the pair.
"""

from typing import Any

from reference_impl import formulas
from reference_impl.types import Contact, Undefined

Answer = dict[str, Any]

CONTACT = ("hit", "distance", "normal")
RESPONSE = ("v1", "v2")
IMPACT = ("hit", "toi", "normal")


def given(**inputs: Any) -> dict[str, Any]:
    """The inputs as they are (the formula builds nothing before it is asked)."""
    return inputs


def _plain(value: Any) -> Any:
    """A value of the formulas as plain data: an Undefined is its reason."""
    return value.reason if isinstance(value, Undefined) else value


def _contact(found: Contact | Undefined) -> Answer:
    if isinstance(found, Undefined):
        return {q: found.reason for q in CONTACT}
    return {"hit": found.hit, "distance": found.distance, "normal": _plain(found.normal)}


def aabb(i: dict[str, Any]) -> Answer:
    """The textbook's box test (touching overlaps)."""
    return _contact(formulas.aabb_contact(i["a_center"], i["a_half"], i["b_center"],
                                          i["b_half"], precision=i["precision"]))


def sphere(i: dict[str, Any]) -> Answer:
    """The textbook's sphere test (touching is not a hit)."""
    return _contact(formulas.sphere_contact(i["a_center"], i["a_radius"], i["b_center"],
                                            i["b_radius"], precision=i["precision"]))


def response(i: dict[str, Any]) -> Answer:
    """The textbook's response, generalised with the restitution."""
    found = formulas.sphere_response(i["a_center"], i["a_mass"], i["a_velocity"],
                                     i["b_center"], i["b_mass"], i["b_velocity"],
                                     i["restitution"], precision=i["precision"])
    if isinstance(found, Undefined):
        return {q: found.reason for q in RESPONSE}
    return {"v1": tuple(float(x) for x in found.v1), "v2": tuple(float(x) for x in found.v2)}


def sampled_impact(i: dict[str, Any]) -> Answer:
    """The textbook's sphere test at t = 0 and at the interval's end only: the first sample
    with a contact, else no contact (a contact between the samples is not seen)."""
    for t in (0.0, i["duration"]):
        ca = tuple(c + v * t for c, v in zip(i["a_center"], i["a_velocity"], strict=True))
        cb = tuple(c + v * t for c, v in zip(i["b_center"], i["b_velocity"], strict=True))
        found = formulas.sphere_contact(ca, i["a_radius"], cb, i["b_radius"],
                                        precision=i["precision"])
        if isinstance(found, Undefined):
            return {q: found.reason for q in IMPACT}
        if found.hit:
            return {"hit": True, "toi": t, "normal": _plain(found.normal)}
    none = "no contact at either sample"
    return {"hit": False, "toi": none, "normal": none}
