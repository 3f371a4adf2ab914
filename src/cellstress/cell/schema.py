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

from cellstress.cell.arrival import MAX_CYCLE, ArrivalField, ArrivalWindow  # noqa: F401  (part of the schema)
from cellstress.cell.obstacles import BoxFootprint, ObstacleSpec  # noqa: F401  (part of the schema)
from cellstress.cell.stopping import StoppingSpec
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
from cellstress.core.records import MAX_DOORS, DoorLeaf
from cellstress.human.anthropometry import BODY_SIZES

DEFAULT_CRITERION = "contact-while-moving"

MAX_JOINTS = 32
MAX_WAYPOINTS = 256
MAX_PANELS = 1024  # fence panels in a cell: the simulator checks the near ones at every step
MAX_COUNT = 32  # devices, start points, table polygons
MAX_CAPSULES = 64
MAX_ROBOTS = 4  # robots in a cell: each adds its joints, capsules and stop latch to every step

# A robot's name: it lands in HTML, CSV and terminal output (escaped there) and in device ``stops`` lists, never
# in a path, so an identifier.
RobotName = Annotated[str, Field(min_length=1, max_length=32, pattern=r"^[A-Za-z_][A-Za-z0-9_]*$")]

JointAngle = Annotated[float, Field(ge=-3600.0, le=3600.0, allow_inf_nan=False)]  # then the URDF's limits


class Pose(Record):
    """Where the robot's base frame is in the cell."""

    xyz: Point3 = (0.0, 0.0, 0.0)
    """Position of the base frame's origin [m]."""
    yaw_deg: Angle = 0.0
    """Rotation about the vertical axis [deg], counter-clockwise seen from above."""


class CapsuleSpec(Record):
    """A capsule fixed to a robot link, in that link's frame."""

    link: Name
    """The URDF link the capsule moves with."""
    p0: Point3
    """One end of the capsule's axis, in the link's frame [m]."""
    p1: Point3
    """The other end [m]."""
    radius: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)]
    """Radius [m]."""


class ToolPose(Record):
    """A Cartesian waypoint: where the robot's tool frame should be, in the cell's frame (solved by inverse
    kinematics when the cell is loaded)."""

    xyz: Point3
    """Position of the tool frame's origin in the cell [m]."""
    rpy_deg: tuple[Angle, Angle, Angle]
    """Orientation of the tool frame in the cell [deg]: roll, pitch, yaw about the cell's fixed x, y, z axes
    (the URDF convention). (0, 180, 0) points a tool's z axis straight down."""


class HeldJoint(Record):
    """A joint the program does not move, held at one value: e.g. a gripper's fingers at a set opening."""

    joint: Name
    """The URDF joint's name."""
    value: JointAngle
    """Its value: degrees for a revolute joint, metres for a prismatic one; within its limits."""


SpeedScale = Annotated[float, Field(ge=0.01, le=1.0, allow_inf_nan=False)]
Dwell = Annotated[float, Field(ge=0.0, le=60.0, allow_inf_nan=False)]
PROGRAMS = ("waypoints_deg", "poses", "trajectory_csv")


