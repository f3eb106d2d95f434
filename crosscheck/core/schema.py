"""The case schema: pydantic models for ``[[case]]`` blocks, and their JSON Schema.

The models check structure and types (strict numbers: a string "1.0" or a
boolean is not a number).  The rules that a bad-input case may break on
purpose (finite numbers, sizes >= 0, masses > 0) are checked afterwards by
:mod:`crosscheck.cases.load`, so they can be waived for cases tagged ``bad-input``.

>>> case = SphereCase(id="s", description="d", kind="sphere", dim=2,
...                   a={"center": [0, 0], "radius": 0.5}, b={"center": [1, 0], "radius": 0.5})
>>> case.b.center
(1.0, 0.0)
"""

from __future__ import annotations

import json
from typing import Annotated, Any, Literal, get_args

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Discriminator,
    Field,
    Strict,
    Tag,
    TypeAdapter,
    model_validator,
)
from pydantic.json_schema import SkipJsonSchema

from crosscheck.core.kinds import spec
from crosscheck.core.model import Kind
from crosscheck.core.scenegen import generated_bodies

BAD_INPUT_TAG = "bad-input"
LOADER_FIELDS = ("source", "origin", "coords", "twin_of", "from_3d")
"""Fields the loader sets on every case; a case file may not set them."""
TWIN_SUFFIX = ".2d"
"""A block's 2-D twin (``twin_2d``) is the block ``<id>.2d``."""
ID_PATTERN = r"^[a-z0-9][a-z0-9._,=+\-]*$"
"""Ids: lowercase letters, digits, '-', '.', '_'; sweeps add '=', ',' and '+' to expanded ids."""

Num = Annotated[float, Strict()]
"""A TOML integer or float (nan and inf parse, and are rejected later unless bad-input)."""
Vector = tuple[Num, ...]
Plane = Literal["xy", "xz", "yz"]
"""A coordinate plane of 3-D space: where a 3-D case's 2-D twin lives."""


