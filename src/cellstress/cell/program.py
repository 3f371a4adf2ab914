"""The robot's program from a cell: joint waypoints, tool poses (inverse kinematics) or a joint-trajectory
file, checked against the URDF's joint position and velocity limits, as the Trajectory the kernel runs.

Every problem is a CellError naming the cell file and the field (for a trajectory file also its row and
column), so ``check`` and every command report it as one line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cellstress.cell.schema import MAX_CYCLE, RobotSpec
from cellstress.core.errors import CellError, CellstressError
from cellstress.robot.ik import Unreachable, solve_poses
from cellstress.robot.joint_file import JointFileError, read_joint_file
from cellstress.robot.joints import (
    JointMap,
    ancestors_or_self,
    branching,
    describe_limit,
    joint_map,
    limit_violation,
    user_value,
)
from cellstress.robot.model import REVOLUTE, RobotModel, base_matrix
from cellstress.robot.trajectory import Trajectory, build_trajectory, linear_trajectory

VELOCITY_SLACK = 1e-9  # relative: a trajectory file sampled exactly at a joint's speed limit is within it


def held_joints(src: str, robot: RobotModel, spec: RobotSpec) -> JointMap:
    """The joints ``robot.hold`` holds (each a joint of the chain, not a mimic one, within its limits) and so
    the ones the program drives."""
    index = {n: j for j, n in enumerate(robot.joint_names)}
    held: dict[int, float] = {}
    for i, h in enumerate(spec.hold):
        field = f"robot.hold[{i}]"
        if h.joint not in index:
            raise CellError(src, f"{field}.joint", f"the robot has no joint {h.joint!r}; its joints are "
                                                  f"{', '.join(robot.joint_names)}")
        j = index[h.joint]
        if robot.mimic_master[j] >= 0:
            master = robot.joint_names[robot.mimic_master[j]]
            raise CellError(src, f"{field}.joint", f"{h.joint!r} mimics {master!r}: hold {master!r} instead")
        value = float(np.deg2rad(h.value)) if robot.kinds[j] == REVOLUTE else float(h.value)
        if limit_violation(robot, _at(robot, j, value)) == j:
            raise CellError(src, f"{field}.value", describe_limit(robot, j, value))
        held[j] = value
    return joint_map(robot, held)


def _at(robot: RobotModel, j: int, value: float) -> np.ndarray:
    """A joint vector inside every limit but joint j's, which is ``value``."""
    lo, hi = robot.sampling_range()
    q = 0.5 * (lo + hi)
    q[j] = value
    return q


def driven_list(jmap: JointMap) -> str:
    """The driven joints with their units, for an error that says what a program must give."""
    return ", ".join(f"{n} [{jmap.robot.unit(j)}]" for j, n in zip(jmap.driven, jmap.driven_names, strict=True))


def _check_waypoints(src: str, field: str, jmap: JointMap, full: np.ndarray) -> None:
    """Every joint of every waypoint within its limits; the error points at the driven value responsible."""
    robot = jmap.robot
    for i, q in enumerate(full):
        j = limit_violation(robot, q)
        if j < 0:
            continue
        source = j if robot.mimic_master[j] < 0 else int(robot.mimic_master[j])
        where = f"{field}[{i}][{jmap.driven.index(source)}]" if source in jmap.driven else f"{field}[{i}]"
        extra = "" if source == j else f" (it mimics {robot.joint_names[source]!r})"
        raise CellError(src, where, describe_limit(robot, j, q[j]) + extra)


def _per_move(task, name: str, default: float, n: int) -> np.ndarray:
    values = getattr(task, name)
    return np.full(n, default) if values is None else np.asarray(values, dtype=float)


def waypoint_program(src: str, jmap: JointMap, spec: RobotSpec, directory: Path | None) -> Trajectory:
    """Minimum-jerk moves through ``waypoints_deg`` or through the joint solutions of ``poses``."""
    task, robot = spec.task, jmap.robot
    nd = len(jmap.driven)
    if task.poses:
        driven = _solve_poses(src, jmap, spec)
        field = "robot.task.poses"
    else:
        for i, w in enumerate(task.waypoints_deg):
            if len(w) != nd:
                raise CellError(src, f"robot.task.waypoints_deg[{i}]",
                                f"has {len(w)} joint values but the robot has {nd} joints the program drives: "
                                f"{driven_list(jmap)}")
        driven = jmap.from_user(np.asarray(task.waypoints_deg, dtype=float))
        field = "robot.task.waypoints_deg"
    full = jmap.expand(driven)
    _check_waypoints(src, field, jmap, full)
    n = len(full)
    return build_trajectory(full, _per_move(task, "dwells", task.dwell, n),
                            _per_move(task, "speed_scales", task.speed_scale, n), robot.velocity_limits)