class TaskSpec(Record):
    """The robot's cyclic program, in one of three forms: joint waypoints (``waypoints_deg``), tool poses
    (``poses``, solved by inverse kinematics), each visited in order by minimum-jerk moves and then back to the
    first; or a joint-trajectory file (``trajectory_csv``) played at its own timing."""

    waypoints_deg: tuple[Annotated[tuple[JointAngle, ...], Field(max_length=MAX_JOINTS)], ...] = \
        Field((), max_length=MAX_WAYPOINTS)
    """Joint values of each waypoint (at least 2), one per joint the program drives (the URDF's joints
    without its ``<mimic>`` joints and ``robot.hold``'s), in URDF order: degrees for revolute joints, metres
    for prismatic ones; within the joints' limits."""
    poses: tuple[ToolPose, ...] = Field((), max_length=MAX_WAYPOINTS)
    """Tool poses to visit (at least 2), instead of ``waypoints_deg``: each is solved by inverse kinematics
    within the joint limits, the solution whose move from the previous waypoint takes least time (the first
    pose's from ``ik_seed_deg``), each joint by the whole turn nearest the previous value, and no joint turning
    further over the cycle than needed (docs/programs.md); a pose it cannot reach within 1 mm and 1 deg is an
    error."""
    tool_frame: Name | None = None
    """The URDF link or frame that ``poses`` place (e.g. panda_hand, tool0); required with ``poses``."""
    ik_seed_deg: Annotated[tuple[JointAngle, ...], Field(max_length=MAX_JOINTS)] | None = None
    """The program's start configuration (the robot's home), a value per driven joint as in
    ``waypoints_deg``: the first pose's solution is the one nearest it. Absent: the middle of each joint's range
    (for a UR, the arm stretched out level: give the home you would jog from)."""
    trajectory_csv: Annotated[str, Field(min_length=1, max_length=1000, pattern=r"^[^\x00]+$")] | None = None
    """A joint-trajectory file (as controllers and offline-programming tools export), instead of waypoints:
    CSV with a header ``time`` then one column per driven joint (``q1, q2, ...`` or the joint names, in URDF
    order), a row per sample; times [s] strictly increasing; joint values in radians (metres for prismatic
    joints) unless ``csv_degrees``. The robot moves at constant speed between rows and its last row must
    repeat the first (the cycle restarts). Path relative to the cell file; at most 200,000 rows and 20 MB."""
    csv_degrees: bool = False
    """The trajectory file's revolute joint values are in degrees (not radians)."""
    dwell: Dwell = 0.2
    """Pause at each waypoint [s]."""
    dwells: tuple[Dwell, ...] | None = None
    """A pause per waypoint [s], instead of ``dwell``."""
    speed_scale: SpeedScale = 0.5
    """Fraction of the joints' velocity limits used between waypoints (minimum-jerk moves)."""
    speed_scales: tuple[SpeedScale, ...] | None = None
    """A ``speed_scale`` per move, instead of one for all: move i goes from waypoint i to the next (the last
    one back to the first), so as many values as waypoints."""
    phase: Annotated[float, Field(ge=0.0, le=3600.0, allow_inf_nan=False)] = 0.0
    """The robot's time in its cycle [s] when an episode starts: the moment at which the worker arrives."""

    @field_validator("waypoints_deg")
    @classmethod
    def _same_length(cls, v: tuple[tuple[float, ...], ...]) -> tuple[tuple[float, ...], ...]:
        lengths = {len(w) for w in v}
        if len(lengths) > 1:
            raise ValueError(f"all waypoints need the same number of joints, got lengths {sorted(lengths)}")
        for w in v:
            if not all(math.isfinite(x) for x in w):
                raise ValueError("waypoints must be finite numbers")
        return v

    @model_validator(mode="after")
    def _one_program(self) -> TaskSpec:
        given = [name for name in PROGRAMS if getattr(self, name)]
        if len(given) != 1:
            got = f"got {' and '.join(given)}" if given else "got none"
            raise ValueError(f"give exactly one program: waypoints_deg, poses or trajectory_csv ({got})")
        count = len(self.waypoints_deg) or len(self.poses)
        if given[0] != "trajectory_csv" and count < 2:
            raise ValueError(f"{given[0]} needs at least 2 waypoints, got {count}")
        if self.poses and self.tool_frame is None:
            raise ValueError("poses need tool_frame: the URDF link they place (e.g. tool0)")
        for name, needs in (("tool_frame", "poses"), ("ik_seed_deg", "poses"), ("csv_degrees", "trajectory_csv")):
            if getattr(self, name) not in (None, False) and not getattr(self, needs):
                raise ValueError(f"{name} is for a program of {needs}; this one has none")
        for name in ("speed_scales", "dwells"):
            values = getattr(self, name)
            if values is None:
                continue
            if given[0] == "trajectory_csv":
                raise ValueError(f"{name} is for waypoint programs; a trajectory file has its own timing")
            if len(values) != count:
                raise ValueError(f"{name} has {len(values)} value(s); give one per waypoint ({count})")
        return self


def _capsules_kind(v: object) -> str:
    return "capsules-auto" if isinstance(v, str) else "capsules-list"


# "auto" or a list of capsules; the discriminator keeps pydantic from reporting both union branches.
CapsulesField = Annotated[
    Annotated[Literal["auto"], Tag("capsules-auto")]
    | Annotated[tuple[CapsuleSpec, ...], Field(max_length=MAX_CAPSULES), Tag("capsules-list")],
    Discriminator(_capsules_kind),
]


