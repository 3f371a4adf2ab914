"""Which joints a robot program drives, and the full joint vector from the driven values.

A URDF ``<mimic>`` joint follows its master (q = multiplier * q_master + offset) and a held joint stays at one
value, so a program gives values for the other joints only. Expanding to every joint happens here, in Python,
before the kernel: the kernel interpolates full joint vectors, which keeps mimic joints exact on both
minimum-jerk and linear moves (each is linear in its master).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.robot.model import REVOLUTE, RobotModel


@dataclass(frozen=True)
class JointMap:
    """The driven joints of ``robot`` (indices, in URDF order) and the held joints' values (rad / m)."""

    robot: RobotModel
    driven: tuple[int, ...]
    held: dict[int, float]

    @property
    def driven_names(self) -> tuple[str, ...]:
        return tuple(self.robot.joint_names[j] for j in self.driven)

    def expand(self, values: np.ndarray) -> np.ndarray:
        """Full joint vectors (..., nj) from driven values (..., nd), both in rad / m."""
        values = np.asarray(values, dtype=float)
        r = self.robot
        out = np.zeros((*values.shape[:-1], r.n_joints))
        out[..., list(self.driven)] = values
        for j, v in self.held.items():
            out[..., j] = v
        for m in np.flatnonzero(r.mimic_master >= 0):
            out[..., m] = r.mimic_multiplier[m] * out[..., r.mimic_master[m]] + r.mimic_offset[m]
        return out

    def jacobian_map(self) -> np.ndarray:
        """(nj, nd): d q_full / d q_driven."""
        r = self.robot
        e = np.zeros((r.n_joints, len(self.driven)))
        for col, j in enumerate(self.driven):
            e[j, col] = 1.0
        for m in np.flatnonzero(r.mimic_master >= 0):
            e[m] = r.mimic_multiplier[m] * e[r.mimic_master[m]]
        return e

    def from_user(self, values: np.ndarray, degrees: bool = True) -> np.ndarray:
        """Driven values given in a cell file's units (deg for revolute joints if ``degrees``, m) to rad / m."""
        values = np.asarray(values, dtype=float)
        if not degrees:
            return values
        revolute = np.asarray([self.robot.kinds[j] == REVOLUTE for j in self.driven])
        return np.where(revolute, np.deg2rad(values), values)


def ancestors_or_self(robot: RobotModel, j: int) -> set[int]:
    """Joint j and every joint between it and the base."""
    out = set()
    while j >= 0:
        out.add(j)
        j = int(robot.parents[j])
    return out


def branching(jmap: JointMap) -> tuple[int, int] | None:
    """Two driven joints on separate branches of the robot's tree (neither carries the other), or None when the
    driven joints lie on one chain. A tree robot (two arms on one torso) has such a pair."""
    driven = jmap.driven
    for i, a in enumerate(driven):
        line = ancestors_or_self(jmap.robot, a)
        for b in driven[i + 1:]:
            if a not in ancestors_or_self(jmap.robot, b) and b not in line:
                return a, b
    return None


def chains(jmap: JointMap) -> tuple[tuple[int, ...], ...]:
    """The driven joints grouped by the highest driven joint that carries them: one group per arm of a tree
    robot (a branching below an arm's first joint stays in its group)."""
    groups: dict[int, list[int]] = {}
    for j in jmap.driven:
        top = min(ancestors_or_self(jmap.robot, j) & set(jmap.driven))
        groups.setdefault(top, []).append(j)
    return tuple(tuple(g) for g in groups.values())


def joint_map(robot: RobotModel, held: dict[int, float]) -> JointMap:
    driven = tuple(j for j in range(robot.n_joints) if robot.mimic_master[j] < 0 and j not in held)
    return JointMap(robot, driven, dict(held))


def user_value(robot: RobotModel, j: int, value: float) -> float:
    """A joint value in rad / m as a cell file gives it (deg for revolute joints)."""
    return float(np.rad2deg(value)) if robot.kinds[j] == REVOLUTE else float(value)


def limit_violation(robot: RobotModel, q: np.ndarray, tol: float = 1e-8) -> int:
    """The first joint whose value in ``q`` (rad / m) is outside its limits, or -1."""
    bad = np.flatnonzero((q < robot.lower - tol) | (q > robot.upper + tol))
    return int(bad[0]) if bad.size else -1


def describe_limit(robot: RobotModel, j: int, value: float) -> str:
    """'<value> is outside joint <name>'s limits <lo>..<hi>' in the cell file's units."""
    unit = robot.unit(j)
    lo, hi, v = (user_value(robot, j, x) for x in (robot.lower[j], robot.upper[j], value))
    fmt = ".1f" if unit == "deg" else ".4g"
    return f"{v:g} {unit} is outside joint {robot.joint_names[j]!r}'s limits {lo:{fmt}}..{hi:{fmt}} {unit}"
