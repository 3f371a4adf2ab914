"""The worker's body capsules, shoulders and trunk frame for a pose: position, heading, trunk flexion, and for
the articulated worker its stance (the hip's drop) and the joints of both arms."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.human.body import PRONE_BEGIN_Z, PRONE_HIP_Z, PRONE_TOL
from cellstress.sim.layout import (
    B_ARM_LEN,
    B_FOREARM,
    B_HAND,
    B_HEAD_RISE,
    B_HIP_Z,
    B_LEG_HALF,
    B_MODEL,
    B_R_ARM,
    B_R_FORE,
    B_R_HAND,
    B_R_HEAD,
    B_R_LEG,
    B_R_TRUNK,
    B_R_UPPER,
    B_SHOULDER_HALF,
    B_SHOULDER_RISE,
    B_TRUNK_TOP,
    B_UPPER_ARM,
    POSE_EXT,
)

# How far a point of the worker can move per unit change of prone_fraction, in units of the worker's radius
# (C_RHO): the trunk's effective forward flexion by pi/2 and its lateral flexion by at most pi/2 (the limit), the
# legs' angle by pi/2, and their length by at most the worker's radius (kernels.sweep: _worker_travel).
PRONE_TRAVEL = 1.5 * np.pi + 1.0

REACH_SLACK = 2.0  # reach-field grid spacings added to the worker's radius (the field is interpolated)


@njit(cache=True, error_model="numpy")
def worker_radius(b, max_drop, reach_h):
    """A radius about the hip pivot (x, y, hip height plus the stance's drop) that holds every point of the
    worker, in every pose (``max_drop``: the highest the stance lifts the hip, 0 for the paper's worker): the
    legs hang from the pivot to the floor, the trunk, head and shoulders turn rigidly about it (``pose_body``),
    the arms hang or reach from the shoulders and the reach volumes lie within the arm's length of them (fences
    only shorten a reach); the reach field is a grid, so ``REACH_SLACK`` spacings are added for its
    interpolation."""
    hz, leg = b[B_HIP_Z] + max(max_drop, 0.0), b[B_LEG_HALF]
    shoulder = np.sqrt(b[B_SHOULDER_RISE] ** 2 + b[B_SHOULDER_HALF] ** 2)
    r_arm = max(b[B_R_ARM], b[B_R_UPPER], b[B_R_FORE], b[B_R_HAND])
    return max(np.sqrt(hz * hz + leg * leg) + b[B_R_LEG], b[B_TRUNK_TOP] + b[B_R_TRUNK], b[B_HEAD_RISE] + b[B_R_HEAD],
               shoulder + b[B_ARM_LEN] + r_arm) + REACH_SLACK * reach_h


@njit(cache=True, error_model="numpy")
def human_pose(P, pose, W):
    """Body capsules (W.ha, W.hb, W.hr), shoulders (W.sh) and trunk frame (W.tr, columns x, y, z) for a pose
    vector (layout.POSE_ROW's order: x, y, heading, forward and lateral flexion, drop, arm joints)."""
    pose_body(P.body, pose[0], pose[1], pose[2], pose[3], pose[4], pose, POSE_EXT, W.ha, W.hb, W.hr, W.sh, W.tr)


@njit(cache=True, error_model="numpy")
def pose_capsules(P, poses, W, A, B, R):
    """The body capsules of each pose vector poses[i] into A[i], B[i] (axes) and R[i] (radii): (n, n_caps, ...)."""
    n_caps = A.shape[1]
    for i in range(poses.shape[0]):
        human_pose(P, poses[i], W)
        for c in range(n_caps):
            R[i, c] = W.hr[c]
            for r in range(3):
                A[i, c, r], B[i, c, r] = W.ha[c, r], W.hb[c, r]


@njit(cache=True, error_model="numpy", inline="always")
def prone_fraction(hip_z):
    """How far the articulated worker's body has tipped forward towards lying prone (0: not at all, 1: prone)
    for its hip at ``hip_z`` [m]: 0 from PRONE_BEGIN_Z up, 1 at PRONE_HIP_Z (to PRONE_TOL), linear between, so
    every point moves continuously as the stance changes (the swept test's bound relies on it)."""
    if hip_z >= PRONE_BEGIN_Z:
        return 0.0
    if hip_z <= PRONE_HIP_Z + PRONE_TOL:
        return 1.0
    return (PRONE_BEGIN_Z - hip_z) / (PRONE_BEGIN_Z - PRONE_HIP_Z)


@njit(cache=True, error_model="numpy", inline="always")
def pose_body(b, x, y, heading, fwd, lat, ext, e0, ha, hb, hr, sh, tr):
    """human_pose on the arrays themselves (the hot path: see the module docstring). ``ext[e0]`` is the hip's
    drop and ``ext[e0 + 1 + 5 k + j]`` arm k's joint j; the paper's worker (BODY_PARAMS MODEL 0) reads neither.

    The articulated worker with its hip below PRONE_BEGIN_Z tips forward (``prone_fraction`` s): the trunk's
    flexion goes to 90 degrees and its lateral flexion to 0 by s, the legs turn backwards about the hip by s 90
    degrees and stretch to their standing length; prone (s = 1) the trunk and head lie along the floor at the
    hip's height PRONE_HIP_Z = R_TRUNK, the legs behind, the arms posed from the shoulders as ever."""
    articulated = b[B_MODEL] != 0.0
    hz = b[B_HIP_Z]
    s = 0.0
    if articulated:
        hz += ext[e0]
        s = prone_fraction(hz)
        if s > 0.0:
            fwd = fwd + s * (0.5 * np.pi - fwd)
            lat = lat * (1.0 - s)
    ch, shh = np.cos(heading), np.sin(heading)
    cf, sf = np.cos(fwd), np.sin(fwd)
    cl, sl = np.cos(lat), np.sin(lat)
    # trunk axes in body coordinates (forward, left, up), then in the world
    xb0, xb1, xb2 = cf, 0.0, -sf
    zb0, zb1, zb2 = sf * cl, sl, cf * cl
    yb0, yb1, yb2 = zb1 * xb2 - zb2 * xb1, zb2 * xb0 - zb0 * xb2, zb0 * xb1 - zb1 * xb0
    tr[0, 0], tr[1, 0], tr[2, 0] = xb0 * ch - xb1 * shh, xb0 * shh + xb1 * ch, xb2
    tr[0, 1], tr[1, 1], tr[2, 1] = yb0 * ch - yb1 * shh, yb0 * shh + yb1 * ch, yb2
    tr[0, 2], tr[1, 2], tr[2, 2] = zb0 * ch - zb1 * shh, zb0 * shh + zb1 * ch, zb2
    lx, ly = -shh, ch  # body left in the world
    # legs
    for k in range(2):
        sgn = 1.0 if k == 0 else -1.0
        ha[k, 0], ha[k, 1], ha[k, 2] = x + sgn * b[B_LEG_HALF] * lx, y + sgn * b[B_LEG_HALF] * ly, hz
        hb[k, 0], hb[k, 1], hb[k, 2] = ha[k, 0], ha[k, 1], b[B_R_LEG]
        hr[k] = b[B_R_LEG]
        if s > 0.0:  # tipping forward: the leg turns back about the hip, not below the floor
            th = 0.5 * np.pi * s
            length = (hz - b[B_R_LEG]) * (1.0 - s) + (b[B_HIP_Z] - b[B_R_LEG]) * s
            back = length * np.sin(th)
            hb[k, 0], hb[k, 1] = ha[k, 0] - back * ch, ha[k, 1] - back * shh
            hb[k, 2] = max(hz - length * np.cos(th), b[B_R_LEG])
    # trunk and head
    ha[2, 0], ha[2, 1], ha[2, 2] = x, y, hz
    for r in range(3):
        hb[2, r] = ha[2, r] + b[B_TRUNK_TOP] * tr[r, 2]
        ha[3, r] = ha[2, r] + b[B_HEAD_RISE] * tr[r, 2]
        hb[3, r] = ha[3, r]
    hr[2] = b[B_R_TRUNK]
    hr[3] = b[B_R_HEAD]
    # shoulders and hanging arms (left = 0, right = 1)
    for k in range(2):
        sgn = 1.0 if k == 0 else -1.0
        for r in range(3):
            sh[k, r] = ha[2, r] + b[B_SHOULDER_RISE] * tr[r, 2] + sgn * b[B_SHOULDER_HALF] * tr[r, 1]
            ha[4 + k, r] = sh[k, r]
            hb[4 + k, r] = sh[k, r]
        if articulated:
            pose_arm(b, ext, e0 + 1 + 5 * k, k, sh, tr, ha, hb, hr)
        else:
            low = sh[k, 2] - (b[B_ARM_LEN] - b[B_R_ARM])
            hb[4 + k, 2] = low if low > b[B_R_ARM] else b[B_R_ARM]
            hr[4 + k] = b[B_R_ARM]


@njit(cache=True, error_model="numpy", inline="always")
def arm_chain(q0, q1, q2, q3, q4, l1, l2, l3):
    """Elbow, wrist and fingertip of the right arm in the shoulder frame (x forward, y left, z up along the
    trunk) for joint angles q [rad]: ``human.reach.arm_points``'s kinematics, written out in scalars so that the
    step allocates nothing. The upper arm's frame is Rx(-q1) Ry(-q0) Rz(q2); elbow and wrist turn it by Ry(-q3)
    and Ry(-q4); each segment points along its frame's -z."""
    c0, s0, c1, s1, c2, s2 = np.cos(q0), np.sin(q0), np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2)
    # columns x (u0) and z (u2) of the upper arm's frame
    u0x, u0y, u0z = c0 * c2, c1 * s2 + s1 * s0 * c2, -s1 * s2 + c1 * s0 * c2
    u2x, u2y, u2z = -s0, s1 * c0, c1 * c0
    c3, s3 = np.cos(q3), np.sin(q3)
    f0x, f0y, f0z = c3 * u0x + s3 * u2x, c3 * u0y + s3 * u2y, c3 * u0z + s3 * u2z
    f2x, f2y, f2z = -s3 * u0x + c3 * u2x, -s3 * u0y + c3 * u2y, -s3 * u0z + c3 * u2z
    c4, s4 = np.cos(q4), np.sin(q4)
    h2x, h2y, h2z = -s4 * f0x + c4 * f2x, -s4 * f0y + c4 * f2y, -s4 * f0z + c4 * f2z
    ex, ey, ez = -l1 * u2x, -l1 * u2y, -l1 * u2z
    wx, wy, wz = ex - l2 * f2x, ey - l2 * f2y, ez - l2 * f2z
    return ex, ey, ez, wx, wy, wz, wx - l3 * h2x, wy - l3 * h2y, wz - l3 * h2z


@njit(cache=True, error_model="numpy", inline="always")
def _to_world(sh, tr, k, lx, ly, lz, out, i):
    """Point (lx, ly, lz) of arm k's shoulder frame (the left arm mirrors y) into out[i]."""
    if k == 0:
        ly = -ly
    for r in range(3):
        out[i, r] = sh[k, r] + lx * tr[r, 0] + ly * tr[r, 1] + lz * tr[r, 2]


@njit(cache=True, error_model="numpy", inline="always")
def pose_arm(b, ext, j0, k, sh, tr, ha, hb, hr):
    """Arm k of the articulated worker (joints ext[j0:j0 + 5]): capsules upper arm 4 + k, forearm 6 + k and
    hand 8 + k. The hand's capsule ends its radius short of the fingertip, so its surface reaches the tip."""
    r_hand = b[B_R_HAND]
    ex, ey, ez, wx, wy, wz, tx, ty, tz = arm_chain(ext[j0], ext[j0 + 1], ext[j0 + 2], ext[j0 + 3], ext[j0 + 4],
                                                   b[B_UPPER_ARM], b[B_FOREARM], b[B_HAND] - r_hand)
    _to_world(sh, tr, k, ex, ey, ez, hb, 4 + k)
    _to_world(sh, tr, k, ex, ey, ez, ha, 6 + k)
    _to_world(sh, tr, k, wx, wy, wz, hb, 6 + k)
    _to_world(sh, tr, k, wx, wy, wz, ha, 8 + k)
    _to_world(sh, tr, k, tx, ty, tz, hb, 8 + k)
    hr[4 + k] = b[B_R_UPPER]
    hr[6 + k] = b[B_R_FORE]
    hr[8 + k] = r_hand