class _Frozen(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class AabbBody(_Frozen):
    """An axis-aligned box: centre and half-widths, as in the textbook."""

    center: Vector
    half: Vector = Field(description="Half-widths per axis (not full extents).")


class SphereBody(_Frozen):
    """A sphere (a disc in 2-D): centre and radius."""

    center: Vector
    radius: Num


class MovingSphere(SphereBody):
    """A sphere with mass and velocity, for response cases."""

    mass: Num
    velocity: Vector


class SweptSphere(SphereBody):
    """A sphere in linear motion, for time-of-impact cases: centre at the start, velocity."""

    velocity: Vector


class Tolerance(_Frozen):
    """Absolute tolerances overriding the harness defaults for this case."""

    distance: Num | None = None
    normal: Num | None = Field(None, description="Angle in radians.")
    velocity: Num | None = None
    toi: Num | None = Field(None, description="Time of impact, in seconds.")


class Expect(_Frozen):
    """An author's pinned expectation; it must agree with the exact oracle."""

    hit: Annotated[bool, Strict()] | None = None
    distance: Num | None = None


class LogSpace(_Frozen):
    """``{ logspace = [lo, hi, n] }``: n values 10**lo ... 10**hi, evenly spaced in exponent."""

    logspace: tuple[Num, Num, Annotated[int, Strict(), Field(ge=1, le=10_000)]]


class LinSpace(_Frozen):
    """``{ linspace = [lo, hi, n] }``: n evenly spaced values from lo to hi."""

    linspace: tuple[Num, Num, Annotated[int, Strict(), Field(ge=1, le=10_000)]]


def _values_tag(value: Any) -> str | None:
    if isinstance(value, dict):
        return next((key for key in ("logspace", "linspace") if key in value), None)
    if isinstance(value, LogSpace | LinSpace):
        return "logspace" if isinstance(value, LogSpace) else "linspace"
    return "list"


Values = Annotated[
    Annotated[list[Num], Field(min_length=1), Tag("list")]
    | Annotated[LogSpace, Tag("logspace")]
    | Annotated[LinSpace, Tag("linspace")],
    Discriminator(_values_tag, custom_error_type="sweep_values",
                  custom_error_message="expected a list of numbers, "
                                       "{ logspace = [lo, hi, n] } or { linspace = [lo, hi, n] }"),
]
"""A sweep parameter's values: a list, or a log- or linearly spaced range."""


class Sweep(_Frozen):
    """Parameters a case is expanded over (cartesian product, in this field order).

    The transformations apply in the order scale, gap/overlap, offset,
    mass_ratio, speed, to the case's own bodies.
    """

    scale: Values | None = Field(None, description="Multiply every centre and size.")
    gap: Values | None = Field(None, description=(
        "Move B along `direction` so the gap is this fraction of the touching distance."))
    overlap: Values | None = Field(None, description="As gap, but overlapping.")
    offset: Values | None = Field(None, description="Add to every centre coordinate of both.")
    mass_ratio: Values | None = Field(None, description="B's mass = A's mass x ratio.")
    speed: Values | None = Field(None, description="Multiply both velocities.")
    step_travel: Values | None = Field(None, description=(
        "Scenes of two bodies: per-step travel, the closing speed x dt over the overlap "
        "window 2 (ra + rb); sets the speeds for each dt."))
    phase: Values | None = Field(None, description=(
        "Scenes of two bodies: where in its step the impact falls (0 < phase < 1), "
        "after `approach_steps` whole steps."))
    direction: Vector | None = Field(None, description=(
        "Direction of gap/overlap (default: from A's centre to B's); an axis for boxes."))


def _whole_number(value: Any) -> Any:
    """Reject 3.0, "3" and true for a dimension (lax Literal matching would take them)."""
    if type(value) is not int:
        raise ValueError(f"expected the integer 2 or 3, got {value!r}")
    return value


class _CaseBase(_Frozen):
    id: str = Field(pattern=ID_PATTERN, description="Unique across the suite.")
    description: str = Field(min_length=1, description="Short; says what the case probes.")
    dim: Annotated[Literal[2, 3], BeforeValidator(_whole_number)]
    tags: tuple[str, ...] = ()
    tolerance: Tolerance | None = None
    swap: Annotated[bool, Strict()] = Field(True, description=(
        "Also run the case with A and B swapped (its results must mirror these)."))
    sweep: Sweep | None = None
    twin_2d: Plane | None = Field(None, description=(
        "3-D cases: also run the case in 2-D in this coordinate plane (the third axis "
        "dropped), as `<id>.2d`; the exact answer must not change."))
    source: SkipJsonSchema[str] = Field("", exclude=True)
    origin: SkipJsonSchema[str] = ""
    """Set by the loader: the id of the block this case was expanded from ('' for a plain block)."""
    coords: SkipJsonSchema[dict[str, float]] = Field(default_factory=dict)
    """Set by the loader: the sweep (or scene step) coordinates of this case, by parameter."""
    twin_of: SkipJsonSchema[str] = ""
    """Set by the loader: for an A/B-swapped twin, the id of the case it mirrors."""
    from_3d: SkipJsonSchema[str] = ""
    """Set by the loader: for a 2-D twin (``twin_2d``), the id of the 3-D case it flattens."""

    @property
    def kind_enum(self) -> Kind:
        return Kind(getattr(self, "kind"))  # noqa: B009

    @property
    def bad_input(self) -> bool:
        return BAD_INPUT_TAG in self.tags


class AabbCase(_CaseBase):
    """Do two axis-aligned boxes overlap (touching counts)?"""

    kind: Literal["aabb"]
    a: AabbBody
    b: AabbBody
    expect: Expect | None = None


class SphereCase(_CaseBase):
    """Do two spheres collide (touching does not count)?"""

    kind: Literal["sphere"]
    a: SphereBody
    b: SphereBody
    expect: Expect | None = None


class ResponseCase(_CaseBase):
    """Velocities after an elastic (or restituted) sphere-sphere collision."""

    kind: Literal["sphere_response"]
    a: MovingSphere
    b: MovingSphere
    restitution: Num = 1.0


class ToiCase(_CaseBase):
    """When do two spheres in linear motion first touch in ``[0, duration]`` (touching counts)?"""

    kind: Literal["sphere_toi"]
    a: SweptSphere
    b: SweptSphere
    duration: Num = Field(description="The interval's length in seconds: the query covers "
                                      "[0, duration].")


class Steps(_Frozen):
    """How engines step a scene: one run per time step x solver iteration count."""

    dt: Values = Field(description="Time steps in seconds (a list, logspace or linspace).")
    iterations: Annotated[list[Annotated[int, Strict(), Field(ge=1)]],
                          Field(min_length=1)] | None = Field(None, description=(
        "Solver iterations (pybullet numSolverIterations, pymunk Space.iterations); "
        "absent: each engine's default."))


class SceneGenerator(_Frozen):
    """Bodies made by a seeded generator of :mod:`reference_impl.events` instead of listed."""

    name: Literal["cluster", "cradle", "billiards"]
    n: Annotated[int, Strict(), Field(ge=2, le=1000)] | None = None
    seed: Annotated[int, Strict(), Field(ge=0)] | None = None
    radius: Num | None = Field(None, description="Ball radius (cradle); mean radius (cluster).")
    speed: Num | None = None
    extent: Num | None = Field(None, description="Half-width of the cluster's box.")
    offset: Num | None = Field(None, description="Billiards: the cue ball's sideways offset.")


class WallSpec(_Frozen):
    """A static wall of a scene: solid where ``normal . x < offset``; ``normal`` is a unit
    axis vector pointing into the free side (a ground at y = 0 in 2-D: normal [0, 1])."""

    normal: Vector
    offset: Num = 0.0


class SceneCase(_CaseBase):
    """N spheres stepped for ``duration``, in open space or under gravity between static walls,
    against an exact event-driven run."""

    kind: Literal["sphere_scene"]
    bodies: tuple[MovingSphere, ...] = ()
    generator: SceneGenerator | None = None
    restitution: Num = 1.0
    duration: Num | None = Field(None, description=(
        "Simulated seconds; engines step round(duration / dt).  Required, unless the block "
        "sweeps `step_travel` or `phase`: then each case runs twice its time to impact."))
    steps: Steps | None = None
    dt: Num | None = Field(None, description="Set by expanding `steps`: one time step.")
    iterations: Annotated[int, Strict(), Field(ge=1)] | None = None
    swap: Annotated[bool, Strict()] = Field(False, description="Scenes are never swapped.")
    approach_steps: Annotated[int, Strict(), Field(ge=1, le=1000)] = Field(4, description=(
        "Swept over `step_travel` or `phase`: whole steps before the first impact."))
    gravity: Vector | None = Field(None, description=(
        "Uniform gravity (m/s^2, one component per dimension); absent: none."))
    walls: tuple[WallSpec, ...] = Field((), description=(
        "Static axis-aligned walls (a ground, or a box's walls); every contact with one "
        "bounces with the scene's restitution."))
    diverge_at: Num = Field(0.01, description=(
        "The `divergence` measure's tolerance: the distance, in mean radii, a centre may be "
        "from the exact one before the trajectory counts as having left it."))

    @model_validator(mode="before")
    @classmethod
    def _generate(cls, data: Any) -> Any:
        if isinstance(data, dict) and data.get("generator") and not data.get("bodies"):
            data = {**data, "bodies": generated_bodies(data["generator"], data.get("dim"))}
        return data

    @property
    def step_count(self) -> int:
        """Steps an engine takes: ``round(duration / dt)`` (at least 1)."""
        return max(1, round((self.duration or 0.0) / (self.dt or DEFAULT_DT)))


DEFAULT_DT = 1.0 / 240.0
"""Time step of a scene case with no ``steps`` (PyBullet's default)."""

PairCase = AabbCase | SphereCase | ResponseCase
"""A two-body case at one instant (every kind but scenes and times of impact)."""
TwoBodyCase = AabbCase | SphereCase | ResponseCase | ToiCase
"""A case of two bodies A and B (every kind but scenes): swept, swapped and flattened alike."""

Case = Annotated[AabbCase | SphereCase | ResponseCase | SceneCase | ToiCase,
                 Field(discriminator="kind")]
"""One validated case of any kind."""

AnyCase = AabbCase | SphereCase | ResponseCase | SceneCase | ToiCase
CASE_ADAPTER: TypeAdapter[AnyCase] = TypeAdapter(Case)


def case_class(kind: Kind | str) -> type[AnyCase]:
    """The schema class of ``kind``: the one its spec names (:attr:`KindSpec.case
    <crosscheck.core.kinds.KindSpec.case>`).

    >>> case_class("sphere_toi").__name__
    'ToiCase'
    """
    name = spec(kind).case
    found: type[AnyCase] = next(c for c in get_args(AnyCase) if c.__name__ == name)
    return found


class CoverBlock(_Frozen):
    """A ``[[cover]]`` block: a covering design over a kind's configuration space.

    It expands to ordinary cases (``<id>.<dimension>=<level>,...``) such that every pair of
    levels of every two of its dimensions is in at least one case (strength 2), and with
    ``strength = 3`` every triple of levels of its ``strong`` dimensions too.  The
    dimensions and levels are those of :mod:`crosscheck.cases.space` (docs/coverage.md).
    """

    id: str = Field(pattern=ID_PATTERN, description="Unique across the suite; the prefix "
                                                      "of every generated case's id.")
    description: str = Field(min_length=1, description="What the design covers.")
    kind: Literal["aabb", "sphere", "sphere_response", "sphere_toi"]
    dim: Annotated[Literal[2, 3], BeforeValidator(_whole_number)]
    strength: Literal[2, 3] = Field(2, description=(
        "2: every pair of levels of every two dimensions; 3: also every triple of the "
        "`strong` dimensions."))
    dimensions: tuple[str, ...] | None = Field(None, description=(
        "The dimensions varied (default: all of the kind's); the others stay at their "
        "default level."))
    levels: dict[str, tuple[str, ...]] | None = Field(None, description=(
        "Levels to use instead of all of a dimension's (by dimension name)."))
    strong: tuple[str, ...] | None = Field(None, description=(
        "With strength 3: the dimensions covered three at a time (default: direction, gap, "
        "size_ratio, those the kind has)."))
    seed: Annotated[int, Strict(), Field(ge=0)] = Field(0, description=(
        "Seeds the design's choices: the same block always gives the same cases."))
    tags: tuple[str, ...] = ()
    swap: Annotated[bool, Strict()] = Field(True, description=(
        "Also run every generated case with A and B swapped."))


class CaseFile(_Frozen):
    """A case file: ``[[case]]`` blocks and ``[[cover]]`` blocks, at least one of them."""

    case: list[Case] = Field(default_factory=list)
    cover: list[CoverBlock] = Field(default_factory=list)


def json_schema() -> dict[str, Any]:
    """The JSON Schema of a case file, for editors (Taplo, VS Code Even Better TOML)."""
    schema = CaseFile.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "Collision Crosscheck case file"
    return schema


def json_schema_text() -> str:
    """The schema as the exact text stored in ``cases/schema.json``."""
    return json.dumps(json_schema(), indent=2, sort_keys=True) + "\n"
