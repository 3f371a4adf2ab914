"""Small typed, immutable records that cross layers: what a reward sees, what a criterion judges, what a
device gives the kernel, and what an ISO 13855 distance is.

They hold numbers and names only (no arrays that change, no behaviour), so they pickle, compare and print.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

Point2 = tuple[float, float]
Point3 = tuple[float, float, float]


class Measures(NamedTuple):
    """What a reward sees at the end of one action (a NamedTuple: it is made after every simulated action)."""

    d_hr: float  # human-robot distance [m]; 0 when the robot is within the worker's reach
    v_r: float  # Cartesian speed of the robot's fastest joint [m/s]
    # the criterion's severity of a contact at the closest points now (iso15066: predicted force / transient
    # limit, as if they touched); None for criteria that judge by distance and speed alone
    severity: float | None = None
    # distinct mode: the unsafe state repeats a hazard class already found (a reward may pay it as a safe end)
    repeat: bool = False


class WorkerPaths(NamedTuple):
    """The worker's open-loop motion for many action sequences (``ResumableWorker.worker_paths_from``): pose
    vectors at every time step, (episodes, steps, pose size), NaN before the step a sequence resumed at; and the
    worker's state as each action begins and as the last ends, (episodes, actions + 1, state size), which a later
    call resumes from."""

    poses: Any
    states: Any


class KernelTest(NamedTuple):
    """A criterion's fast path: unsafe exactly when d_HR <= distance_tolerance and v_R > speed_tolerance,
    evaluated inside the compiled simulation loop."""

    distance_tolerance: float
    speed_tolerance: float


@dataclass(frozen=True)
class Contact:
    """The simulator's account of the closest point pair between worker and robot at one time step, for
    criteria that judge contacts themselves (``Criterion.judge``).

    Points are in the cell frame [m]; ``normal`` is the unit vector from the robot point towards the human
    point; ``v_rel`` [m/s] is the robot point's speed along it (towards the human, never below 0);
    ``reflected_mass`` [kg] is the robot's inertia felt at that point along the normal (inf when its joints
    cannot move the point that way), without any payload.
    """

    d_hr: float
    v_r: float
    robot_link: str
    body_part: str
    region: str  # ISO/TS 15066 body region of the human point (``human.regions``)
    robot_point: Point3
    human_point: Point3
    normal: Point3
    v_rel: float
    reflected_mass: float


# ---- detection primitives: what a safety device gives the compiled kernel ------------------------------------
@dataclass(frozen=True)
class ScanPlane:
    """A horizontal detection plane at ``height`` [m] inside a polygon (a laser scanner's field, a mat's
    area): it sees a body capsule that crosses the plane inside the polygon."""

    polygon: tuple[Point2, ...]
    height: float


@dataclass(frozen=True)
class VerticalField:
    """A vertical detection rectangle over the floor segment ``start``-``end`` from ``bottom`` to ``top`` [m]
    (a light curtain, a door's opening): it sees a body capsule that touches the rectangle."""

    start: Point2
    end: Point2
    bottom: float
    top: float


MAX_DOORS = 4  # guard doors per cell: the simulator's state has two slots for each (sim.layout.STATE)


@dataclass(frozen=True)
class DoorLeaf:
    """An interlocked guard door's leaf over the floor segment ``start``-``end`` from ``bottom`` to ``top`` [m]:
    it blocks walking, the trunk and the arms like a fence panel until it is passable. The worker opens it by
    walking into it; its interlock signals from that moment. It starts to open then (with ``guard_locking``:
    once the robot is at rest) and is passable ``opening_time`` [s] later."""

    start: Point2
    end: Point2
    bottom: float
    top: float
    opening_time: float
    guard_locking: bool


Primitive = ScanPlane | VerticalField | DoorLeaf


@dataclass(frozen=True)
class TimedPanel:
    """A panel over the floor segment ``start``-``end`` from ``bottom`` to ``top`` [m] that blocks like a fence
    panel only while the cell's clock, (phase + t) modulo the robot's cycle, lies in [``t_in``, ``t_out``] [s]:
    a pallet filling a conveyor opening as it passes."""

    start: Point2
    end: Point2
    bottom: float
    top: float
    t_in: float
    t_out: float


@dataclass(frozen=True)
class Channel:
    """One detection primitive of a device and what its detection does (what the kernel senses): ``speed`` 0
    stops the robot, a fraction in (0, 1) cuts it to that fraction of its path speed (a warning field);
    ``response_time`` [s] until it takes effect; ``clear_time`` [s] without detection until it is released
    (inf: never, a manual restart). ``name`` is shown where the channel sees the worker."""

    primitive: Primitive
    name: str
    speed: float
    response_time: float
    clear_time: float
    # muted (sees nothing) while the cell's clock, (phase + t) modulo the robot's cycle, lies in [on, off] [s]
    muted: tuple[float, float] | None = None
    # speed and separation monitoring: the channel measures the worker's separation from the robot and commands
    # a speed fraction from it (``speed`` is then ignored), as ``SeparationRule`` says
    separation: SeparationRule | None = None


@dataclass(frozen=True)
class SeparationRule:
    """How a speed and separation monitoring channel turns a measured separation S [m] into a speed fraction:
    the largest s in [0, 1] with v_h (T_r + T_s) + s v_max (T_r + T_s / 2) + allowance <= S (ISO/TS 15066:2016,
    5.5.4, with the times the controller was configured with)."""

    human_speed: float  # v_h [m/s]
    max_speed: float  # v_max [m/s]
    reaction_time: float  # configured T_r [s]
    stopping_time: float  # configured T_s [s]
    allowance: float  # C + Z_d + Z_r [m]


@dataclass(frozen=True)
class IsoDistance:
    """One ISO 13855 minimum distance S = K T + C: K [mm/s], T [s], C and S [mm], and the arithmetic as text."""

    K: float
    T: float
    C: float
    S: float
    formula: str