class RobotSpec(Record):
    """The robot: a serial chain from a URDF, placed in the cell, with its collision capsules and its program."""

    name: RobotName = "robot"
    """The robot's name (letters, digits, ``_``; not starting with a digit): devices name the robots they stop
    by it (``stops``) and a hazard names the robot it touched. Unique among ``robots``."""

    urdf: Annotated[str, Field(min_length=1, max_length=1000, pattern=r"^[^\x00]+$")] = "ur10"
    """A robot of example-robot-data by its short name (ur3, ur5, ur10, ur3-gripper, ur5-gripper, panda,
    kinova, xarm7, z1, so100, so101) or the path of a URDF file, relative to the cell file: a chain or tree of
    revolute, continuous and prismatic joints (fixed and ``<mimic>`` joints too), with velocity limits, and a
    shape for every moving link that has a mass (docs/robot.md)."""
    base: Pose = Pose()
    """The base frame in the cell."""
    capsules: CapsulesField = "auto"
    """The collision capsules: auto (one per link, enclosing its collision shapes: meshes, boxes, cylinders,
    spheres, capsules; its visual shapes where it has none: docs/robot.md) or a list."""
    extra_capsules: tuple[CapsuleSpec, ...] = Field((), max_length=MAX_CAPSULES)
    """Capsules added to the robot's own, e.g. a gripper holding a part."""
    stopping_time: PositiveTime = 0.15
    """Time [s] from the stop signal to standstill, braking along the path (category 1, no delay; the paper's)."""
    stopping: StoppingSpec | None = None
    """How the robot stops, instead of ``stopping_time``: stop category, controller delay, braking time or the
    maker's stopping data (docs/robot.md, Stopping)."""
    pedestal: Literal["auto", "none"] = "auto"
    """auto: the robot's base (the shapes of the links that do not move, in plan, from the floor up to their top)
    is an obstacle the worker cannot walk or lean into; none: nothing below the base (a robot hung from above)."""
    hold: tuple[HeldJoint, ...] = Field((), max_length=MAX_JOINTS)
    """Joints the program does not drive, each held at a value (a gripper at a set opening)."""
    task: TaskSpec
    """The robot's cyclic program."""

    @field_validator("hold")
    @classmethod
    def _hold_once(cls, v: tuple[HeldJoint, ...]) -> tuple[HeldJoint, ...]:
        names = [h.joint for h in v]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"a joint is held once: {', '.join(dup)} appears more than once")
        return v


class TableSpec(Record):
    """The work table: the worker cannot walk into it, and bends over it."""

    height: Height = 0.85
    """Height of the table top [m]."""
    polygons: tuple[Polygon, ...] = Field(min_length=1, max_length=MAX_COUNT)
    """Outlines of the table top [m], each a simple polygon of at most 256 points."""


class FenceSpec(Record):
    """A run of fence panels along a polyline, from ``bottom`` to ``top`` above the floor."""

    points: tuple[Point2, ...] = Field(min_length=2, max_length=MAX_VERTICES)
    """The polyline on the floor [m]; each segment is a panel."""
    top: Height = 2.0
    """Height of the panels' top edge [m] (ISO 13857: below 1 m a fence is no barrier to reaching)."""
    bottom: Elevation = 0.0
    """Height of the panels' bottom edge [m] (a gap under a panel lets a hand through)."""

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
    """Left edge [m]."""
    xmax: Coordinate
    """Right edge [m]."""
    ymin: Coordinate
    """Lower (back) edge [m]."""
    ymax: Coordinate
    """Upper (front) edge [m]."""

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
WORKER_MODELS: tuple[str, ...] = registry.names("workers")
BODY_SIZE_NAMES: tuple[str, ...] = tuple(BODY_SIZES)
DeviceSpec = _tagged_union("devices")
CriterionSpec = _tagged_union("criteria", DEFAULT_CRITERION)


class Anthropometry(Record):
    """Body dimensions [m]; defaults are the paper's Table I. The ranges span adult workers from below the 5th
    percentile woman to above the 95th percentile man (stature about 1.52 to 1.87 m; docs/cells.md)."""

    height: Annotated[float, Field(ge=1.4, le=2.1, allow_inf_nan=False)] = 1.78
    """Stature [m]; the body's capsules scale with it (Winter's segment proportions)."""
    upper_arm: Annotated[float, Field(ge=0.2, le=0.45, allow_inf_nan=False)] = 0.30
    """Upper arm length [m]."""
    forearm: Annotated[float, Field(ge=0.18, le=0.40, allow_inf_nan=False)] = 0.31
    """Forearm length [m]."""
    hand: Annotated[float, Field(ge=0.12, le=0.25, allow_inf_nan=False)] = 0.18
    """Hand length [m]."""


