"""The cell file schema: typed, frozen records validated by pydantic.

Lengths are metres, angles degrees, times seconds. The frame is right-handed with z up; the built-in cells
put the robot base near the origin, the upper (front) end of the cell at +y and the lower (back) end at -y.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    Tag,
    field_validator,
    model_validator,
)

Finite = Annotated[float, Field(allow_inf_nan=False)]
Point2 = tuple[Finite, Finite]
Point3 = tuple[Finite, Finite, Finite]
PositiveTime = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]
Length = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]


class _Record(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


def _segments_cross(a: Point2, b: Point2, c: Point2, d: Point2) -> bool:
    """True when segments ab and cd properly intersect (touching at shared endpoints is not a crossing)."""

    def orient(p: Point2, q: Point2, r: Point2) -> float:
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    return (o1 * o2 < 0) and (o3 * o4 < 0)


def check_simple_polygon(points: tuple[Point2, ...]) -> tuple[Point2, ...]:
    if len(points) < 3:
        raise ValueError(f"a polygon needs at least 3 points, got {len(points)}")
    n = len(points)
    # crossings first: a symmetric bow-tie has zero signed area, and "intersects itself" is the real problem
    for i in range(n):
        for j in range(i + 1, n):
            if j in (i, (i + 1) % n) or i == (j + 1) % n:
                continue
            if _segments_cross(points[i], points[(i + 1) % n], points[j], points[(j + 1) % n]):
                raise ValueError(f"the polygon intersects itself (edge {i} from point {i} crosses edge {j} "
                                 f"from point {j})")
    area2 = sum(points[i][0] * points[(i + 1) % n][1] - points[(i + 1) % n][0] * points[i][1]
                for i in range(n))
    if abs(area2) < 1e-12:
        raise ValueError("the polygon has zero area")
    return points


# A simple polygon; validated per polygon so that errors name the polygon's index (table.polygons[1]).
Polygon = Annotated[tuple[Point2, ...], AfterValidator(check_simple_polygon)]


class Pose(_Record):
    xyz: Point3 = (0.0, 0.0, 0.0)
    yaw_deg: float = Field(0.0, allow_inf_nan=False)


class CapsuleSpec(_Record):
    """A capsule fixed to a robot link, in that link's frame."""

    link: str
    p0: Point3
    p1: Point3
    radius: Length


class TaskSpec(_Record):
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


class RobotSpec(_Record):
    urdf: str = "ur10"
    base: Pose = Pose()
    capsules: CapsulesField = "auto"
    extra_capsules: tuple[CapsuleSpec, ...] = ()
    stopping_time: PositiveTime = 0.15
    task: TaskSpec


class TableSpec(_Record):
    height: Length = 0.85
    polygons: tuple[Polygon, ...] = Field(min_length=1)


class FenceSpec(_Record):
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


class FloorSpec(_Record):
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


class LaserScannerSpec(_Record):
    type: Literal["laser-scanner"]
    name: str
    polygon: Polygon
    height: Annotated[float, Field(ge=0.0, le=1.0)] = 0.3
    response_time: PositiveTime = 0.35


class LightCurtainSpec(_Record):
    type: Literal["light-curtain"]
    name: str
    start: Point2
    end: Point2
    bottom: NonNegative = 0.2
    top: Length = 1.8
    response_time: PositiveTime = 0.05
    resolution_mm: Annotated[float, Field(gt=0.0, le=200.0)] = 30.0

    @model_validator(mode="after")
    def _shape(self) -> LightCurtainSpec:
        if self.start == self.end:
            raise ValueError("start and end are the same point")
        if self.top <= self.bottom:
            raise ValueError(f"top ({self.top}) must be above bottom ({self.bottom})")
        return self


DeviceSpec = Annotated[LaserScannerSpec | LightCurtainSpec, Field(discriminator="type")]


class Anthropometry(_Record):
    """Body dimensions; defaults are the paper's Table I."""

    height: Annotated[float, Field(gt=1.0, lt=2.5)] = 1.78
    upper_arm: Length = 0.30
    forearm: Length = 0.31
    hand: Length = 0.18


class StartSpec(_Record):
    xy: Point2
    heading_deg: float = Field(allow_inf_nan=False)


class NamedStart(StartSpec):
    name: Annotated[str, Field(min_length=1, pattern=r"^[A-Za-z0-9_.-]+$")]
    # the robot's path time [s] when a worker from this start point begins (the moment of the cycle at which
    # they arrive); None: the cell's robot.task.phase
    phase: NonNegative | None = None


class HumanSpec(_Record):
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


CRITERIA = ("contact-while-moving", "iso15066")


class CriterionSpec(_Record):
    """What is unsafe: ``contact-while-moving`` (the paper) or ``iso15066`` (force limits per body region;
    ``payload`` [kg] is added to the robot's reflected mass, see docs/criteria.md)."""

    type: Literal["contact-while-moving", "iso15066"] = "contact-while-moving"
    distance_tolerance: Annotated[float, Field(ge=0.0, le=0.1)] = 0.0
    speed_tolerance: Annotated[float, Field(ge=0.0, le=0.1)] = 0.001
    payload: Annotated[float, Field(ge=0.0, le=1000.0)] = 2.0


class SimulationSpec(_Record):
    dt: PositiveTime = 0.05
    steps_per_action: Annotated[int, Field(ge=1, le=100)] = 4
    actions_per_episode: Annotated[int, Field(ge=1, le=100)] = 8


class CellSpec(_Record):
    name: str
    description: str = ""
    robot: RobotSpec
    table: TableSpec
    fences: tuple[FenceSpec, ...] = ()
    floor: FloorSpec
    devices: tuple[DeviceSpec, ...] = ()
    human: HumanSpec
    criterion: CriterionSpec = CriterionSpec()
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
