"""The robot's cyclic program as segments the kernel evaluates: each segment dwells at its waypoint, then moves
to the next one, by a minimum-jerk move (waypoint programs) or at constant speed (a joint-trajectory file).

A minimum-jerk segment s(u) = 10u^3 - 15u^4 + 6u^5 peaks at 15/8 of the mean speed, so a segment of joint
change dq takes T = max_j 15/8 |dq_j| / (scale * vmax_j). Velocity and acceleration are zero at every
waypoint, so the cycle is smooth where segments join. A linear segment runs at dq / T throughout: the rows of a
controller's trajectory are dense, and their own timing is the program.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_SEGMENT_TIME = 0.2  # s; keeps tiny moves from becoming jerks


@dataclass(frozen=True)
class Trajectory:
    waypoints: np.ndarray  # (n, nj) every joint, rad or m; segment i moves from row i to row (i + 1) % n
    starts: np.ndarray  # (n,) time each segment's dwell begins, s (strictly increasing, starts[0] = 0)
    move_times: np.ndarray  # (n,) duration of each move, s
    dwells: np.ndarray  # (n,) pause at each waypoint before its move, s
    cycle: float
    linear: bool = False  # constant-speed moves (a trajectory file) instead of minimum-jerk ones

    @property
    def n_segments(self) -> int:
        return len(self.starts)


def build_trajectory(waypoints: np.ndarray, dwells: np.ndarray, speed_scales: np.ndarray,
                     vmax: np.ndarray) -> Trajectory:
    """Minimum-jerk moves between joint waypoints (rad / m), move i at speed_scales[i] of the joint limits."""
    w = np.asarray(waypoints, dtype=float)
    dwells = np.asarray(dwells, dtype=float)
    n = len(w)
    moves = np.empty(n)
    for i in range(n):
        dq = np.abs(w[(i + 1) % n] - w[i])
        moves[i] = max(MIN_SEGMENT_TIME, float(np.max(1.875 * dq / (speed_scales[i] * vmax))))
    starts = np.concatenate([[0.0], np.cumsum(dwells + moves)[:-1]])
    cycle = float(np.sum(dwells + moves))
    return Trajectory(w, starts, moves, dwells, cycle)


def linear_trajectory(times: np.ndarray, rows: np.ndarray) -> Trajectory:
    """Constant-speed moves through timed rows whose last row repeats the first (the cycle's end)."""
    times = np.asarray(times, dtype=float)
    starts = times[:-1] - times[0]
    moves = np.diff(times)
    return Trajectory(np.asarray(rows[:-1], dtype=float), starts, moves, np.zeros(len(starts)),
                      float(times[-1] - times[0]), linear=True)


def evaluate(traj: Trajectory, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """Joint positions and velocities (per unit of path time) at path time tau; reference for the kernel."""
    tc = tau % traj.cycle
    i = int(np.searchsorted(traj.starts, tc, side="right") - 1)
    a, b = traj.waypoints[i], traj.waypoints[(i + 1) % traj.n_segments]
    u = (tc - traj.starts[i] - traj.dwells[i]) / traj.move_times[i]
    if u < 0.0 or (u == 0.0 and not traj.linear):
        return a.copy(), np.zeros_like(a)
    u = min(u, 1.0)
    if traj.linear:
        return a + u * (b - a), (b - a) / traj.move_times[i]
    s = u**3 * (10 - 15 * u + 6 * u * u)
    ds = 30 * u * u * (1 - u) ** 2 / traj.move_times[i]
    return a + s * (b - a), ds * (b - a)
