"""Read-only views of the simulator's geometry for pictures: robot capsules at a path time, body capsules for a
pose, the reach volume as points, the path time of every step of a trace.

Everything here calls the compiled kernels themselves (no second implementation of the kinematics or the body),
so a picture shows exactly what the simulator measured. Nothing here is on the hot path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from cellstress.human.body import BODY_PARTS, N_CAPSULES
from cellstress.sim import kernels as K
from cellstress.sim.build import Layout


@dataclass(frozen=True, eq=False)
class BodyPose:
    """The worker's capsules (``a``-``b`` axis, radius ``r``; order ``BODY_PARTS[:6]``), shoulders (left, right)
    and trunk frame (columns: forward, left, up) for one pose."""

    a: np.ndarray  # (6, 3)
    b: np.ndarray  # (6, 3)
    r: np.ndarray  # (6,)
    shoulders: np.ndarray  # (2, 3)
    trunk: np.ndarray  # (3, 3)

    @property
    def names(self) -> tuple[str, ...]:
        return BODY_PARTS[:N_CAPSULES]


def body_pose(layout: Layout, x: float, y: float, heading: float, forward: float, lateral: float) -> BodyPose:
    """Body capsules for a position [m] and heading / forward / lateral flexion [rad] (``kernels.human_pose``)."""
    W = K.make_work(layout.params)
    K.human_pose(layout.params, float(x), float(y), float(heading), float(forward), float(lateral), W)
    return BodyPose(W.ha.copy(), W.hb.copy(), W.hr.copy(), W.sh.copy(), W.tr.copy())


def robot_capsules(layout: Layout, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """Robot capsule axes (a, b), each (n_capsules, 3), at path time ``tau``; radii are ``layout.params.cap_r``.

    The pose depends on the path time only (a stop slows the path time down, it does not change the path), so
    the pose is ``kernels.robot_live`` at t = tau - phase with no stop."""
    P = layout.params
    W = K.make_work(P)
    K.robot_live(P, float(tau) - float(P.scal[K.C_PHASE0]), np.inf, W)
    return W.ra.copy(), W.rb.copy()


def path_times(rows: np.ndarray) -> np.ndarray:
    """The robot's path time at every row of ``Trace.rows``."""
    return np.asarray(rows[:, K.M_TAU], dtype=float)


@njit(cache=True, error_model="numpy")
def _detour_within(fences, near, n_near, s, pts, arm_length, keep):
    for i in range(pts.shape[0]):
        d = K.fence_detour(fences, near, n_near, s[0], s[1], s[2], pts[i, 0], pts[i, 1], pts[i, 2])
        keep[i] = d - arm_length <= 0.0


def reach_nodes(layout: Layout, stride: int = 1) -> np.ndarray:
    """Shoulder-frame coordinates (m, 3) of the right arm's reach-field grid nodes inside its volume (field value
    <= 0; trilinear interpolation is exact at nodes). ``stride`` > 1 keeps every stride-th node per axis."""
    field = layout.reach
    vals = field.values[::stride, ::stride, ::stride]
    return field.origin + np.argwhere(vals <= 0.0).astype(float) * (stride * field.spacing)


def reach_points(layout: Layout, pose: BodyPose, side: int, stride: int = 1,
                 nodes: np.ndarray | None = None) -> np.ndarray:
    """World points (m, 3) of the reach-field grid nodes inside arm ``side``'s reach volume (0 left, 1 right).

    A node is inside where the kernel's ``reach_value`` is <= 0: the field value at the node and, near fences,
    the arm's detour around them within the arm's length. ``nodes`` may hold ``reach_nodes(layout, stride)``
    computed once, for many poses."""
    P = layout.params
    local = (reach_nodes(layout, stride) if nodes is None else nodes).copy()
    if side == 0:
        local[:, 1] = -local[:, 1]  # the left arm is the mirror image of the right one
    pts = pose.shoulders[side] + local @ pose.trunk.T
    W = K.make_work(P)
    W.sh[:] = pose.shoulders
    n_near = int(K.near_fences(P, W, P.body[K.B_ARM_LEN] + 0.05))
    if n_near == 0:
        return pts
    keep = np.zeros(len(pts), dtype=np.bool_)
    _detour_within(P.fences, W.near, n_near, np.ascontiguousarray(pose.shoulders[side]), np.ascontiguousarray(pts),
                   float(P.body[K.B_ARM_LEN]), keep)
    return pts[keep]
