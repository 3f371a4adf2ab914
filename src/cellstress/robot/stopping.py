"""How a robot stops, as the simulator models it: stop category (IEC 60204-1:2016, 9.2.2), controller delay,
braking, and the maker's stopping data read conservatively (docs/robot.md, Stopping).

**Along the path (categories 1 and 2).** After the stop signal reaches the robot (the device's detection plus
its response time) the robot keeps its path speed for a delay ``delay``, then slows linearly to a standstill
over ``braking``: it travels v (delay + braking / 2). From a published stopping distance S and time T at the
joint speed v the two times follow (``profile``): delay = 2 S / v - T, braking = 2 (T - S / v), matching both
when T / 2 <= S / v <= T. Outside that range no such profile matches both, and the conservative reading is
taken: S / v < T / 2 (the joint stopped faster than a linear ramp from the signal) gives braking = T with no
delay (v T / 2 > S: more distance, the same time); S / v > T (it travelled more than at full speed for the whole
time) gives full speed for T, then braking over 2 (S / v - T) (the distance S, later than T).

**Held where it was (category 0).** Power is removed and each joint's brake stops it on its own, so the arm
may leave its path. The simulator poses it where the stop took effect and grows every capsule by how far any of
its points can move while each joint turns (or slides) by at most its stopping distance (``travel``): the
capsule of the true arm lies inside the grown one at every moment (``hold_radii``).

**Conservative lookup.** Makers publish S and T per joint at a grid of speeds, payloads and extensions (33,
66 and 100 % of each). For the program's top speed of the joint and the cell's payload and extension, the next
published point at or above them on every axis is used (``joint_stops``), and S and T are the largest the file
gives at that point or below it: never below the published data, even where the data are not monotone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.robot.model import PRISMATIC, REVOLUTE, RobotModel
from cellstress.robot.stopping_file import StoppingRow
from cellstress.robot.trajectory import Trajectory

CATEGORIES = (0, 1, 2)
PEAK = 1.875  # a minimum-jerk move's peak speed over its mean speed (robot.trajectory)
MATCHED, FASTER, SLOWER = "matched", "faster", "slower"


class StoppingDataError(CellstressError):
    """Stopping data that do not fit the robot or its program: ``where`` names the file's row and column or
    the joint, ``problem`` says what is wrong."""

    def __init__(self, where: str, problem: str):
        self.where = where
        self.problem = problem
        super().__init__(f"{where}: {problem}" if where else problem)


@dataclass(frozen=True)
class Profile:
    """Full path speed for ``delay`` seconds after the stop signal, then a linear ramp to standstill over
    ``braking`` seconds; ``reading`` says how it follows from the data (MATCHED, FASTER or SLOWER)."""

    delay: float
    braking: float
    reading: str


def profile(distance: float, time: float, speed: float) -> Profile:
    """The braking profile of a joint that stops within ``distance`` (rad or m) and ``time`` (s) from ``speed``
    (rad/s or m/s), read conservatively (see the module docstring)."""
    s_over_v = distance / speed
    if s_over_v < 0.5 * time:
        return Profile(0.0, time, FASTER)
    if s_over_v > time:
        return Profile(time, 2.0 * (s_over_v - time), SLOWER)
    return Profile(max(0.0, 2.0 * s_over_v - time), max(0.0, 2.0 * (time - s_over_v)), MATCHED)


@dataclass(frozen=True)
class JointStop:
    """One joint's published stopping, as used: the point (speed %, payload kg, extension %) of the file's row
    ``row``, the program's top speed of the joint, the distance and time (the largest at that point or below),
    the point's speed and the profile that follows."""

    joint: str
    row: int
    point: tuple[float, float, float]
    program_speed_pct: float
    distance: float  # rad or m
    time: float  # s
    speed: float  # rad/s or m/s at the point
    profile: Profile
    angular: bool = True


