"""The robot program check of ``cellstress check``: per move of each robot's program its largest joint travel,
the tool's top speed and the cycle time, and two failures an integrator would never program.

* **The long way round.** A joint that turns more than 180 deg on a move fails when whole turns of the
  program's waypoints, within the joint's limits, would keep its longest move shorter
  (``robot.turns.least_largest_move``). For two waypoints that is: the target +- 360 deg is within the limits.
  A program cycles, so its moves of one joint add up to nothing, and a cycle through three stations around
  the base has to turn back the long way once (120 + 120 - 240 deg): that move is needed, and passes. A joint
  whose range leaves no other way (a Panda joint of +-166 deg) may turn further too: it is the only way there.
  Joints tied to a ``<mimic>`` joint are left alone (a whole turn would not give the same pose).
* **Through a solid.** A moving link passes through the robot's own pedestal, the table, an obstacle, a fence
  or the floor when its capsule's axis goes more than 10 mm into it (``analysis.program_sweep``, which says
  how the capsules are sampled so that no such pass is missed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cellstress.analysis.program_sweep import (
    DEPTH,
    PassThrough,
    passes_through,
    point_speed_bounds,
    sample_spacing,
)
from cellstress.robot.ik import frame_index
from cellstress.robot.model import REVOLUTE, RobotModel, load_pinocchio
from cellstress.robot.trajectory import evaluate
from cellstress.robot.turns import EPS, least_largest_move, turns_freely
from cellstress.sim.build import Layout, RobotPart

SPEED_DT = 0.02  # s of path time between the tool speed's samples along a move
MIN_SPEED_SAMPLES = 64  # per minimum-jerk move
MAX_SPEED_ROWS = 20_000  # a trajectory file's rows whose tool speed is taken, at most (time)
MAX_LISTED = 12  # failure lines listed per robot; the rest are counted
HALF_TURN = math.pi


@dataclass(frozen=True)
class MoveCheck:
    """One move of a program: from waypoint ``index`` to the next (the last one back to the first)."""

    index: int  # 0-based
    start: float  # path time [s] the move begins (after its waypoint's dwell)
    duration: float  # s
    joint: str  # the revolute joint turning most ('' if none turns)
    turn_deg: float  # its travel [deg]
    slide_joint: str  # the prismatic joint sliding most ('' if none slides)
    slide_m: float  # its travel [m]
    tool_speed: float  # m/s, the tool frame's top speed along the move (NaN: not taken, ``speed_stride``)
    long_way: tuple[tuple[str, float, float], ...]  # (joint, travel deg, least largest travel deg): each a FAIL


@dataclass(frozen=True)
class ProgramCheck:
    """The program check of one robot."""

    robot: str  # '' in a cell of one robot
    tool: str  # the frame whose speed is reported
    kind: str  # 'pose', 'waypoint' or 'row' (a trajectory file's rows)
    cycle: float  # s
    moves: tuple[MoveCheck, ...]
    passes: tuple[PassThrough, ...]
    speed_bound: float  # m/s, the largest bound on capsule axis point speed
    spacing: float  # m of capsule travel between samples, and between points along an axis (DEPTH, or more)
    speed_stride: int = 1  # a trajectory file's tool speed taken every this many rows (the others NaN)

    @property
    def ok(self) -> bool:
        return not self.passes and not any(m.long_way for m in self.moves)

    def failures(self) -> list[str]:
        """'program' (or 'program:ROBOT') when this robot's program fails, as ``StaticCheck.failures``."""
        return [] if self.ok else ["program" + (f":{self.robot}" if self.robot else "")]

    def lines(self) -> list[str]:
        return program_lines(self)


# ---- joint travel ------------------------------------------------------------------------------------------
def long_way_round(robot: RobotModel, waypoints: np.ndarray) -> list[tuple[int, str, float, float]]:
    """(move, joint, its travel there [deg], the least largest travel of that joint [deg]) for each joint that
    turns more than half a turn on some move when whole turns of the waypoints, within its limits, would keep
    its largest move shorter (``robot.turns.least_largest_move``); the move named is the joint's longest."""
    out: list[tuple[int, str, float, float]] = []
    moves = np.roll(waypoints, -1, axis=0) - waypoints
    for j in range(robot.n_joints):
        if not turns_freely(robot, j):
            continue
        travel = np.abs(moves[:, j])
        i = int(np.argmax(travel))
        if travel[i] <= HALF_TURN + EPS:
            continue
        least = least_largest_move(waypoints[:, j], float(robot.lower[j]), float(robot.upper[j]))
        if travel[i] > least + 1e-6:
            out.append((i, robot.joint_names[j], float(np.rad2deg(travel[i])), float(np.rad2deg(least))))
    return out


