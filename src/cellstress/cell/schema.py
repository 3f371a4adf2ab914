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
from cellstress.core.fields import (
    MAX_EXTENT,
    MAX_VERTICES,
    Angle,
    Coordinate,
    Elevation,
    Height,
    Name,
    Point2,
    Point3,
    Polygon,
    PositiveTime,
    Record,
)

DEFAULT_CRITERION = "contact-while-moving"

MAX_JOINTS = 32
MAX_WAYPOINTS = 256
MAX_PANELS = 1024  # fence panels in a cell: the simulator checks the near ones at every step
MAX_COUNT = 32  # devices, start points, table polygons
MAX_CAPSULES = 64
MAX_CYCLE = 600.0  # s, the robot's cycle (the static check samples it every 10 ms)

JointAngle = Annotated[float, Field(ge=-3600.0, le=3600.0, allow_inf_nan=False)]  # then the URDF's limits


class Pose(Record):
    xyz: Point3 = (0.0, 0.0, 0.0)
    yaw_deg: Angle = 0.0


class CapsuleSpec(Record):
    """A capsule fixed to a robot link, in that link's frame."""

    link: Name
    p0: Point3
    p1: Point3
    radius: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)]


class TaskSpec(Record):
    """A cyclic pick-and-place: joint waypoints visited in order, then back to the first."""

    waypoints_deg: tuple[Annotated[tuple[JointAngle, ...], Field(max_length=MAX_JOINTS)], ...] = \
        Field(min_length=2, max_length=MAX_WAYPOINTS)
    dwell: Annotated[float, Field(ge=0.0, le=60.0, allow_inf_nan=False)] = 0.2
    speed_scale: Annotated[float, Field(ge=0.01, le=1.0, allow_inf_nan=False)] = 0.5
    phase: Annotated[float, Field(ge=0.0, le=3600.0, allow_inf_nan=False)] = 0.0

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
    | Annotated[tuple[CapsuleSpec, ...], Field(max_length=MAX_CAPSULES), Tag("capsules-list")],
    Discriminator(_capsules_kind),
]


class RobotSpec(Record):
    urdf: Annotated[str, Field(min_length=1, max_length=1000, pattern=r"^[^\x00]+$")] = "ur10"
    base: Pose = Pose()
    capsules: CapsulesField = "auto"
    extra_capsules: tuple[CapsuleSpec, ...] = Field((), max_length=MAX_CAPSULES)
    stopping_time: PositiveTime = 0.15
    task: TaskSpec


class TableSpec(Record):
    height: Height = 0.85
    polygons: tuple[Polygon, ...] = Field(min_length=1, max_length=MAX_COUNT)


class FenceSpec(Record):
    """A run of fence panels along a polyline, from ``bottom`` to ``top`` above the floor."""

    points: tuple[Point2, ...] = Field(min_length=2, max_length=MAX_VERTICES)
    top: Height = 2.0
    bottom: Elevation = 0.0

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

    xmin: Coordinate
    xmax: Coordinate
    ymin: Coordinate
    ymax: Coordinate

    @model_validator(mode="after")
    def _ordered(self) -> FloorSpec:
        if not (self.xmin < self.xmax and self.ymin < self.ymax):
            raise ValueError("need xmin < xmax and ymin < ymax")
        if self.xmax - self.xmin > MAX_EXTENT or self.ymax - self.ymin > MAX_EXTENT:
            raise ValueError(f"the floor is at most {MAX_EXTENT:g} m on a side")
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
    """Body dimensions [m]; defaults are the paper's Table I. The ranges span adult workers from below the 5th
    percentile woman to above the 95th percentile man (stature about 1.52 to 1.87 m; docs/cells.md)."""

    height: Annotated[float, Field(ge=1.4, le=2.1, allow_inf_nan=False)] = 1.78
    upper_arm: Annotated[float, Field(ge=0.2, le=0.45, allow_inf_nan=False)] = 0.30
    forearm: Annotated[float, Field(ge=0.18, le=0.40, allow_inf_nan=False)] = 0.31
    hand: Annotated[float, Field(ge=0.12, le=0.25, allow_inf_nan=False)] = 0.18


class StartSpec(Record):
    xy: Point2
    heading_deg: Angle


class NamedStart(StartSpec):
    name: Annotated[str, Field(min_length=1, max_length=100, pattern=r"^[A-Za-z0-9_.-]+$")]
    # the robot's path time [s] when a worker from this start point begins (the moment of the cycle at which
    # they arrive); None: the cell's robot.task.phase
    phase: Annotated[float, Field(ge=0.0, le=3600.0, allow_inf_nan=False)] | None = None


class HumanSpec(Record):
    start: StartSpec
    # the start points a search chooses from, one per episode (its first decision); empty: ``start`` only
    starts: tuple[NamedStart, ...] = Field((), max_length=MAX_COUNT)
    anthropometry: Anthropometry = Anthropometry()
    walking_speed: Annotated[float, Field(ge=0.1, le=3.0, allow_inf_nan=False)] = 1.6
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
    dt: Annotated[float, Field(ge=0.001, le=1.0, allow_inf_nan=False)] = 0.05
    steps_per_action: Annotated[int, Field(ge=1, le=100)] = 4
    actions_per_episode: Annotated[int, Field(ge=1, le=100)] = 8


class CellSpec(Record):
    name: Name
    description: Annotated[str, Field(max_length=10_000)] = ""
    robot: RobotSpec
    table: TableSpec
    fences: tuple[FenceSpec, ...] = Field((), max_length=MAX_PANELS)
    floor: FloorSpec
    devices: tuple[DeviceSpec, ...] = Field((), max_length=MAX_COUNT)
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

    @field_validator("fences")
    @classmethod
    def _panel_count(cls, v: tuple[FenceSpec, ...]) -> tuple[FenceSpec, ...]:
        panels = sum(len(f.points) - 1 for f in v)
        if panels > MAX_PANELS:
            raise ValueError(f"the fences have {panels} straight panels; at most {MAX_PANELS}")
        return v
