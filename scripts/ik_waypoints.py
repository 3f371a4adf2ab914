"""Design aid: joint waypoints for a pick or place pose, by damped least-squares IK with pinocchio.

Usage: python scripts/ik_waypoints.py X Y Z [--seed q1,...,q6] [--base-yaw DEG]
X, Y, Z: tool0 position in the robot base frame [m]; the tool points straight down.
The built-in cells' waypoints were made with this script (see docs/cells.md). A cell file can now give the
poses itself (robot.task.poses and tool_frame, solved when the cell is loaded: docs/cell-format.md); this
script stays as the record of how the built-in waypoints were made.
"""

from __future__ import annotations

import argparse

import numpy as np
import pinocchio as pin

from cellstress.robot.model import resolve_urdf


def solve(target, seed, robot="ur10", iters=500):
    model = pin.buildModelFromUrdf(str(resolve_urdf(robot, None)))
    data = model.createData()
    fid = model.getFrameId("tool0")
    goal = pin.SE3(np.diag([1.0, -1.0, -1.0]), np.asarray(target, float))  # z down
    q = np.asarray(seed, float)
    for _ in range(iters):
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        err = pin.log6(data.oMf[fid].actInv(goal)).vector
        if np.linalg.norm(err) < 1e-9:
            break
        J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL)
        dq = J.T @ np.linalg.solve(J @ J.T + 1e-6 * np.eye(6), err)
        q = q + dq
    q = (q + np.pi) % (2 * np.pi) - np.pi
    return q, float(np.linalg.norm(err))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("xyz", nargs=3, type=float)
    ap.add_argument("--seed", default="0,-60,90,-120,-90,0", help="degrees")
    args = ap.parse_args()
    seed = np.deg2rad([float(v) for v in args.seed.split(",")])
    q, err = solve(args.xyz, seed)
    print("[" + ", ".join(f"{v:.1f}" for v in np.rad2deg(q)) + "]", f"residual {err:.1e}")


if __name__ == "__main__":
    main()
