"""Tool poses to joint waypoints: inverse kinematics with pinocchio, within the joint limits, each waypoint the
solution an integrator would choose after the one before.

Damped least squares on the pose error log6(oMf^-1 oMdes) (pinocchio's own formulation), over the driven joints
only (mimic joints follow through the JointMap), each step clipped to the joint limits. Every pose is solved
from several seeds: the previous waypoint's solution (for a redundant arm with a pull in the null space of the
pose, its free motion, back towards it) and a fixed set of deterministic restarts. Each solution found is
turned, joint by joint, by whole turns to the value nearest the previous waypoint that the joint's range
allows (``nearest_turn``: a joint of +-360 deg reaches an angle as theta or theta +- 360 deg, a continuous
joint as any of them). Of the solutions, the one whose move from the previous waypoint takes least time is
kept: the smallest largest joint travel, each joint's travel divided by its speed limit (a minimum-jerk move's
time is proportional to it, ``robot.trajectory``; for joints of one speed limit, the smallest largest travel).
The last pose also counts the move back to the first (the program cycles). The first pose's previous waypoint
is the program's start configuration (``ik_seed_deg``, else the middle of each joint's range).

Finally each joint's whole turns are chosen over the cycle at once (``robot.turns.unwound``): no move turns a
joint further than whole turns of the waypoints within its limits make necessary, which keeps every move
under half a turn where the range allows the shorter way and the cycle does not have to turn back.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.robot.joints import JointMap, limit_violation
from cellstress.robot.model import RobotModel, load_pinocchio
from cellstress.robot.turns import TURN, turns_freely, unwound

POSITION_TOL = 1e-3  # m: a pose counts as reached within 1 mm ...
ANGLE_TOL = np.deg2rad(1.0)  # ... and 1 deg
RESTARTS = 12
ITERATIONS = 300
DAMPING = 1e-6
MAX_STEP = 0.5  # rad (or m) per iteration
NULL_GAIN = 0.5
STALL = 40  # iterations: a solve whose error fell by less than STALL_GAIN over this many has stalled
STALL_GAIN = 0.01
SAME = 1e-6  # rad (or m): solutions this close are one


class Unreachable(CellstressError):
    """No solution within the joint limits reaches the pose; ``residual`` is the best found (m, rad)."""

    def __init__(self, index: int, residual: tuple[float, float]):
        self.index = index
        self.residual = residual
        super().__init__(f"pose {index} is out of reach: the closest the arm gets is "
                         f"{residual[0] * 1000:.1f} mm and {np.rad2deg(residual[1]):.1f} deg away")


def _pose_error(pin, model, data, frame_id, q, target):
    pin.framesForwardKinematics(model, data, q)
    current = data.oMf[frame_id]
    err = pin.log6(current.actInv(target)).vector
    return err, current


def _solve(pin, model, data, frame_id, e, jmap, target, seed, lo, hi):
    """Driven joint values reaching ``target`` from ``seed``, and the residual (m, rad)."""
    x = seed.copy()
    best = (np.inf, np.inf)
    history = []
    for _ in range(ITERATIONS):
        q = jmap.robot.pinocchio_q(jmap.expand(x))
        err, current = _pose_error(pin, model, data, frame_id, q, target)
        best = (float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:])))
        if best[0] < 1e-7 and best[1] < 1e-7:  # well inside the tolerance, so the check below is not marginal
            break
        history.append(best[0] + best[1])
        if len(history) > STALL and history[-1] > (1.0 - STALL_GAIN) * history[-1 - STALL]:
            break  # stuck (at a limit, or in a local minimum away from the pose): the other seeds go on
        jac = pin.computeFrameJacobian(model, data, q, frame_id, pin.ReferenceFrame.LOCAL) @ e
        a = -pin.Jlog6(current.actInv(target).inverse()) @ jac  # d err / d x
        pinv = a.T @ np.linalg.inv(a @ a.T + DAMPING * np.eye(6))
        # the pose error's step, plus (in the null space of the pose: a redundant arm's free motion) a pull
        # back towards the start, so the solution is the one nearest the previous waypoint, not any one
        step = -pinv @ err
        if len(x) > 6:  # (a chain of 6 joints or fewer has no such motion: the pull would only slow it down)
            step += NULL_GAIN * (seed - x - pinv @ (a @ (seed - x)))
        norm = float(np.linalg.norm(step))
        if norm > MAX_STEP:  # far from the target the linearisation overshoots
            step *= MAX_STEP / norm
        x = np.clip(x + step, lo, hi)
    # the residual of the final x, measured in the target's frame as position and angle
    q = jmap.robot.pinocchio_q(jmap.expand(x))
    pin.framesForwardKinematics(model, data, q)
    rel = data.oMf[frame_id].actInv(target)
    residual = (float(np.linalg.norm(rel.translation)), float(np.linalg.norm(pin.log3(rel.rotation))))
    return x, residual


def nearest_turn(x: np.ndarray, refs: list[np.ndarray], robot: RobotModel, joints: list[int]) -> np.ndarray:
    """``x`` (values of ``joints``) with each revolute joint moved by whole turns, within its limits, to the
    value whose largest distance from the ``refs`` is least (one ref: the value nearest it): the same pose
    (``turns_freely``)."""
    out = np.asarray(x, dtype=float).copy()
    for c, j in enumerate(joints):
        if not turns_freely(robot, j):
            continue
        lo, hi = robot.lower[j], robot.upper[j]
        # the turns k that keep x + k turns within the limits (a continuous joint: any)
        k_lo = np.ceil((lo - out[c] - 1e-9) / TURN) if np.isfinite(lo) else -np.inf
        k_hi = np.floor((hi - out[c] + 1e-9) / TURN) if np.isfinite(hi) else np.inf
        rs = [float(r[c]) for r in refs]
        mid = 0.5 * (min(rs) + max(rs))  # the cost max_r |v - r| is least at the refs' middle
        base = np.round((mid - out[c]) / TURN)
        candidates = {float(np.clip(base + d, k_lo, k_hi)) for d in (-1.0, 0.0, 1.0)}
        candidates.add(float(np.clip(np.round((rs[0] - out[c]) / TURN), k_lo, k_hi)))
        best = min(sorted(candidates), key=lambda k: (max(abs(out[c] + k * TURN - r) for r in rs),
                                                      abs(out[c] + k * TURN - rs[0])))
        out[c] += best * TURN
    return out


def move_time(a: np.ndarray, b: np.ndarray, vmax: np.ndarray) -> float:
    """The largest joint travel from a to b, each joint's divided by its speed limit [s]: a minimum-jerk move's
    time in proportion (``robot.trajectory.build_trajectory``)."""
    return float(np.max(np.abs(b - a) / vmax))


def _choose(found: list[np.ndarray], refs: list[np.ndarray], vmax: np.ndarray) -> np.ndarray:
    """The solution whose slowest move to or from the refs is quickest; ties: the least squared travel from
    refs[0], then the first found (so the choice is deterministic)."""
    def cost(x):
        return (round(max(move_time(r, x, vmax) for r in refs), 9),
                round(float(np.sum(((x - refs[0]) / vmax) ** 2)), 9))
    return min(found, key=cost)


def frame_index(pin, model, frame: str) -> int:
    """Pinocchio's index of the frame named ``frame``: a link (a joint may share its name, as the SO-100's
    ``gripper`` does), else any frame of that name; CellstressError naming the links if there is none."""
    for kind in (pin.FrameType.BODY, None):
        if model.existFrame(frame) if kind is None else model.existFrame(frame, kind):
            return int(model.getFrameId(frame) if kind is None else model.getFrameId(frame, kind))
    frames = sorted({f.name for f in model.frames if f.type == pin.FrameType.BODY})
    raise CellstressError(f"the robot has no frame {frame!r}; its links are {', '.join(frames)}")


def solve_poses(jmap: JointMap, frame: str, targets: list[np.ndarray], seed: np.ndarray) -> np.ndarray:
    """Driven joint values (n, nd) for each 4x4 target of ``frame`` in the robot's base frame, in order,
    starting from the configuration ``seed`` (the first waypoint is the solution nearest it)."""
    import pinocchio as pin  # heavy: imported only when a cell has poses (as robot.model does)

    robot = jmap.robot
    model = load_pinocchio(robot.urdf)
    frame_id = frame_index(pin, model, frame)
    data = model.createData()
    e = jmap.jacobian_map()
    driven = list(jmap.driven)
    lo, hi = robot.lower[driven], robot.upper[driven]
    vmax = robot.velocity_limits[driven]
    rng = np.random.default_rng(0)  # restarts are deterministic: same cell, same waypoints
    restarts = rng.uniform(*(r[driven] for r in robot.sampling_range()), (RESTARTS, len(driven)))
    out: list[np.ndarray] = []
    previous = np.clip(seed, lo, hi)
    for i, target in enumerate(targets):
        goal = pin.SE3(target[:3, :3], target[:3, 3])
        # the last pose moves on to the first one again (the program cycles): both moves count
        refs = [previous] if i == 0 or i < len(targets) - 1 else [previous, out[0]]
        found: list[np.ndarray] = []
        best = (np.inf, np.inf)
        for start in (previous, *restarts):
            x, res = _solve(pin, model, data, frame_id, e, jmap, goal, start, lo, hi)
            if res[0] + res[1] < best[0] + best[1]:
                best = res
            if res[0] <= POSITION_TOL and res[1] <= ANGLE_TOL and limit_violation(robot, jmap.expand(x)) < 0:
                x = nearest_turn(x, refs, robot, driven)
                if all(np.max(np.abs(x - f)) > SAME for f in found):
                    found.append(x)
        if not found:
            raise Unreachable(i, best)
        x = _choose(found, refs, vmax)
        out.append(x)
        previous = x
    q = np.asarray(out)
    if len(q) > 1:  # the cycle as a whole: each joint's whole turns such that none turns further than needed
        start = np.clip(seed, lo, hi)
        for c, j in enumerate(driven):
            if turns_freely(robot, j):
                q[:, c] = unwound(q[:, c], float(robot.lower[j]), float(robot.upper[j]), float(start[c]))
    return q