class StartSpec(Record):
    """Where the worker stands when an episode starts."""

    xy: Point2
    """Position on the floor [m]: not inside the table, a fence or the robot's base."""
    heading_deg: Angle
    """Direction the worker faces [deg], counter-clockwise from +x."""


class NamedStart(StartSpec):
    name: Annotated[str, Field(min_length=1, max_length=100, pattern=r"^[A-Za-z0-9_.-]+$")]
    """The start point's name (letters, digits, ``. _ -``): an episode's actions begin with ``start:NAME``."""
    phase: Annotated[float, Field(ge=0.0, le=3600.0, allow_inf_nan=False)] | None = None
    """The robot's time in its cycle [s] when a worker from here arrives; absent: robot.task.phase."""


class HumanSpec(Record):
    """The worker: where they start, their body and how they move."""

    model: Literal[WORKER_MODELS] = "paper"  # type: ignore[valid-type]
    """How the worker is modelled (registry group ``workers``). paper: the paper's 30 actions, hanging arms and
    the reach volumes of the arms (Table III's worker); articulated: jointed arms that collide with fences, the
    table and obstacles, crouching, kneeling, tiptoe, stepping back and sideways (docs/worker.md)."""
    body: Literal[BODY_SIZE_NAMES] | None = None  # type: ignore[valid-type]
    """A body size from an anthropometric survey, 5th percentile woman to 95th percentile man (docs/worker.md):
    it sets ``anthropometry``, so give one or the other (read back, a cell has both, and they agree)."""
    start: StartSpec
    """The worker's start pose."""
    starts: tuple[NamedStart, ...] = Field((), max_length=MAX_COUNT)
    """Start points a search chooses from, one per episode (its first decision); empty: ``start`` only."""
    arrival: ArrivalField = "cycle"
    """When in the robot's cycle the worker arrives. cycle: at any time step of the cycle, and the search chooses
    it as an episode's first decision (with the start point); fixed: at robot.task.phase (or a start point's own
    phase), as in the paper; a window {start, end} [s]: at any time step in it."""
    anthropometry: Anthropometry = Anthropometry()
    """Body dimensions."""
    walking_speed: Annotated[float, Field(ge=0.1, le=3.0, allow_inf_nan=False)] = 1.6
    """Walking speed [m/s] (ISO 13855's approach speed)."""
    max_forward_flexion_deg: Annotated[float, Field(ge=0.0, le=90.0)] = 55.0
    """The largest forward bend of the trunk [deg]."""
    max_lateral_flexion_deg: Annotated[float, Field(ge=0.0, le=60.0)] = 35.0
    """The largest sideways bend of the trunk [deg]."""

    @model_validator(mode="before")
    @classmethod
    def _body_size(cls, data: Any) -> Any:
        if not isinstance(data, dict) or data.get("body") is None or data.get("body") not in BODY_SIZES:
            return data
        size = BODY_SIZES[data["body"]]
        dims = {"height": size.stature, "upper_arm": size.upper_arm, "forearm": size.forearm, "hand": size.hand}
        given = data.get("anthropometry")
        if given is not None:
            given = given.model_dump() if isinstance(given, Anthropometry) else given
            if given != dims:
                raise ValueError(f"give body ({data['body']}) or anthropometry, not both: the body size sets the "
                                 "anthropometry")
        return {**data, "anthropometry": dims}

    @field_validator("starts")
    @classmethod
    def _unique_start_names(cls, v: tuple[NamedStart, ...]) -> tuple[NamedStart, ...]:
        names = [s.name for s in v]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"start names must be unique: {', '.join(dup)} appears more than once")
        return v


class SimulationSpec(Record):
    """The simulation's clock and the length of an episode."""

    dt: Annotated[float, Field(ge=0.001, le=1.0, allow_inf_nan=False)] = 0.05
    """Time step [s]."""
    steps_per_action: Annotated[int, Field(ge=1, le=100)] = 4
    """Time steps per worker action (4 x 0.05 s = 0.2 s, the paper's)."""
    actions_per_episode: Annotated[int, Field(ge=1, le=100)] = 8
    """Actions per episode (the paper's 8)."""