@dataclass(frozen=True)
class RobotStop:
    """How one robot stops, resolved from its cell entry: what the kernel runs on and what ``check`` prints.

    ``delay`` and ``braking`` are the kernel's (layout STOP_DELAY, STOP_TIME): from the stop's signal reaching
    the robot to the start of braking, then to standstill. For category 0 (``hold``) the delay is 0 and
    ``braking`` the whole time to standstill (the pose is held from the signal on); ``travel`` is then how far
    each joint may turn or slide after the signal (rad or m, every joint of the URDF)."""

    category: int
    controller_delay: float  # s, as the cell gives it
    delay: float
    braking: float
    hold: bool = False
    travel: tuple[float, ...] = ()
    joints: tuple[JointStop, ...] = ()  # from the maker's stopping data (empty for a given stopping time)
    data: str | None = None  # the data file, as the cell names it

    def describe(self) -> str:
        """In words: the braking time alone for the paper's plain stop (category 1, no delay, no data), else the
        category, the delay, the braking and where the numbers come from."""
        if self.category == 1 and self.delay == 0.0 and not self.joints:
            return f"{self.braking:g} s"
        source = f"from {self.data}" if self.data else "given"
        if self.hold:
            return (f"category 0 ({source}): held where the stop takes effect, at rest {self.braking:.3g} s later, "
                    f"the capsules grown for the joints' own braking")
        delay = f"{self.delay:.3g} s at full speed ({self.controller_delay:.3g} s controller delay), then " \
            if self.delay > 0.0 else ""
        return (f"category {self.category} ({source}): {delay}braking {self.braking:.3g} s along the path, at rest "
                f"{self.to_standstill:.3g} s after the signal")

    @property
    def to_standstill(self) -> float:
        """Time from the stop signal reaching the robot to standstill [s]: ISO 13855's stopping time of the
        machine (T = device response + this)."""
        return self.delay + self.braking


def peak_joint_speeds(traj: Trajectory) -> np.ndarray:
    """Every joint's top speed over the program [rad/s or m/s]: a minimum-jerk move peaks at 15/8 of its mean
    speed, a linear one runs at its mean."""
    w = np.asarray(traj.waypoints, dtype=float)
    nxt = np.roll(w, -1, axis=0)
    mean = np.abs(nxt - w) / np.asarray(traj.move_times, dtype=float)[:, None]
    return (mean if traj.linear else PEAK * mean).max(axis=0)


def given_stop(category: int, controller_delay: float, stopping_time: float, robot: RobotModel,
               peaks: np.ndarray) -> RobotStop:
    """The stop of a robot given by a braking time: along the path after the delay (categories 1, 2); held, each
    joint travelling at most its top speed over the delay and the stopping time (category 0)."""
    if category != 0:
        return RobotStop(category, controller_delay, controller_delay, stopping_time)
    total = controller_delay + stopping_time
    return RobotStop(category, controller_delay, 0.0, total, True, tuple(float(x) for x in peaks * total))


def data_stop(category: int, controller_delay: float, joints: tuple[JointStop, ...], robot: RobotModel,
              peaks: np.ndarray, data: str) -> RobotStop:
    """The stop of a robot from its maker's data (``joint_stops``). Along the path: the longest delay and the
    longest braking of the joints (the path time then never runs behind any joint's own profile). Held: the
    longest time; each joint in the data travels its distance plus its top speed over the controller's delay,
    one not in the data its top speed over the whole time."""
    if category != 0:
        delay = max(j.profile.delay for j in joints)
        braking = max(j.profile.braking for j in joints)
        return RobotStop(category, controller_delay, controller_delay + delay, braking, joints=joints, data=data)
    total = controller_delay + max(j.time for j in joints)
    travel = peaks * total
    for j in joints:
        k = robot.joint_names.index(j.joint)
        travel[k] = j.distance + peaks[k] * controller_delay
    return RobotStop(category, controller_delay, 0.0, total, True, tuple(float(x) for x in travel), joints, data)


