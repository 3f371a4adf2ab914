"""Tool poses to joint waypoints: inverse kinematics with pinocchio, within the joint limits, continuous from
one waypoint to the next.

Damped least squares on the pose error log6(oMf^-1 oMdes) (pinocchio's own formulation), over the driven joints
only (mimic joints follow through the JointMap), each step clipped to the joint limits. The previous
waypoint's solution is tried first, with a pull in the null space of the pose (a redundant arm's free motion)
back towards it; a few deterministic restarts cover the case it cannot reach, and among the solutions found the
closest to the previous waypoint is kept, so the arm does not flip configuration.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.robot.joints import JointMap, limit_violation
from cellstress.robot.model import load_pinocchio

POSITION_TOL = 1e-3  # m: a pose counts as reached within 1 mm ...
ANGLE_TOL = np.deg2rad(1.0)  # ... and 1 deg
RESTARTS = 12
ITERATIONS = 300
DAMPING = 1e-6
MAX_STEP = 0.5  # rad (or m) per iteration
NULL_GAIN = 0.5


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
    for _ in range(ITERATIONS):
        q = jmap.robot.pinocchio_q(jmap.expand(x))
        err, current = _pose_error(pin, model, data, frame_id, q, target)
        best = (float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:])))
        if best[0] < 1e-7 and best[1] < 1e-7:  # well inside the tolerance, so the check below is not marginal
            break
        jac = pin.computeFrameJacobian(model, data, q, frame_id, pin.ReferenceFrame.LOCAL) @ e
        a = -pin.Jlog6(current.actInv(target).inverse()) @ jac  # d err / d x
        pinv = a.T @ np.linalg.inv(a @ a.T + DAMPING * np.eye(6))
        # the pose error's step, plus (in the null space of the pose: a redundant arm's free motion) a pull
        # back towards the start, so the solution is the one nearest the previous waypoint, not any one
        step = -pinv @ err + NULL_GAIN * (seed - x - pinv @ (a @ (seed - x)))
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


def solve_poses(jmap: JointMap, frame: str, targets: list[np.ndarray], seed: np.ndarray) -> np.ndarray:
    """Driven joint values (n, nd) for each 4x4 target of ``frame`` in the robot's base frame, in order."""
    import pinocchio as pin  # heavy: imported only when a cell has poses (as robot.model does)

    robot = jmap.robot
    model = load_pinocchio(robot.urdf)
    if not model.existFrame(frame):
        frames = sorted({f.name for f in model.frames if f.type == pin.FrameType.BODY})
        raise CellstressError(f"the robot has no frame {frame!r}; its links are {', '.join(frames)}")
    frame_id = model.getFrameId(frame)
    data = model.createData()
    e = jmap.jacobian_map()
    driven = list(jmap.driven)
    lo, hi = robot.lower[driven], robot.upper[driven]
    rng = np.random.default_rng(0)  # restarts are deterministic: same cell, same waypoints
    restarts = rng.uniform(*(r[driven] for r in robot.sampling_range()), (RESTARTS, len(driven)))
    out = []
    previous = np.clip(seed, lo, hi)
    for i, target in enumerate(targets):
        goal = pin.SE3(target[:3, :3], target[:3, 3])
        found, best = [], (np.inf, np.inf)
        for start in (previous, *restarts):
            x, res = _solve(pin, model, data, frame_id, e, jmap, goal, start, lo, hi)
            if res[0] + res[1] < best[0] + best[1]:
                best = res
            if res[0] <= POSITION_TOL and res[1] <= ANGLE_TOL and limit_violation(robot, jmap.expand(x)) < 0:
                found.append(x)
                if len(found) >= 3:
                    break
        if not found:
            raise Unreachable(i, best)
        x = min(found, key=lambda s: float(np.sum((s - previous) ** 2)))
        out.append(x)
        previous = x
    return np.asarray(out)