class CellSpec(Record):
    """A robot cell: the robot and its program, the table, fences, floor, safety devices, the worker and the
    criterion that says what is unsafe."""

    name: Name
    """The cell's name, shown in outputs (printable, one line)."""
    description: Annotated[str, Field(max_length=10_000)] = ""
    """Free text; its first sentence is shown by ``cellstress cells`` and ``check``."""
    robot: RobotSpec | None = None
    """The robot (a cell has ``robot`` or ``robots``, not both): the same as ``robots`` with one entry."""
    robots: tuple[RobotSpec, ...] = Field((), max_length=MAX_ROBOTS)
    """Several robots, each with its own program and stopping time, names unique (at most 4). Read back, it
    always holds every robot of the cell (``robot`` alone: that one), and ``robot`` is its first."""
    table: TableSpec | None = None
    """The work table (an obstacle of one height; absent: no table)."""
    obstacles: tuple[ObstacleSpec, ...] = Field((), max_length=MAX_COUNT)
    """Static obstacles besides the table, names unique."""
    fences: tuple[FenceSpec, ...] = Field((), max_length=MAX_PANELS)
    """Fences, each a polyline of panels (at most 1,024 panels in all)."""
    floor: FloorSpec
    """The walkable floor."""
    devices: tuple[DeviceSpec, ...] = Field((), max_length=MAX_COUNT)
    """Safety devices, each tagged by its ``type`` (the kinds installed: see below); names unique."""
    human: HumanSpec
    """The worker."""
    criterion: CriterionSpec = Field(default_factory=lambda: registry.load("criteria", DEFAULT_CRITERION)())
    """What is unsafe, tagged by its ``type``; absent: contact-while-moving (the paper's)."""
    simulation: SimulationSpec = SimulationSpec()
    """Time step and episode length."""

    @model_validator(mode="after")
    def _robot_or_robots(self) -> CellSpec:
        if (self.robot is None) == (not self.robots):
            raise ValueError("give exactly one of robot (one robot) and robots (a list of robots)"
                             + (", not both" if self.robots else ""))
        # (the two names always agree afterwards: every reader may take spec.robots, or spec.robot for the first)
        if self.robot is None:
            object.__setattr__(self, "robot", self.robots[0])
        else:
            object.__setattr__(self, "robots", (self.robot,))
        return self

    @field_validator("devices")
    @classmethod
    def _unique_device_names(cls, v: tuple[DeviceSpec, ...]) -> tuple[DeviceSpec, ...]:
        first: dict[str, int] = {}
        for i, d in enumerate(v):
            if d.name in first:
                raise ValueError(f"device names must be unique: devices[{first[d.name]}] and devices[{i}] "
                                 f"are both named {d.name!r}")
            first[d.name] = i
        doors = [i for i, d in enumerate(v) if any(isinstance(p, DoorLeaf) for p in d.primitives())]
        if len(doors) > MAX_DOORS:
            raise ValueError(f"{len(doors)} guard doors (devices{doors}); the simulator takes at most {MAX_DOORS}")
        return v

    @field_validator("obstacles")
    @classmethod
    def _unique_obstacle_names(cls, v: tuple[ObstacleSpec, ...]) -> tuple[ObstacleSpec, ...]:
        first: dict[str, int] = {}
        for i, o in enumerate(v):
            if o.name in first:
                raise ValueError(f"obstacle names must be unique: obstacles[{first[o.name]}] and obstacles[{i}] "
                                 f"are both named {o.name!r}")
            first[o.name] = i
        return v

    @model_validator(mode="after")
    def _obstacle_names_free(self) -> CellSpec:
        if self.table is not None:
            taken = {"table", *(f"table-{i + 1}" for i in range(1, len(self.table.polygons)))}
            for i, o in enumerate(self.obstacles):
                if o.name in taken:
                    raise ValueError(f"obstacles[{i}] is named {o.name!r}, the name of the table's polygon")
        return self

    def solid_obstacles(self) -> tuple[ObstacleSpec, ...]:
        """The table's polygons (named ``table``, ``table-2``, ...) and then ``obstacles``, as one list."""
        table = () if self.table is None else tuple(
            ObstacleSpec(name="table" if i == 0 else f"table-{i + 1}", polygon=p, height=self.table.height)
            for i, p in enumerate(self.table.polygons))
        return table + self.obstacles

    @field_validator("fences")
    @classmethod
    def _panel_count(cls, v: tuple[FenceSpec, ...]) -> tuple[FenceSpec, ...]:
        panels = sum(len(f.points) - 1 for f in v)
        if panels > MAX_PANELS:
            raise ValueError(f"the fences have {panels} straight panels; at most {MAX_PANELS}")
        return v
