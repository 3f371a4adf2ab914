"""Whole turns of a revolute joint in a cyclic program: the same poses, the least turning.

A revolute joint whose range spans more than a turn (a UR's +-360 deg) or none at all (a continuous joint)
reaches an angle as theta, theta + 360 deg, ...; which of them each waypoint takes decides how far the joint
turns on each move. A program cycles (its last waypoint moves back to the first), so the moves of one joint
add up to nothing: a program that visits three stations around the base must turn back the long way once,
whatever the values (120 + 120 - 240 deg). What can be asked of a program is that no joint turns further on
any move than whole turns of its waypoints, within the joint's limits, make necessary: ``least_largest_move``
is that bound, ``unwound`` the waypoint values that attain it (and among those, the least travel in all).
"""

from __future__ import annotations

import math

import numpy as np

from cellstress.robot.model import REVOLUTE, RobotModel

TURN = 2.0 * math.pi
EPS = 1e-9  # rad: limits and equal moves are compared with this slack


def turns_freely(robot: RobotModel, j: int) -> bool:
    """Whether a whole turn of joint j leaves the robot's pose as it is: a revolute joint that no ``<mimic>``
    joint follows (its follower would turn by multiplier turns, not necessarily whole ones) and that follows
    none."""
    return robot.kinds[j] == REVOLUTE and robot.mimic_master[j] < 0 and j not in robot.mimic_master


def candidates(values: np.ndarray, lo: float, hi: float) -> list[np.ndarray]:
    """For each waypoint, the values its joint value takes by whole turns within [lo, hi]. A joint without
    limits (continuous) gets the turns within reach of every waypoint: as many as the values spread over, plus
    one either side, which is all a cycle of least turning can use (each of its moves is under a turn)."""
    values = np.asarray(values, dtype=float)
    if math.isfinite(lo) and math.isfinite(hi):
        out = []
        for v in values:
            k = np.arange(math.ceil((lo - v - EPS) / TURN), math.floor((hi - v + EPS) / TURN) + 1)
            out.append(v + k * TURN if len(k) else np.array([v]))
        return out
    spread = math.ceil((float(values.max() - values.min()) + math.pi) / TURN) + 1
    ks = np.arange(-spread, spread + 1)
    return [v + ks * TURN for v in values]


def _bottleneck(cands: list[np.ndarray], c0: float) -> float:
    """The least largest move of a cycle that starts at value c0 of waypoint 0 and takes one candidate of each
    other waypoint."""
    best = np.array([0.0])
    prev = np.array([c0])
    for c in cands[1:]:
        step = np.abs(c[:, None] - prev[None, :])
        best = np.min(np.maximum(step, best[None, :]), axis=1)
        prev = c
    return float(np.min(np.maximum(best, np.abs(prev - c0))))


def least_largest_move(values: np.ndarray, lo: float, hi: float) -> float:
    """The least that the largest move of this joint can be [rad] over a cyclic program through ``values``
    (waypoint order, the last moving back to the first), each waypoint taken at any whole turn within the
    limits."""
    cands = candidates(values, lo, hi)
    if len(cands) < 2:
        return 0.0
    return min(_bottleneck(cands, float(c0)) for c0 in cands[0])


def _least_travel(cands: list[np.ndarray], c0: float, cap: float) -> tuple[float, list[float]] | None:
    """The least total travel of a cycle from c0 whose moves all stay within ``cap``, with its values."""
    cost = np.array([0.0])
    prev = np.array([c0])
    back: list[np.ndarray] = []
    for c in cands[1:]:
        step = np.abs(c[:, None] - prev[None, :])
        total = np.where(step <= cap, step + cost[None, :], np.inf)
        back.append(np.argmin(total, axis=1))
        cost = np.min(total, axis=1)
        prev = c
    closing = np.abs(prev - c0)
    cost = np.where(closing <= cap, cost + closing, np.inf)
    k = int(np.argmin(cost))
    if not math.isfinite(float(cost[k])):
        return None
    path = [float(prev[k])]
    for i in range(len(cands) - 1, 1, -1):
        k = int(back[i - 1][k])
        path.append(float(cands[i - 1][k]))
    return float(cost.min()), [c0, *reversed(path)]


def unwound(values: np.ndarray, lo: float, hi: float, near: float) -> np.ndarray:
    """``values`` with each waypoint turned by whole turns, within [lo, hi], so that the cycle's largest move is
    least, then its total travel; of equal cycles, the one whose first value is nearest ``near``."""
    values = np.asarray(values, dtype=float)
    cands = candidates(values, lo, hi)
    if len(cands) < 2:
        return values.copy()
    cap = least_largest_move(values, lo, hi) + EPS
    best: tuple[float, float, list[float]] | None = None
    for c0 in sorted(cands[0], key=lambda c: abs(c - near)):
        found = _least_travel(cands, float(c0), cap)
        if found is not None and (best is None or found[0] < best[0] - EPS):
            best = (found[0], abs(c0 - near), found[1])
    assert best is not None  # the cap is attained by some c0
    return np.asarray(best[2])