def joint_stops(rows: tuple[StoppingRow, ...], category: int, robot: RobotModel, peaks: np.ndarray,
                payload: float, extension: float) -> tuple[JointStop, ...]:
    """Each joint's stopping at the next published point at or above the program's speed, ``payload`` [kg] and
    ``extension`` [%], for the robot's stop category (a category 2 robot uses category 1 rows where the file has
    none of its own: both are controlled stops along the path). StoppingDataError otherwise."""
    index = {n: j for j, n in enumerate(robot.joint_names)}
    for r in rows:
        if r.joint not in index:  # (the file's text is never quoted: a cell may name any file)
            raise StoppingDataError(f"row {r.row}, column 1 (joint)", f"is not a joint of the robot; its joints are "
                                                                      f"{', '.join(robot.joint_names)}")
        kind = robot.kinds[index[r.joint]]
        if (kind == REVOLUTE) != r.angular:
            want = "deg or rad" if kind == REVOLUTE else "m or mm"
            raise StoppingDataError(f"row {r.row}, column 7 (unit)", f"joint {r.joint} is {kind}: its distance "
                                                                     f"is in {want}")
    use = [r for r in rows if r.category == category]
    if not use and category == 2:
        use = [r for r in rows if r.category == 1]
    if not use:
        have = sorted({r.category for r in rows})
        raise StoppingDataError("", f"has no rows for stop category {category} (it has category "
                                    f"{', '.join(map(str, have))})")
    out = []
    for name in robot.joint_names:
        mine = [r for r in use if r.joint == name]
        if mine:
            k = index[name]
            pct = 100.0 * float(peaks[k]) / float(robot.velocity_limits[k])
            out.append(_joint_stop(name, mine, pct, payload, extension, float(robot.velocity_limits[k]),
                                   robot.kinds[k] != PRISMATIC))
    return tuple(out)


AXES = ("speed", "payload", "extension")
UNITS = ("% of its top speed", "kg", "% extension")


def _joint_stop(name: str, rows: list[StoppingRow], pct: float, payload: float, extension: float, vmax: float,
                angular: bool) -> JointStop:
    ours = (pct, payload, extension)
    corner = []
    for a in range(3):
        levels = sorted({r.point[a] for r in rows})
        above = [x for x in levels if x >= ours[a] - 1e-9]
        if not above:
            what = f"the program moves it at {pct:.1f} % of its top speed" if a == 0 else \
                f"the cell's {AXES[a]} is {ours[a]:g} {UNITS[a]}"
            raise StoppingDataError(f"joint {name}", f"{what}; the file publishes it up to {levels[-1]:g} "
                                                     f"{UNITS[a]}, and data are never extrapolated")
        corner.append(above[0])
    at = [r for r in rows if r.point == tuple(corner)]
    if not at:
        raise StoppingDataError(f"joint {name}", f"no published point at speed {corner[0]:g} %, payload "
                                                 f"{corner[1]:g} kg, extension {corner[2]:g} % (the next at or "
                                                 "above the program's on every axis): give the whole grid")
    below = [r for r in rows if all(r.point[a] <= corner[a] + 1e-9 for a in range(3))]
    distance = max(r.distance for r in below)
    time = max(r.time for r in below)
    speed = corner[0] / 100.0 * vmax
    return JointStop(name, at[0].row, tuple(corner), pct, distance, time, speed, profile(distance, time, speed),
                     angular)


def hold_radii(robot: RobotModel, cap_joint: np.ndarray, cap_a: np.ndarray, cap_b: np.ndarray,
               travel: np.ndarray) -> np.ndarray:
    """How much to grow each capsule so that it holds the capsule of every pose whose joints are each within
    ``travel`` of the held pose: for a point carried by joints j, |p(q) - p(q0)| <= sum_j travel_j lever_j,
    lever_j bounding its distance from joint j's origin in every pose (the link lengths in between, each
    prismatic joint's largest slide, and the capsule's end; a revolute joint turning by a moves a point at
    distance r by at most a r, a prismatic one by its slide)."""
    link = np.linalg.norm(robot.placements[:, :3, 3], axis=1)
    slide = np.zeros(robot.n_joints)
    for j in range(robot.n_joints):
        if robot.kinds[j] == PRISMATIC:
            lo, hi = float(robot.lower[j]), float(robot.upper[j])
            slide[j] = max(abs(lo), abs(hi)) if np.isfinite(lo) and np.isfinite(hi) else 0.0
    out = np.zeros(len(cap_joint))
    for c in range(len(cap_joint)):
        j = int(cap_joint[c])
        lever = max(float(np.linalg.norm(cap_a[c])), float(np.linalg.norm(cap_b[c])))
        grow = 0.0
        while j >= 0:
            grow += float(travel[j]) * (1.0 if robot.kinds[j] == PRISMATIC else lever)
            lever += float(link[j]) + float(slide[j])
            j = int(robot.parents[j])
        out[c] = grow
    return out
