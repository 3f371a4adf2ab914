"""How fast the robot's capsules can move along the robot's path: per capsule, an upper bound on the speed of
any point of its axis per second of path time. The swept contact test between time steps (``kernels.sweep``),
the verifier's distance bound and its arrival margins all rest on it.

The bound: the sum over the joints that move the capsule of each revolute joint's peak rate times the point's
distance from the joint's origin (at most the link lengths in between, the largest slides of the prismatic
joints in between, and the capsule's end), plus each prismatic joint's own peak speed (a slide moves every point
it carries at its speed). A joint's peak rate is its largest move between two waypoints over the move's
duration, times ``PEAK`` (a minimum-jerk move peaks at 1.875 times its mean speed; a linear move at 1).
``tests/verifier/test_verify_bounds.py`` checks it against finely sampled robot poses.
"""

from __future__ import annotations

import numpy as np

from cellstress.robot.model import PRISMATIC

PEAK = 1.875  # a minimum-jerk segment's peak speed over its mean speed


def capsule_speeds(part) -> np.ndarray:
    """For each capsule of one robot (a ``sim.build.RobotPart``), an upper bound on the speed of any point of its
    axis per second of path time (see the module)."""
    model, traj = part.model, part.trajectory
    wp = np.asarray(traj.waypoints)
    moves = np.asarray(traj.move_times, dtype=float)
    qd_max = np.zeros(wp.shape[1])
    for i in range(len(wp)):
        step = np.abs(wp[(i + 1) % len(wp)] - wp[i])
        qd_max = np.maximum(qd_max, PEAK * step / moves[i])
    prismatic = np.asarray([k == PRISMATIC for k in model.kinds])
    # a move's joint values stay between its two waypoints' (minimum-jerk and linear moves are monotone), so a
    # prismatic joint's slide is at most its largest waypoint value, and it carries the joints below it that far
    slide = np.where(prismatic, np.abs(wp).max(axis=0), 0.0)
    link = np.linalg.norm(np.asarray(model.placements)[:, :3, 3], axis=1)  # from the parent's origin, unslid
    out = np.zeros(len(part.capsules))
    for c, cap in enumerate(part.capsules):
        speed, lever, i = 0.0, max(np.linalg.norm(cap.p0), np.linalg.norm(cap.p1)), int(cap.joint)
        while i >= 0:  # joint i moves the point; its distance from joint i's origin is at most ``lever``
            if prismatic[i]:
                speed += qd_max[i]  # a slide moves every point it carries at its own speed
            else:
                speed += qd_max[i] * lever  # a turn: at most the point's distance from the axis times the rate
            lever += link[i] + slide[i]
            i = int(model.parents[i])
        out[c] = speed  # (0 for a capsule on the base: joint -1)
    return out
