"""The robot's cyclic task: joint waypoints joined by minimum-jerk segments whose duration respects the joint
speed limits, with a dwell (grip or release) at every waypoint.

A minimum-jerk segment s(u) = 10u^3 - 15u^4 + 6u^5 peaks at 15/8 of the mean speed, so a segment of joint
change dq takes T = max_j 15/8 |dq_j| / (scale * vmax_j). Velocity and acceleration are zero at every
waypoint, so the cycle is smooth where segments join.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_SEGMENT_TIME = 0.2  # s; keeps tiny moves from becoming jerks


@dataclass(frozen=True)
class Trajectory:
    waypoints: np.ndarray  # (n, nj) rad
    starts: np.ndarray  # (n,) time each segment's dwell begins, s
    move_times: np.ndarray  # (n,) duration of each move, s
    dwell: float
    cycle: float

    @property
    def n_segments(self) -> int:
        return len(self.starts)


def build_trajectory(waypoints_deg, dwell: float, speed_scale: float, vmax: np.ndarray) -> Trajectory:
    w = np.deg2rad(np.asarray(waypoints_deg, dtype=float))
    n = len(w)
    moves = np.empty(n)
    for i in range(n):
        dq = np.abs(w[(i + 1) % n] - w[i])
        moves[i] = max(MIN_SEGMENT_TIME, float(np.max(1.875 * dq / (speed_scale * vmax))))
    starts = np.concatenate([[0.0], np.cumsum(dwell + moves)[:-1]])
    cycle = float(np.sum(dwell + moves))
    return Trajectory(w, starts, moves, float(dwell), cycle)


def evaluate(traj: Trajectory, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """Joint positions and velocities (per unit of path time) at path time tau; reference for the kernel."""
    tc = tau % traj.cycle
    i = int(np.searchsorted(traj.starts, tc, side="right") - 1)
    a, b = traj.waypoints[i], traj.waypoints[(i + 1) % traj.n_segments]
    u = (tc - traj.starts[i] - traj.dwell) / traj.move_times[i]
    if u <= 0.0:
        return a.copy(), np.zeros_like(a)
    u = min(u, 1.0)
    s = u**3 * (10 - 15 * u + 6 * u * u)
    ds = 30 * u * u * (1 - u) ** 2 / traj.move_times[i]
    return a + s * (b - a), ds * (b - a)
