"""Read-only views of the simulator's geometry for pictures: robot capsules at a path time, body capsules for a
pose, the reach volume as points, the path time of every step of a trace.

Everything here calls the compiled kernels themselves (no second implementation of the kinematics or the body),
so a picture shows exactly what the simulator measured. Nothing here is on the hot path.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.human.body import CAPSULE_PART, BodyPose
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.build import Layout
from cellstress.sim.geometry import segment_segment


def body_pose(layout: Layout, pose: np.ndarray) -> BodyPose:
    """Body capsules for a pose vector (``layout.POSE_ROW``'s order; ``layout.row_pose``, ``layout.pose_vector``)
    as ``kernels.human_pose`` places them."""
    W = K.make_work(layout.params)
    K.human_pose(layout.params, np.ascontiguousarray(pose, dtype=float), W)
    n = int(layout.params.body[L.B_N_CAPS])
    return BodyPose(W.ha[:n].copy(), W.hb[:n].copy(), W.hr[:n].copy(), W.sh.copy(), W.tr.copy())


def robot_capsules(layout: Layout, tau) -> tuple[np.ndarray, np.ndarray]:
    """Robot capsule axes (a, b), each (n_capsules, 3), at path time ``tau``; radii are ``layout.params.cap_r``.
    In a cell of several robots ``tau`` may hold each robot's path time (a row of ``path_times``); a single
    value poses the others at the same time since the episode began, unstopped.

    The pose depends on the path time only (a stop slows the path time down, it does not change the path), so
    the pose is ``kernels.robot_live`` at t = tau - phase with no stop (``kernels.other_robots`` for the
    others, with their phase set to their path time at step 0)."""
    P = layout.params
    taus = np.atleast_1d(np.asarray(tau, dtype=float))
    W = K.make_work(P)
    K.robot_live(P, float(taus[0]) - float(P.scal[L.C_PHASE0]), np.inf, W)
    nx = P.x_scal.shape[0]
    if nx:
        x_scal = P.x_scal.copy()
        x_scal[:, L.C_PHASE0] = taus[1:] if len(taus) > 1 else x_scal[:, L.C_PHASE0] + taus[0] - P.scal[L.C_PHASE0]
        state = np.full(L.NS, np.inf)
        K.other_robots(P._replace(x_scal=x_scal, pre_xv=np.zeros((0, nx))), np.int64(0), state, W)
    return W.ra.copy(), W.rb.copy()


def path_times(rows: np.ndarray, n_robots: int = 1) -> np.ndarray:
    """The robot's path time at every row of ``Trace.rows``; with ``n_robots`` > 1, (rows, robots): each
    robot's."""
    if n_robots > 1:
        return np.asarray(rows[:, [L.M_TAU, *range(L.M_XTAU, L.M_XTAU + n_robots - 1)]], dtype=float)
    return np.asarray(rows[:, L.M_TAU], dtype=float)


@njit(cache=True, error_model="numpy")
def _detour_within(fences, near, n_near, s, pts, arm_length, keep):
    for i in range(pts.shape[0]):
        d = K.fence_detour(fences, near, n_near, s[0], s[1], s[2], pts[i, 0], pts[i, 1], pts[i, 2], np.inf)
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
    n_near = int(K.near_fences(P, W, P.body[L.B_ARM_LEN] + 0.05))
    if n_near == 0:
        return pts
    keep = np.zeros(len(pts), dtype=np.bool_)
    _detour_within(P.fences, W.near, n_near, np.ascontiguousarray(pose.shoulders[side]), np.ascontiguousarray(pts),
                   float(P.body[L.B_ARM_LEN]), keep)
    return pts[keep]


def time_scaling(layout: Layout, row: np.ndarray) -> float:
    """The robot's time scaling sigma at a metric row: 1 running, falling to 0 while braking, 0 stopped. The row
    holds the path time tau and the stop phase; while braking, the time since the stop took effect follows from
    tau = tau0 + t_s + d - d^2 / (2 T) with t = t_s + d, so sigma = 1 - d / T (a category 0 stop holds
    tau = tau0 + t_s, so d = t - (tau - tau0))."""
    P = layout.params
    T = float(P.scal[L.C_STOP_TIME])
    tau, t, phase = float(row[L.M_TAU]), float(row[L.M_T]), int(row[L.M_PHASE])
    if phase == L.PHASE_STOPPED:
        return 0.0
    if phase == L.PHASE_BRAKING and P.scal[L.C_STOP_HOLD] != 0.0:
        return max(0.0, 1.0 - (t - (tau - float(P.scal[L.C_PHASE0]))) / T)
    if phase == L.PHASE_BRAKING:
        d = float(np.sqrt(max(0.0, 2.0 * T * (t + float(P.scal[L.C_PHASE0]) - tau))))
        return max(0.0, 1.0 - d / T)
    return 1.0


def joint_state(layout: Layout, row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The robot's joint positions and velocities (q, q_dot) at a metric row, from the kernel's own trajectory
    (at the row's path time, scaled by ``time_scaling``)."""
    P = layout.params
    nj = P.placements.shape[0]
    q, qd = np.zeros(nj), np.zeros(nj)
    K.joint_trajectory(P, float(row[L.M_TAU]), time_scaling(layout, row), q, qd)
    return q, qd


def contact_normal(layout: Layout, row: np.ndarray, pose: BodyPose) -> np.ndarray:
    """Unit normal from the robot towards the human at a row's closest points: between the capsule axes for a
    body capsule (defined also when they overlap), from the robot point towards the shoulder for a reach volume
    (as the kernel places the points)."""
    part, link = int(row[L.M_PART]), int(row[L.M_LINK])
    rp = np.asarray(row[L.M_RX:L.M_RZ + 1], dtype=float)
    if part in (L.PART_LEFT_REACH, L.PART_RIGHT_REACH):
        v = pose.shoulders[part - L.PART_LEFT_REACH] - rp
    else:
        c = CAPSULE_PART.index(part)
        ra, rb = robot_capsules(layout, float(row[L.M_TAU]))
        c1, c2 = np.zeros(3), np.zeros(3)
        segment_segment(np.ascontiguousarray(ra[link]), np.ascontiguousarray(rb[link]),
                          np.ascontiguousarray(pose.a[c]), np.ascontiguousarray(pose.b[c]), c1, c2)
        v = c2 - c1
        if float(np.linalg.norm(v)) <= 1e-9:
            v = np.asarray(row[L.M_HX:L.M_HZ + 1], dtype=float) - rp
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-12 else np.array([0.0, 0.0, 1.0])