def _solve_poses(src: str, jmap: JointMap, spec: RobotSpec) -> np.ndarray:
    task, robot = spec.task, jmap.robot
    driven = list(jmap.driven)
    _check_one_chain(src, jmap, task.tool_frame)
    if task.ik_seed_deg is not None:
        if len(task.ik_seed_deg) != len(driven):
            raise CellError(src, "robot.task.ik_seed_deg", f"has {len(task.ik_seed_deg)} values; the program "
                                                           f"drives {len(driven)} joints: {driven_list(jmap)}")
        seed = jmap.from_user(np.asarray(task.ik_seed_deg, dtype=float))
    else:
        lo, hi = robot.sampling_range()
        seed = 0.5 * (lo[driven] + hi[driven])
    to_base = np.linalg.inv(base_matrix(spec.base.xyz, spec.base.yaw_deg))
    targets = [to_base @ _pose_matrix(p.xyz, p.rpy_deg) for p in task.poses]
    try:
        return solve_poses(jmap, task.tool_frame, targets, seed)
    except Unreachable as exc:
        raise CellError(src, f"robot.task.poses[{exc.index}]",
                        f"cannot be reached within the joint limits: the closest solution is "
                        f"{exc.residual[0] * 1000:.1f} mm and {np.rad2deg(exc.residual[1]):.1f} deg away "
                        "(at most 1 mm and 1 deg)") from None
    except CellstressError as exc:
        raise CellError(src, "robot.task.tool_frame", str(exc)) from None


def _check_one_chain(src: str, jmap: JointMap, tool_frame: str) -> None:
    """Tool poses decide only the joints that carry the tool frame; on a tree robot (two arms on one torso) the
    other branches' joints would be left to the solver's start values, so such a program is refused."""
    robot = jmap.robot
    pair = branching(jmap)
    if pair is None or tool_frame not in robot.link_joint:
        return
    carriers = ancestors_or_self(robot, robot.link_joint[tool_frame])
    free = [robot.joint_names[j] for j in jmap.driven if j not in carriers]
    shown = ", ".join(free[:4]) + (", ..." if len(free) > 4 else "")
    raise CellError(src, "robot.task.poses", f"the robot branches (joints {robot.joint_names[pair[0]]!r} and "
                                             f"{robot.joint_names[pair[1]]!r} are on separate branches) and tool "
                                             f"poses of {tool_frame!r} decide only the joints that carry it, not "
                                             f"{len(free)} others ({shown}): hold those (robot.hold) or give joint "
                                             "waypoints or a trajectory file for every joint")


def _pose_matrix(xyz, rpy_deg) -> np.ndarray:
    """URDF rpy: R = Rz(yaw) Ry(pitch) Rx(roll), about fixed axes."""
    r, p, y = np.deg2rad(rpy_deg)
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3] = rz @ ry @ rx
    m[:3, 3] = xyz
    return m


def file_program(src: str, jmap: JointMap, spec: RobotSpec, directory: Path | None) -> Trajectory:
    """Linear moves through the rows of ``trajectory_csv``, each row within the position limits and each move
    within the velocity limits."""
    task, robot = spec.task, jmap.robot
    field = "robot.task.trajectory_csv"
    path = trajectory_path(task.trajectory_csv, directory)
    try:
        jf = read_joint_file(path, jmap.driven_names)
    except JointFileError as exc:
        raise CellError(src, field, f"{path}: {exc}") from None
    full = jmap.expand(jmap.from_user(jf.values, degrees=task.csv_degrees))
    header_of = {j: k + 2 for k, j in enumerate(jmap.driven)}  # the file's column of a driven joint
    for r, q in enumerate(full):
        j = limit_violation(robot, q)
        if j >= 0:
            raise CellError(src, field, f"{path}: row {r + 2}{_column(robot, header_of, j)}: "
                                        f"{describe_limit(robot, j, q[j])}")
    speed = np.abs(np.diff(full, axis=0)) / np.diff(jf.times)[:, None]
    over = speed > robot.velocity_limits * (1 + VELOCITY_SLACK)
    if over.any():
        r, j = (int(x) for x in np.argwhere(over)[0])
        v, vmax = (user_value(robot, j, x) for x in (speed[r, j], robot.velocity_limits[j]))
        per = "deg/s" if robot.kinds[j] == REVOLUTE else "m/s"
        raise CellError(src, field, f"{path}: rows {r + 2} to {r + 3}{_column(robot, header_of, j)}: joint "
                                    f"{robot.joint_names[j]!r} moves at {v:.4g} {per}, over its limit "
                                    f"{vmax:.4g} {per}")
    if np.abs(full[-1] - full[0]).max() > 1e-6:
        raise CellError(src, field, f"{path}: the last row must repeat the first row's joint values (the "
                                    "program cycles back to its start); add a row that returns there")
    return linear_trajectory(jf.times, full)


def _column(robot: RobotModel, header_of: dict[int, int], j: int) -> str:
    source = j if robot.mimic_master[j] < 0 else int(robot.mimic_master[j])
    return f", column {header_of[source]} ({robot.joint_names[source]})" if source in header_of else ""


def trajectory_path(ref: str, directory: Path | None) -> Path:
    """The file ``trajectory_csv`` names: relative paths from the cell file's folder."""
    path = Path(ref).expanduser()
    return directory / path if not path.is_absolute() and directory is not None else path


def robot_program(src: str, robot: RobotModel, spec: RobotSpec, directory: Path | None) -> Trajectory:
    """The robot's cyclic program as a Trajectory, every joint limit checked; CellError otherwise."""
    jmap = held_joints(src, robot, spec)
    if not jmap.driven:
        raise CellError(src, "robot.hold", "holds every joint: the program has nothing to move")
    make = file_program if spec.task.trajectory_csv else waypoint_program
    traj = make(src, jmap, spec, directory)
    if traj.cycle > MAX_CYCLE:
        raise CellError(src, "robot.task", f"the cycle takes {traj.cycle:.0f} s; at most {MAX_CYCLE:.0f} s "
                                           "(raise speed_scale, shorten dwell)")
    return traj
