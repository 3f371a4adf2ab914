"""The cell file schema: typed, frozen records validated by pydantic.

Lengths are metres, angles degrees, times seconds. The frame is right-handed with z up; the built-in cells
put the robot base near the origin, the upper (front) end of the cell at +y and the lower (back) end at -y.

The kinds of safety device and of criterion are plug-ins: their records come from the ``cellstress.devices``
and ``cellstress.criteria`` registries (``core.registry``), tagged by their ``type`` field, so a device kind
installed by another package is a valid ``devices`` entry without any change here.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Union

from pydantic import (
    Discriminator,
    Field,
    Tag,
    field_validator,
    model_validator,
)

from cellstress.core import registry
from cellstress.core.fields import Finite, Length, NonNegative, Point2, Point3, Polygon, PositiveTime, Record

DEFAULT_CRITERION = "contact-while-moving"

class Pose(Record):
    xyz: Point3 = (0.0, 0.0, 0.0)
    yaw_deg: float = Field(0.0, allow_inf_nan=False)


class CapsuleSpec(Record):
    """A capsule fixed to a robot link, in that link's frame."""

    link: str
    p0: Point3
    p1: Point3
    radius: Length


class TaskSpec(Record):
    """A cyclic pick-and-place: joint waypoints visited in order, then back to the first."""

    waypoints_deg: tuple[tuple[float, ...], ...] = Field(min_length=2)
    dwell: NonNegative = 0.2
    speed_scale: Annotated[float, Field(gt=0.0, le=1.0)] = 0.5
    phase: NonNegative = 0.0

    @field_validator("waypoints_deg")
    @classmethod
    def _same_length(cls, v: tuple[tuple[float, ...], ...]) -> tuple[tuple[float, ...], ...]:
        lengths = {len(w) for w in v}
        if len(lengths) != 1:
            raise ValueError(f"all waypoints need the same number of joints, got lengths {sorted(lengths)}")
        for w in v:
            if not all(math.isfinite(x) for x in w):
                raise ValueError("waypoints must be finite numbers")
        return v


def _capsules_kind(v: object) -> str:
    return "capsules-auto" if isinstance(v, str) else "capsules-list"


# "auto" or a list of capsules; the discriminator keeps pydantic from reporting both union branches.
CapsulesField = Annotated[
    Annotated[Literal["auto"], Tag("capsules-auto")]
    | Annotated[tuple[CapsuleSpec, ...], Tag("capsules-list")],
    Discriminator(_capsules_kind),
]


class RobotSpec(Record):
    urdf: str = "ur10"
    base: Pose = Pose()
    capsules: CapsulesField = "auto"
    extra_capsules: tuple[CapsuleSpec, ...] = ()
    stopping_time: PositiveTime = 0.15
    task: TaskSpec


class TableSpec(Record):
    height: Length = 0.85
    polygons: tuple[Polygon, ...] = Field(min_length=1)


class FenceSpec(Record):
    """A run of fence panels along a polyline, from ``bottom`` to ``top`` above the floor."""

    points: tuple[Point2, ...] = Field(min_length=2)
    top: Length = 2.0
    bottom: NonNegative = 0.0

    @model_validator(mode="after")
    def _heights(self) -> FenceSpec:
        if self.top <= self.bottom:
            raise ValueError(f"top ({self.top}) must be above bottom ({self.bottom})")
        for a, b in zip(self.points, self.points[1:], strict=False):
            if a == b:
                raise ValueError(f"two consecutive points are equal: {a}")
        return self


class FloorSpec(Record):
    """The walkable rectangle: the worker cannot leave it."""

    xmin: Finite
    xmax: Finite
    ymin: Finite
    ymax: Finite

    @model_validator(mode="after")
    def _ordered(self) -> FloorSpec:
        if not (self.xmin < self.xmax and self.ymin < self.ymax):
            raise ValueError("need xmin < xmax and ymin < ymax")
        return self


def _tag(value: Any, default: str | None = None) -> str | None:
    """The ``type`` tag of a record or of its mapping in a file (``default`` when a mapping has none)."""
    if isinstance(value, dict):
        return value.get("type", default)
    return getattr(value, "type", default)


def _tagged_union(group: str, default: str | None = None):
    """The records of a registry group as one union, told apart by their ``type`` tag."""
    kinds = registry.load_all(group)
    if len(kinds) == 1:
        return next(iter(kinds.values()))
    members = tuple(Annotated[cls, Tag(name)] for name, cls in kinds.items())
    return Annotated[Union[members], Discriminator(lambda v: _tag(v, default))]  # noqa: UP007 (a built tuple)


DEVICE_KINDS: tuple[str, ...] = registry.names("devices")
CRITERIA: tuple[str, ...] = registry.names("criteria")
DeviceSpec = _tagged_union("devices")
CriterionSpec = _tagged_union("criteria", DEFAULT_CRITERION)


class Anthropometry(Record):
    """Body dimensions; defaults are the paper's Table I."""

    height: Annotated[float, Field(gt=1.0, lt=2.5)] = 1.78
    upper_arm: Length = 0.30
    forearm: Length = 0.31
    hand: Length = 0.18


class StartSpec(Record):
    xy: Point2
    heading_deg: float = Field(allow_inf_nan=False)


class NamedStart(StartSpec):
    name: Annotated[str, Field(min_length=1, pattern=r"^[A-Za-z0-9_.-]+$")]
    # the robot's path time [s] when a worker from this start point begins (the moment of the cycle at which
    # they arrive); None: the cell's robot.task.phase
    phase: NonNegative | None = None


class HumanSpec(Record):
    start: StartSpec
    # the start points a search chooses from, one per episode (its first decision); empty: ``start`` only
    starts: tuple[NamedStart, ...] = ()
    anthropometry: Anthropometry = Anthropometry()
    walking_speed: Length = 1.6
    max_forward_flexion_deg: Annotated[float, Field(ge=0.0, le=90.0)] = 55.0
    max_lateral_flexion_deg: Annotated[float, Field(ge=0.0, le=60.0)] = 35.0

    @field_validator("starts")
    @classmethod
    def _unique_start_names(cls, v: tuple[NamedStart, ...]) -> tuple[NamedStart, ...]:
        names = [s.name for s in v]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"start names must be unique: {', '.join(dup)} appears more than once")
        return v


class SimulationSpec(Record):
    dt: PositiveTime = 0.05
    steps_per_action: Annotated[int, Field(ge=1, le=100)] = 4
    actions_per_episode: Annotated[int, Field(ge=1, le=100)] = 8


class CellSpec(Record):
    name: str
    description: str = ""
    robot: RobotSpec
    table: TableSpec
    fences: tuple[FenceSpec, ...] = ()
    floor: FloorSpec
    devices: tuple[DeviceSpec, ...] = ()
    human: HumanSpec
    criterion: CriterionSpec = Field(default_factory=lambda: registry.load("criteria", DEFAULT_CRITERION)())
    simulation: SimulationSpec = SimulationSpec()

    @field_validator("devices")
    @classmethod
    def _unique_device_names(cls, v: tuple[DeviceSpec, ...]) -> tuple[DeviceSpec, ...]:
        first: dict[str, int] = {}
        for i, d in enumerate(v):
            if d.name in first:
                raise ValueError(f"device names must be unique: devices[{first[d.name]}] and devices[{i}] "
                                 f"are both named {d.name!r}")
            first[d.name] = i
        return v