def travels(robot: RobotModel, waypoints: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per move (waypoint i to the next, the last back to the first): the revolute joint turning most and its
    travel [deg], the prismatic joint sliding most and its travel [m] (joint -1 and 0 where none moves)."""
    d = np.abs(np.roll(waypoints, -1, axis=0) - waypoints)
    rev = np.array([k == REVOLUTE for k in robot.kinds])
    turn = np.where(rev[None, :], d, -1.0)
    slide = np.where(~rev[None, :], d, -1.0)
    j_rev, j_pri = np.argmax(turn, axis=1), np.argmax(slide, axis=1)
    deg = np.rad2deg(np.maximum(turn.max(axis=1), 0.0))
    metres = np.maximum(slide.max(axis=1), 0.0)
    return np.where(deg > 0.0, j_rev, -1), deg, np.where(metres > 0.0, j_pri, -1), metres


# ---- tool speed --------------------------------------------------------------------------------------------
def tool_frame(part: RobotPart) -> str:
    """The frame whose speed is reported: the program's ``tool_frame``, else the last link (in URDF order) that
    the program's last driven joint carries (a held gripper's fingers are not the tool)."""
    if part.spec.task.tool_frame:
        return part.spec.task.tool_frame
    last = part.joints.driven[-1]
    links = [name for name, j in part.model.link_joint.items() if j == last]
    return links[-1] if links else list(part.model.link_joint)[-1]


def tool_speeds(part: RobotPart, frame: str, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """The tool frame's speed [m/s] at joint positions q and speeds qd (rows), by pinocchio's kinematics."""
    import pinocchio as pin  # heavy: only ``check`` gets here

    robot = part.model
    model = load_pinocchio(robot.urdf)
    data = model.createData()
    fid = frame_index(pin, model, frame)
    out = np.empty(len(q))
    for k in range(len(q)):
        pin.forwardKinematics(model, data, robot.pinocchio_q(q[k]), qd[k])
        out[k] = float(np.linalg.norm(pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED).linear))
    return out


def move_speeds(part: RobotPart, frame: str) -> tuple[np.ndarray, int]:
    """(the tool's top speed on each move [m/s], every how many rows of a trajectory file it was taken).

    A minimum-jerk move is sampled at least every SPEED_DT of path time (at least MIN_SPEED_SAMPLES times),
    joint positions and speeds from ``robot.trajectory.evaluate`` (the kernel's Python reference). A trajectory
    file's move runs at constant joint speed, taken at the row's middle, every row up to MAX_SPEED_ROWS rows and
    evenly spaced rows beyond (the others NaN)."""
    traj = part.trajectory
    if traj.linear:
        stride = max(1, math.ceil(traj.n_segments / MAX_SPEED_ROWS))
        rows = np.arange(0, traj.n_segments, stride)
        a, b = traj.waypoints[rows], traj.waypoints[(rows + 1) % traj.n_segments]
        out = np.full(traj.n_segments, np.nan)
        out[rows] = tool_speeds(part, frame, 0.5 * (a + b), (b - a) / traj.move_times[rows, None])
        return out, stride
    out = np.zeros(traj.n_segments)
    for i in range(traj.n_segments):
        begin, dur = traj.starts[i] + traj.dwells[i], traj.move_times[i]
        n = max(MIN_SPEED_SAMPLES, math.ceil(dur / SPEED_DT))
        q, qd = zip(*(evaluate(traj, float(t)) for t in begin + (np.arange(n) + 0.5) / n * dur), strict=True)
        out[i] = float(np.max(tool_speeds(part, frame, np.asarray(q), np.asarray(qd))))
    return out, 1


# ---- the check ---------------------------------------------------------------------------------------------
def check_program(layout: Layout, r: int) -> ProgramCheck:
    part = layout.robots[r]
    traj, robot, task = part.trajectory, part.model, part.spec.task
    frame = tool_frame(part)
    speeds, stride = move_speeds(part, frame)
    long_way = long_way_round(robot, traj.waypoints)
    j_rev, deg, j_pri, metres = travels(robot, traj.waypoints)
    name_of = ("", *robot.joint_names)  # index j + 1: joint -1 is none
    moves = tuple(MoveCheck(i, float(traj.starts[i] + traj.dwells[i]), float(traj.move_times[i]),
                            name_of[j_rev[i] + 1], float(deg[i]), name_of[j_pri[i] + 1], float(metres[i]),
                            float(speeds[i]), tuple((j, d, least) for k, j, d, least in long_way if k == i))
                  for i in range(traj.n_segments))
    bounds = point_speed_bounds(part)
    step = sample_spacing(part, bounds)
    kind = "row" if traj.linear else ("pose" if task.poses else "waypoint")
    name = part.name if len(layout.robots) > 1 else ""
    return ProgramCheck(name, frame, kind, traj.cycle, moves, passes_through(layout, r, bounds, step),
                        float(bounds.max()), step, stride)


def check_programs(layout: Layout) -> tuple[ProgramCheck, ...]:
    """The program check of every robot of the cell, robot 0 first."""
    return tuple(check_program(layout, r) for r in range(len(layout.robots)))


# ---- the lines ``check`` prints ----------------------------------------------------------------------------
def _move_name(p: ProgramCheck, i: int) -> str:
    n = len(p.moves)
    if p.kind == "row":
        return f"rows {i + 2}-{i + 3}"
    return f"move {i + 1} ({p.kind} {i + 1} -> {(i + 1) % n + 1})"


def program_lines(p: ProgramCheck) -> list[str]:
    whose = f"robot {p.robot}: " if p.robot else ""
    out = [f"{whose}{len(p.moves)} moves, cycle {p.cycle:.2f} s, tool {p.tool}; links tested against pedestals, "
           f"tables, obstacles, fences and the floor at least every {p.spacing * 1000:.0f} mm of capsule travel "
           f"(capsule points at most {p.speed_bound:.2f} m/s)"]
    if p.kind == "row":
        worst = max(p.moves, key=lambda m: m.turn_deg)
        fast = max((m for m in p.moves if not math.isnan(m.tool_speed)), key=lambda m: m.tool_speed)
        every = f"; taken every {p.speed_stride} rows" if p.speed_stride > 1 else ""
        out.append(f"  {len(p.moves)} linear moves between the file's rows: largest joint travel "
                   f"{worst.joint or '-'} {worst.turn_deg:.1f} deg ({_move_name(p, worst.index)}), tool top speed "
                   f"{fast.tool_speed:.2f} m/s ({_move_name(p, fast.index)}{every})")
    else:
        for m in p.moves:
            slide = f", {m.slide_joint} {m.slide_m:.3f} m" if m.slide_joint else ""
            out.append(f"  {_move_name(p, m.index)}: {m.duration:.2f} s from {m.start:.2f} s of the cycle, "
                       f"largest joint travel {m.joint or '-'} {m.turn_deg:.1f} deg{slide}, tool top speed "
                       f"{m.tool_speed:.2f} m/s")
    fails = [f"  FAIL {_move_name(p, m.index)}: {j} turns {deg:.1f} deg the long way round; whole turns of the "
             f"waypoints within its limits keep its every move within {least:.1f} deg" for m in p.moves
             for j, deg, least in m.long_way]
    for x in p.passes:
        if x.solid.startswith("fence "):
            gap = DEPTH - x.depth
            what = "passes through" if gap < 5e-4 else f"comes within {gap * 1000:.0f} mm of"
        else:
            what = f"passes {x.depth:.3f} m {'below' if x.solid == 'the floor' else 'into'}"
        fails.append(f"  FAIL {_move_name(p, x.move)}: link {x.link} {what} {x.solid} at {x.t:.2f} s of the cycle")
    out += fails[:MAX_LISTED]
    if len(fails) > MAX_LISTED:
        out.append(f"  ... and {len(fails) - MAX_LISTED} more FAIL lines")
    if p.ok:
        out.append("  ok: no move turns a joint the long way round, no link passes through a solid")
    return out
