"""The compiled simulator: one time step of worker, devices and robot, and whole episodes in batches.

Everything here is numba-compiled and works on ``SimParams`` (a named tuple of arrays built once per cell by
``sim.build``) and a state vector of ``NS`` floats. The step lifecycle follows dm_control's composer:
move the worker -> sense (devices latch a stop) -> move the robot -> measure.

The robot is a pure function of time and of the moment its stop takes effect: its path time advances one
second per second until the stop, then slows linearly to a standstill within the stopping time, so
tau(t) = t_s + d - d^2 / (2 T) for d = t - t_s < T. Nothing is integrated, so nothing drifts.

Speed: numba reference-counts arrays, and passing a tuple of arrays (SimParams, Work) into an inlined function
increments and decrements every member, atomically. On the hot path that bookkeeping once took two thirds of
the run time. So the inlined helpers take the arrays they read (and scalars, and index rows element-wise
rather than slicing views); only the entry points take SimParams and Work. The step itself (step_action,
sense_and_measure and the non-inlined helpers they call) allocates nothing and is compiled without
reference counting at all (``geometry.NO_REFCOUNT``); only run_batch, which allocates, keeps it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange
from numba.typed import List

from cellstress.sim.geometry import (
    NO_REFCOUNT,
    point_segment_2d,
    polygon_distance,
    segment_rectangle_xyz,
    segment_segment_xyz,
)

# ---- state vector -----------------------------------------------------------------------------------------
S_K, S_X, S_Y, S_HEADING, S_FWD, S_LAT, S_TSTOP, S_TRIG_DEV, S_TRIG_T, S_UNSAFE, S_ACTIONS = range(11)
NS = 11

# ---- metric row (one per time step) -----------------------------------------------------------------------
(M_T, M_X, M_Y, M_HEADING, M_FWD, M_LAT, M_D, M_V, M_SEEN, M_PHASE, M_LINK, M_PART,
 M_RX, M_RY, M_RZ, M_HX, M_HY, M_HZ, M_UNSAFE, M_TAU, M_ACTION, M_STEP) = range(22)
NM = 22

# stop phases
PHASE_RUNNING, PHASE_PENDING, PHASE_BRAKING, PHASE_STOPPED = 0, 1, 2, 3

# scalar parameters (P.scal)
(C_DT, C_STOP_TIME, C_PHASE0, C_CYCLE, C_DWELL, C_DTOL, C_VTOL, C_REACH_ORIGIN, C_REACH_H) = range(9)
N_SCAL = 9

# body parameter indices (mirror cellstress.human.body)
B_HIP_Z, B_SHOULDER_RISE, B_SHOULDER_HALF, B_LEG_HALF, B_HEAD_RISE, B_TRUNK_TOP = range(6)
B_R_LEG, B_R_TRUNK, B_R_HEAD, B_R_ARM, B_ARM_LEN, B_BODY_RADIUS, B_WALK_SPEED = range(6, 13)
N_BODY_CAPSULES = 6
PART_LEFT_REACH, PART_RIGHT_REACH = 6, 7

DEV_SCANNER, DEV_CURTAIN = 0, 1
BATCH_CHUNK = 32  # episodes per work-array set in run_batch
TRACE_REL_TOL = 0.05  # far from contact, d_HR needs only relative accuracy (it feeds a smooth reward)
WALK_BLOCK_HEIGHT = 0.5  # a panel whose bottom is above this does not stop walking


class SimParams(NamedTuple):
    scal: np.ndarray  # (N_SCAL,)
    spa: int  # steps per action
    act: np.ndarray  # (n_actions, 4): walks, heading change, target forward / lateral flexion
    body: np.ndarray  # body parameters
    base: np.ndarray  # (4, 4) robot base in the world
    parents: np.ndarray  # (nj,) int64
    placements: np.ndarray  # (nj, 4, 4)
    axes: np.ndarray  # (nj, 3)
    anc: np.ndarray  # (nj, nj) float: 1 where column joint moves row joint's origin
    wp: np.ndarray  # (nw, nj) waypoints
    seg_start: np.ndarray  # (nw,)
    seg_move: np.ndarray  # (nw,)
    cap_joint: np.ndarray  # (nc,) int64, -1 = base
    cap_a: np.ndarray  # (nc, 3)
    cap_b: np.ndarray  # (nc, 3)
    cap_r: np.ndarray  # (nc,)
    reach: np.ndarray  # (n, n, n) float32 signed distance
    fences: np.ndarray  # (nf, 6) x0 y0 x1 y1 zlo zhi
    table_verts: np.ndarray  # (V, 2)
    table_poly: np.ndarray  # (T, 2) int64 start, count
    floor: np.ndarray  # (4,) xmin xmax ymin ymax
    dev_kind: np.ndarray  # (nd,) int64
    dev_resp: np.ndarray  # (nd,)
    dev_rect: np.ndarray  # (nd, 6) curtain rectangle; for scanners [4] holds the scan height
    dev_poly: np.ndarray  # (nd, 2) int64 start, count into dev_verts
    dev_verts: np.ndarray  # (V, 2)
    pre_ra: np.ndarray  # (n_pre, nc, 3) robot capsules at step k before any stop (a cache: see robot_at)
    pre_rb: np.ndarray
    pre_v: np.ndarray  # (n_pre,) v_R
    pre_tau: np.ndarray  # (n_pre,) path time


class Work(NamedTuple):
    q: np.ndarray
    qd: np.ndarray
    rot: np.ndarray
    pos: np.ndarray
    ra: np.ndarray
    rb: np.ndarray
    ha: np.ndarray
    hb: np.ndarray
    hr: np.ndarray
    sh: np.ndarray
    tr: np.ndarray
    near: np.ndarray
    best_r: np.ndarray
    lbs: np.ndarray
    ts: np.ndarray
    stopped: np.ndarray  # (2,) t_stop, v_R of the standstill pose held in ra/rb, or NaN (see robot_at)


@njit(cache=True, error_model="numpy")
def make_work(P):
    nj = P.placements.shape[0]
    nc = P.cap_r.shape[0]
    return Work(
        np.zeros(nj), np.zeros(nj), np.zeros((nj, 3, 3)), np.zeros((nj, 3)),
        np.zeros((nc, 3)), np.zeros((nc, 3)),
        np.zeros((N_BODY_CAPSULES, 3)), np.zeros((N_BODY_CAPSULES, 3)), np.zeros(N_BODY_CAPSULES),
        np.zeros((2, 3)), np.zeros((3, 3)), np.zeros(P.fences.shape[0] + 1, dtype=np.int64),
        np.zeros(3),
        np.zeros(2 * nc), np.zeros(2 * nc), np.full(2, np.nan),
    )


# ---- robot ------------------------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy", inline="always")
def path_time(scal, t, t_stop):
    """(path time tau, time-scaling sigma = dtau/dt, stop phase) at time t for a stop effective at t_stop."""
    T = scal[C_STOP_TIME]
    tau0 = scal[C_PHASE0]
    if not t_stop < np.inf:
        return tau0 + t, 1.0, PHASE_RUNNING
    if t < t_stop:
        return tau0 + t, 1.0, PHASE_PENDING
    d = t - t_stop
    if d >= T:
        return tau0 + t_stop + 0.5 * T, 0.0, PHASE_STOPPED
    return tau0 + t_stop + d - d * d / (2.0 * T), 1.0 - d / T, PHASE_BRAKING


@njit(cache=True, error_model="numpy", inline="always")
def _joint_trajectory(scal, seg_start, seg_move, wp, tau, sigma, q, qd):
    """Joint positions and velocities on the cyclic minimum-jerk path at path time tau."""
    cycle = scal[C_CYCLE]
    dwell = scal[C_DWELL]
    tc = tau - cycle * np.floor(tau / cycle)
    nw = seg_start.shape[0]
    i = nw - 1
    for k in range(1, nw):
        if tc < seg_start[k]:
            i = k - 1
            break
    j = i + 1 if i + 1 < nw else 0
    T = seg_move[i]
    u = (tc - seg_start[i] - dwell) / T
    nj = q.shape[0]
    if u <= 0.0:
        for k in range(nj):
            q[k] = wp[i, k]
            qd[k] = 0.0
        return
    if u > 1.0:
        u = 1.0
    s = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
    ds = 30.0 * u * u * (1.0 - u) * (1.0 - u) / T * sigma
    for k in range(nj):
        dq = wp[j, k] - wp[i, k]
        q[k] = wp[i, k] + s * dq
        qd[k] = ds * dq


@njit(cache=True, error_model="numpy", inline="always")
def _forward_kinematics(parents, placements, base, axes, q, rot, pos):
    """World rotation and origin of every joint frame."""
    # (No temporary array and no row views: each would be allocated or reference-counted on every call.)
    nj = q.shape[0]
    for j in range(nj):
        par = parents[j]
        # parent frame in the world; its rotation part goes to rot[j] for now
        for r in range(3):
            for c in range(3):
                acc = 0.0
                for k in range(3):
                    pr = base[r, k] if par < 0 else rot[par, r, k]
                    acc += pr * placements[j, k, c]
                rot[j, r, c] = acc
        for r in range(3):
            acc = base[r, 3] if par < 0 else pos[par, r]
            for k in range(3):
                pr = base[r, k] if par < 0 else rot[par, r, k]
                acc += pr * placements[j, k, 3]
            pos[j, r] = acc
        # rotation about the joint axis (Rodrigues)
        kx, ky, kz = axes[j, 0], axes[j, 1], axes[j, 2]
        c, s = np.cos(q[j]), np.sin(q[j])
        v = 1.0 - c
        r00, r01, r02 = c + kx * kx * v, kx * ky * v - kz * s, kx * kz * v + ky * s
        r10, r11, r12 = ky * kx * v + kz * s, c + ky * ky * v, ky * kz * v - kx * s
        r20, r21, r22 = kz * kx * v - ky * s, kz * ky * v + kx * s, c + kz * kz * v
        for r in range(3):
            a0, a1, a2 = rot[j, r, 0], rot[j, r, 1], rot[j, r, 2]
            rot[j, r, 0] = a0 * r00 + a1 * r10 + a2 * r20
            rot[j, r, 1] = a0 * r01 + a1 * r11 + a2 * r21
            rot[j, r, 2] = a0 * r02 + a1 * r12 + a2 * r22


@njit(cache=True, error_model="numpy", inline="always")
def _fastest_joint_speed(anc, axes, qd, rot, pos):
    """v_R: the largest Cartesian speed of any joint origin (the paper's 'fastest robot joint')."""
    nj = qd.shape[0]
    best = 0.0
    for i in range(nj):
        vx = vy = vz = 0.0
        for j in range(i):
            if anc[i, j] == 0.0:
                continue
            wx = rot[j, 0, 0] * axes[j, 0] + rot[j, 0, 1] * axes[j, 1] + rot[j, 0, 2] * axes[j, 2]
            wy = rot[j, 1, 0] * axes[j, 0] + rot[j, 1, 1] * axes[j, 1] + rot[j, 1, 2] * axes[j, 2]
            wz = rot[j, 2, 0] * axes[j, 0] + rot[j, 2, 1] * axes[j, 1] + rot[j, 2, 2] * axes[j, 2]
            dx, dy, dz = pos[i, 0] - pos[j, 0], pos[i, 1] - pos[j, 1], pos[i, 2] - pos[j, 2]
            vx += qd[j] * (wy * dz - wz * dy)
            vy += qd[j] * (wz * dx - wx * dz)
            vz += qd[j] * (wx * dy - wy * dx)
        sp = np.sqrt(vx * vx + vy * vy + vz * vz)
        if sp > best:
            best = sp
    return best


@njit(cache=True, error_model="numpy", inline="always")
def _robot_capsules(cap_joint, cap_a, cap_b, base, rot, pos, ra, rb):
    for c in range(cap_joint.shape[0]):
        j = cap_joint[c]
        for r in range(3):
            ax = base[r, 3] if j < 0 else pos[j, r]
            bx = ax
            for k in range(3):
                m = base[r, k] if j < 0 else rot[j, r, k]
                ax += m * cap_a[c, k]
                bx += m * cap_b[c, k]
            ra[c, r] = ax
            rb[c, r] = bx


@njit(cache=True, error_model="numpy")
def robot_live(P, t, t_stop, W):
    """Pose the robot at time t: capsules into W.ra/W.rb. Returns (v_R, stop phase, path time)."""
    W.stopped[0] = np.nan
    return _robot_live(P.scal, P.seg_start, P.seg_move, P.wp, P.parents, P.placements, P.base, P.axes, P.anc,
                       P.cap_joint, P.cap_a, P.cap_b, W.q, W.qd, W.rot, W.pos, W.ra, W.rb, t, t_stop)


@njit(cache=True, error_model="numpy", inline="always")
def _robot_live(scal, seg_start, seg_move, wp, parents, placements, base, axes, anc, cap_joint, cap_a, cap_b,
                q, qd, rot, pos, ra, rb, t, t_stop):
    tau, sigma, phase = path_time(scal, t, t_stop)
    _joint_trajectory(scal, seg_start, seg_move, wp, tau, sigma, q, qd)
    _forward_kinematics(parents, placements, base, axes, q, rot, pos)
    _robot_capsules(cap_joint, cap_a, cap_b, base, rot, pos, ra, rb)
    return _fastest_joint_speed(anc, axes, qd, rot, pos), phase, tau


# The same with SimParams / Work, for callers outside the hot loop (tests, scene, the ISO check).
@njit(cache=True, error_model="numpy")
def joint_trajectory(P, tau, sigma, q, qd):
    _joint_trajectory(P.scal, P.seg_start, P.seg_move, P.wp, tau, sigma, q, qd)


@njit(cache=True, error_model="numpy")
def forward_kinematics(P, q, rot, pos):
    _forward_kinematics(P.parents, P.placements, P.base, P.axes, q, rot, pos)


@njit(cache=True, error_model="numpy")
def fastest_joint_speed(P, qd, rot, pos):
    return _fastest_joint_speed(P.anc, P.axes, qd, rot, pos)


@njit(cache=True, error_model="numpy")
def robot_capsules(P, rot, pos, ra, rb):
    _robot_capsules(P.cap_joint, P.cap_a, P.cap_b, P.base, rot, pos, ra, rb)


@njit(cache=True, error_model="numpy", inline="always")
def robot_at(P, k, t_stop, W):
    """The robot at step k. Until a stop takes effect every episode moves the robot identically, so those
    steps come from a table made once per cell by the same code (bit-identical to computing them). Once the
    robot stands, its pose no longer changes: W.stopped = (t_stop, v_R) marks that W.ra/W.rb hold the
    standstill pose for that stop (NaN: they do not)."""
    scal, ra, rb, stopped = P.scal, W.ra, W.rb, W.stopped
    t = k * scal[C_DT]
    pre_v = P.pre_v
    if t < t_stop and k < pre_v.shape[0]:
        pre_ra, pre_rb = P.pre_ra, P.pre_rb
        for c in range(ra.shape[0]):
            for r in range(3):
                ra[c, r] = pre_ra[k, c, r]
                rb[c, r] = pre_rb[k, c, r]
        stopped[0] = np.nan
        return pre_v[k], (PHASE_RUNNING if t_stop == np.inf else PHASE_PENDING), P.pre_tau[k]
    if stopped[0] == t_stop and t - t_stop >= scal[C_STOP_TIME]:
        tau, _, phase = path_time(scal, t, t_stop)
        return stopped[1], phase, tau
    v, phase, tau = _robot_live(scal, P.seg_start, P.seg_move, P.wp, P.parents, P.placements, P.base, P.axes,
                                P.anc, P.cap_joint, P.cap_a, P.cap_b, W.q, W.qd, W.rot, W.pos, ra, rb, t, t_stop)
    if phase == PHASE_STOPPED:
        stopped[0], stopped[1] = t_stop, v
    else:
        stopped[0] = np.nan
    return v, phase, tau


@njit(cache=True, error_model="numpy")
def robot_table(P, n, ra, rb, v, tau):
    """Fill the pre-stop robot table for steps 0..n-1."""
    W = make_work(P)
    for k in range(n):
        v[k], _, tau[k] = robot_live(P, k * P.scal[C_DT], np.inf, W)
        ra[k] = W.ra
        rb[k] = W.rb


# ---- human ------------------------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def human_pose(P, x, y, heading, fwd, lat, W):
    """Body capsules (W.ha, W.hb, W.hr), shoulders (W.sh) and trunk frame (W.tr, columns x, y, z)."""
    pose_body(P.body, x, y, heading, fwd, lat, W.ha, W.hb, W.hr, W.sh, W.tr)


@njit(cache=True, error_model="numpy", inline="always")
def pose_body(b, x, y, heading, fwd, lat, ha, hb, hr, sh, tr):
    """human_pose on the arrays themselves (the hot path: see the module docstring)."""
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
    hz = b[B_HIP_Z]
    lx, ly = -shh, ch  # body left in the world
    # legs
    for k in range(2):
        sgn = 1.0 if k == 0 else -1.0
        ha[k, 0], ha[k, 1], ha[k, 2] = x + sgn * b[B_LEG_HALF] * lx, y + sgn * b[B_LEG_HALF] * ly, hz
        hb[k, 0], hb[k, 1], hb[k, 2] = ha[k, 0], ha[k, 1], b[B_R_LEG]
        hr[k] = b[B_R_LEG]
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
        low = sh[k, 2] - (b[B_ARM_LEN] - b[B_R_ARM])
        hb[4 + k, 2] = low if low > b[B_R_ARM] else b[B_R_ARM]
        hr[4 + k] = b[B_R_ARM]


@njit(cache=True, error_model="numpy", inline="always")
def _grid_coord(c, origin, hi, h, n):
    """(clamped cell index, fraction, squared distance outside the grid) along one axis."""
    out2 = 0.0
    if c < origin:
        out2 = (origin - c) ** 2
        c = origin
    elif c > hi:
        out2 = (c - hi) ** 2
        c = hi
    g = (c - origin) / h
    i = int(g)
    if i > n - 2:
        i = n - 2
    return i, g - i, out2


@njit(cache=True, error_model="numpy", inline="always")
def reach_lookup(vals, origin, h, px, py, pz):
    """Trilinear signed distance at p (shoulder frame); beyond the grid, the distance to it is added."""
    n = vals.shape[0]
    hi = origin + (n - 1) * h
    i, fx, ex = _grid_coord(px, origin, hi, h, n)
    j, fy, ey = _grid_coord(py, origin, hi, h, n)
    k, fz, ez = _grid_coord(pz, origin, hi, h, n)
    c00 = vals[i, j, k] * (1 - fx) + vals[i + 1, j, k] * fx
    c10 = vals[i, j + 1, k] * (1 - fx) + vals[i + 1, j + 1, k] * fx
    c01 = vals[i, j, k + 1] * (1 - fx) + vals[i + 1, j, k + 1] * fx
    c11 = vals[i, j + 1, k + 1] * (1 - fx) + vals[i + 1, j + 1, k + 1] * fx
    c0 = c00 * (1 - fy) + c10 * fy
    c1 = c01 * (1 - fy) + c11 * fy
    return c0 * (1 - fz) + c1 * fz + np.sqrt(ex + ey + ez)


@njit(cache=True, error_model="numpy", inline="always")
def _edge_detour(sx, sy, sz, qx, qy, qz, ex, ey, ez, dx, dy, dz, length):
    """Shortest path s -> e -> q with e on the edge (ex, ey, ez) + t d, t in [0, length]; returns (len, t)."""
    ts = (sx - ex) * dx + (sy - ey) * dy + (sz - ez) * dz
    tq = (qx - ex) * dx + (qy - ey) * dy + (qz - ez) * dz
    rs = np.sqrt(max(0.0, (sx - ex) ** 2 + (sy - ey) ** 2 + (sz - ez) ** 2 - ts * ts))
    rq = np.sqrt(max(0.0, (qx - ex) ** 2 + (qy - ey) ** 2 + (qz - ez) ** 2 - tq * tq))
    t = ts if rs + rq <= 1e-12 else ts + (tq - ts) * rs / (rs + rq)
    t = 0.0 if t < 0.0 else (length if t > length else t)
    px, py, pz = ex + t * dx, ey + t * dy, ez + t * dz
    d1 = np.sqrt((sx - px) ** 2 + (sy - py) ** 2 + (sz - pz) ** 2)
    d2 = np.sqrt((qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2)
    return d1 + d2, t


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _path_clear(fences, near, n_near, ax, ay, az, bx, by, bz):
    """No near fence panel lies across the straight segment a-b."""
    return _blocking_panel(fences, near, n_near, ax, ay, az, bx, by, bz) < 0


@njit(cache=True, error_model="numpy", inline="always")
def _panel_across(fences, i, ax, ay, az, bx, by, bz):
    """Fence panel i lies across the straight segment a-b."""
    ux, uy = fences[i, 2] - fences[i, 0], fences[i, 3] - fences[i, 1]
    nx, ny = -uy, ux
    sa = (ax - fences[i, 0]) * nx + (ay - fences[i, 1]) * ny
    sb = (bx - fences[i, 0]) * nx + (by - fences[i, 1]) * ny
    if sa * sb >= 0.0:
        return False
    t = sa / (sa - sb)
    cx, cy, cz = ax + t * (bx - ax), ay + t * (by - ay), az + t * (bz - az)
    u = ((cx - fences[i, 0]) * ux + (cy - fences[i, 1]) * uy) / (ux * ux + uy * uy)
    return 0.0 <= u <= 1.0 and fences[i, 4] <= cz <= fences[i, 5]


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _blocking_panel(fences, near, n_near, ax, ay, az, bx, by, bz):
    """The index into ``near`` of the first near fence panel across the straight segment a-b, or -1."""
    for m in range(n_near):
        if _panel_across(fences, near[m], ax, ay, az, bx, by, bz):
            return m
    return -1


@njit(cache=True, error_model="numpy", inline="always")
def _panel_edges(fences, i, sx, sy, sz, qx, qy, qz):
    """The shortest paths s -> e -> q over panel i's top edge and around its two end edges, as (length,
    position along the edge) each: (top, t_top, first end, t_first, second end, t_second)."""
    ux, uy = fences[i, 2] - fences[i, 0], fences[i, 3] - fences[i, 1]
    w = np.sqrt(ux * ux + uy * uy)
    ux /= w
    uy /= w
    top, t_top = _edge_detour(sx, sy, sz, qx, qy, qz, fences[i, 0], fences[i, 1], fences[i, 5], ux, uy, 0.0, w)
    height = fences[i, 5] - fences[i, 4]
    end0, t0 = _edge_detour(sx, sy, sz, qx, qy, qz, fences[i, 0], fences[i, 1], fences[i, 4], 0.0, 0.0, 1.0, height)
    end1, t1 = _edge_detour(sx, sy, sz, qx, qy, qz, fences[i, 2], fences[i, 3], fences[i, 4], 0.0, 0.0, 1.0, height)
    return top, t_top, end0, t0, end1, t1


@njit(cache=True, error_model="numpy", inline="always")
def _around_panel(fences, i, sx, sy, sz, qx, qy, qz, top, end0, end1):
    """A lower bound on any path from s to q that passes panel i, when the straight path crosses it, given
    the panel's edge detours ``top``, ``end0``, ``end1`` (``_panel_edges``).

    The path must cross the panel's plane outside the panel, and |s - c| + |c - q| over the plane is convex
    with its minimum inside the panel, so the shortest such crossing lies on the panel's border: the least
    of the four edge detours. The bottom edge counts only if s or q lies at or below it: otherwise a path
    below the panel would have to dip under the panel and come back up, and the segment from such a crossing
    to the straight path's crossing enters the panel through an end edge or the top, at no greater length."""
    lb = min(top, end0, end1)
    if fences[i, 4] < min(sz, qz):
        return lb
    ux, uy = fences[i, 2] - fences[i, 0], fences[i, 3] - fences[i, 1]
    w = np.sqrt(ux * ux + uy * uy)
    return min(lb, _edge_detour(sx, sy, sz, qx, qy, qz, fences[i, 0], fences[i, 1], fences[i, 4], ux / w, uy / w,
                                0.0, w)[0])


@njit(cache=True, error_model="numpy", inline="always")
def _detour_and_bound(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff):
    """(fence_detour's length, a lower bound of it that moves by at most |dq| with q).

    The bound is |s - q| where nothing is in the way, else the largest ``_around_panel`` of the panels in
    the way (every way round must pass each of them). Each term is 1-Lipschitz in q, and a panel's term
    equals |s - q| where q's straight path starts or stops crossing it (at the panel's border), so the bound
    is continuous and 1-Lipschitz except where q itself passes through a panel, where it can drop."""
    around = -1.0
    first = -1  # the first panel in the way: its edge detours are reused below
    first_edges = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for m in range(n_near):
        if _panel_across(fences, near[m], sx, sy, sz, qx, qy, qz):
            e = _panel_edges(fences, near[m], sx, sy, sz, qx, qy, qz)
            a = _around_panel(fences, near[m], sx, sy, sz, qx, qy, qz, e[0], e[2], e[4])
            around = a if a > around else around
            if first < 0:
                first = m
                first_edges = e
    if around < 0.0:
        d = np.sqrt((sx - qx) ** 2 + (sy - qy) ** 2 + (sz - qz) ** 2)
        return d, d
    if cutoff < np.inf and around - 1e-9 >= cutoff:
        return cutoff, around
    best = cutoff
    nudge = 0.01  # step the bend point off the panel so the crossing tests are not degenerate
    for m in range(n_near):
        i = near[m]
        ux, uy = fences[i, 2] - fences[i, 0], fences[i, 3] - fences[i, 1]
        w = np.sqrt(ux * ux + uy * uy)
        ux /= w
        uy /= w
        if m == first:
            top, t_top, end0, t0, end1, t1 = first_edges
        else:
            top, t_top, end0, t0, end1, t1 = _panel_edges(fences, i, sx, sy, sz, qx, qy, qz)
        for edge in range(3):
            if edge == 0:  # top edge
                length, t = top, t_top
                ex, ey, ez = fences[i, 0] + t * ux, fences[i, 1] + t * uy, fences[i, 5] + nudge
            else:  # vertical end edges
                sgn = -1.0 if edge == 1 else 1.0
                bx = fences[i, 0] if edge == 1 else fences[i, 2]
                by = fences[i, 1] if edge == 1 else fences[i, 3]
                length, t = (end0, t0) if edge == 1 else (end1, t1)
                ex, ey, ez = bx + sgn * nudge * ux, by + sgn * nudge * uy, fences[i, 4] + t
            if (length < best and _path_clear(fences, near, n_near, sx, sy, sz, ex, ey, ez)
                    and _path_clear(fences, near, n_near, ex, ey, ez, qx, qy, qz)):
                best = length
    return best, around


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def fence_detour(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff=np.inf):
    """Length of the shortest arm path from shoulder s to q around the near fence panels, over their top
    edge or around their ends (inf if every such path is blocked); |s - q| when nothing is in the way.

    A finite ``cutoff`` says that any length from it up will do: the result is exact below it and ``cutoff``
    otherwise, and bends that are not shorter are not checked for crossings (most of the cost). If even the
    way around one of the panels in the way is that long, no bend is looked at."""
    return _detour_and_bound(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff)[0]


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def fence_detour_bound(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff):
    """``fence_detour`` and its 1-Lipschitz lower bound (see ``_detour_and_bound``)."""
    return _detour_and_bound(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff)


@njit(cache=True, error_model="numpy", inline="always")
def _reach_field(reach, origin, h, sh, tr, side, px, py, pz):
    """Signed distance from p to the reach volume of arm ``side`` (0 left, 1 right), fences ignored."""
    dx, dy, dz = px - sh[side, 0], py - sh[side, 1], pz - sh[side, 2]
    l0 = tr[0, 0] * dx + tr[1, 0] * dy + tr[2, 0] * dz
    ly = tr[0, 1] * dx + tr[1, 1] * dy + tr[2, 1] * dz
    l1 = -ly if side == 0 else ly
    l2 = tr[0, 2] * dx + tr[1, 2] * dy + tr[2, 2] * dz
    return reach_lookup(reach, origin, h, l0, l1, l2)


@njit(cache=True, error_model="numpy", inline="always")
def _fence_value(arm_len, fences, near, sh, side, n_near, f, px, py, pz, cutoff):
    """The reach value ``f`` raised where the near fence panels make the hand go the long way round; exact
    below ``cutoff``, and at least ``cutoff`` otherwise."""
    g = fence_detour(fences, near, n_near, sh[side, 0], sh[side, 1], sh[side, 2], px, py, pz,
                     cutoff + arm_len) - arm_len
    return g if g > f else f


@njit(cache=True, error_model="numpy", inline="always")
def _reach_value(reach, origin, h, arm_len, fences, near, sh, tr, side, n_near, px, py, pz):
    """Signed distance from p to the reach volume of arm ``side`` (0 left, 1 right), fences respected."""
    f = _reach_field(reach, origin, h, sh, tr, side, px, py, pz)
    if n_near > 0:
        f = _fence_value(arm_len, fences, near, sh, side, n_near, f, px, py, pz, np.inf)
    return f


@njit(cache=True, error_model="numpy")
def near_fences(P, W, margin):
    """Collect into W.near the fence panels within ``margin`` of either shoulder (plan view)."""
    return collect_near_fences(P.fences, W.sh, W.near, margin)


@njit(cache=True, error_model="numpy", inline="always")
def collect_near_fences(fences, sh, near, margin):
    n = 0
    for f in range(fences.shape[0]):
        x0, y0, x1, y1 = fences[f, 0], fences[f, 1], fences[f, 2], fences[f, 3]
        d0 = point_segment_2d(sh[0, 0], sh[0, 1], x0, y0, x1, y1)
        d1 = point_segment_2d(sh[1, 0], sh[1, 1], x0, y0, x1, y1)
        if d0 < margin or d1 < margin:
            near[n] = f
            n += 1
    return n


@njit(cache=True, error_model="numpy")
def reach_value(P, p, side, W, n_near):
    """Signed distance from point p to the reach volume of arm ``side`` at the pose in W (outside the hot loop)."""
    return _reach_value(P.reach, P.scal[C_REACH_ORIGIN], P.scal[C_REACH_H], P.body[B_ARM_LEN], P.fences, W.near,
                        W.sh, W.tr, side, n_near, p[0], p[1], p[2])


@njit(cache=True, error_model="numpy", inline="always")
def reach_to_segment(reach, origin, h, arm_len, fences, near, sh, tr, side, n_near,
                     ax, ay, az, bx, by, bz, r, bound, out_q):
    """min over the capsule axis ab of (reach distance - r), by sphere tracing the 1-Lipschitz field.

    Stops early once the rest of the segment cannot come below ``bound``. The minimum is found to within
    the field's grid spacing plus TRACE_REL_TOL of the distance. Writes the closest axis point to out_q.
    """
    L = np.sqrt((bx - ax) ** 2 + (by - ay) ** 2 + (bz - az) ** 2)
    best = np.inf
    t = 0.0
    # Does the axis pass through a near panel? (Not for a robot inside its fence; if it does, the detour's
    # bound may drop there faster than the axis moves, and the trace below does not lean on that bound.)
    through = n_near > 0 and _blocking_panel(fences, near, n_near, ax, ay, az, bx, by, bz) >= 0
    sx, sy, sz = sh[side, 0], sh[side, 1], sh[side, 2]
    while True:
        tt = t / L if L > 0.0 else 0.0
        px, py, pz = ax + tt * (bx - ax), ay + tt * (by - ay), az + tt * (bz - az)
        fl = _reach_field(reach, origin, h, sh, tr, side, px, py, pz)
        f = fl
        lb = fl
        # The fenced value is never below fl, so where fl >= best it cannot be a new best, and where
        # fl >= bound + r it cannot matter to the caller (which ignores results >= bound): skip the detour.
        # Nor does its exact value from bound + r + h up: it is no new best then, and the steps below use
        # only its lower bound there.
        if n_near > 0 and fl < best and fl < bound + r:
            g, g_lb = fence_detour_bound(fences, near, n_near, sx, sy, sz, px, py, pz, bound + r + h + arm_len)
            g -= arm_len
            g_lb -= arm_len
            f = g if g > f else f
            lb = g_lb if g_lb > lb else lb
        if f < best:
            best = f
            out_q[0], out_q[1], out_q[2] = px, py, pz
        target = best if best < bound + r else bound + r
        slack = TRACE_REL_TOL * (target if target > 0.0 else 0.0)
        if fl >= target:
            # The fenceless field is 1-Lipschitz and never above the fenced value, so it bounds the rest of
            # the axis from below: no point within this step can undercut min(best, bound) by more than h + slack.
            step = fl - target + h + slack
        else:
            # A panel holds the hand back here (fl < target <= f). The fenced value jumps where the hand's
            # way round changes, so walk in strides of at most 2 h, as on its own it would need; but the
            # detour's lower bound is 1-Lipschitz along an axis that does not pass through a panel, so where
            # that bound is far above the target the stride can be as long as it is.
            step = f - target + h + slack
            if step > 2.0 * h:
                step = 2.0 * h
            if not through:
                long_step = lb - target + h + slack
                if long_step > step:
                    step = long_step
        if t >= L or fl - (L - t) - r >= bound:
            break
        t += step
        if t > L:
            t = L
    return best - r


# ---- sensing ----------------------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy", inline="always")
def device_sees(dev_kind, dev_rect, dev_poly, dev_verts, body, d, ha, hb, hr):
    """Does device d detect the worker: a body capsule (legs, trunk, head, arms at rest) in its region?

    The reach volumes are not seen: they stand for where an arm *could* strike, and the worst-case worker
    keeps the arm back until it can. ISO 13855's reach allowance C covers exactly this.
    """
    if dev_kind[d] == DEV_SCANNER:
        H = dev_rect[d, 4]
        start, count = dev_poly[d, 0], dev_poly[d, 1]
        for c in range(N_BODY_CAPSULES):
            a0, a1, a2, b0, b1, b2, r = ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2], hr[c]
            lo, hi = min(a2, b2), max(a2, b2)
            if H < lo - r or H > hi + r:
                continue
            if b2 == a2:
                t = 0.0
            else:
                t = (H - a2) / (b2 - a2)
                t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
            px, py, pz = a0 + t * (b0 - a0), a1 + t * (b1 - a1), a2 + t * (b2 - a2)
            dz = abs(pz - H)
            if dz > r:
                continue
            if polygon_distance(px, py, dev_verts, start, count) <= np.sqrt(r * r - dz * dz):
                return True
    else:
        x0, y0, x1, y1, zlo, zhi = dev_rect[d, 0], dev_rect[d, 1], dev_rect[d, 2], dev_rect[d, 3], \
            dev_rect[d, 4], dev_rect[d, 5]
        # no body capsule is further than this from the hip axis in plan view
        extent = body[B_SHOULDER_HALF] + body[B_R_TRUNK] + body[B_HEAD_RISE]
        if point_segment_2d(ha[2, 0], ha[2, 1], x0, y0, x1, y1) > extent:
            return False
        for c in range(N_BODY_CAPSULES):
            if segment_rectangle_xyz(ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2],
                                     x0, y0, x1, y1, zlo, zhi)[0] <= hr[c]:
                return True
    return False


# ---- walking and posture limits ---------------------------------------------------------------------------
@njit(cache=True, error_model="numpy", inline="always")
def feet_ok(r, fl, table_verts, table_poly, fences, x, y):
    """The footprint circle (radius r) stays on the floor, off the table and clear of fence panels."""
    if x - r < fl[0] or x + r > fl[1] or y - r < fl[2] or y + r > fl[3]:
        return False
    for t in range(table_poly.shape[0]):
        if polygon_distance(x, y, table_verts, table_poly[t, 0], table_poly[t, 1]) < r:
            return False
    for f in range(fences.shape[0]):
        if fences[f, 4] < WALK_BLOCK_HEIGHT and \
                point_segment_2d(x, y, fences[f, 0], fences[f, 1], fences[f, 2], fences[f, 3]) < r:
            return False
    return True


@njit(cache=True, error_model="numpy", inline="always")
def trunk_clear(body, fences, ha, hb, hr):
    """Trunk, head and arms (from the shoulders down) do not pass through any fence panel.

    The shoulders matter most: the reach volumes hang on them, so a shoulder past a panel would reach
    around it for free. (Where the hands can get past a panel is limited separately, by fence_detour.)
    """
    extent = body[B_HEAD_RISE] + body[B_R_HEAD] + body[B_SHOULDER_HALF]
    for f in range(fences.shape[0]):
        x0, y0, x1, y1, zlo, zhi = fences[f, 0], fences[f, 1], fences[f, 2], fences[f, 3], fences[f, 4], fences[f, 5]
        if point_segment_2d(ha[2, 0], ha[2, 1], x0, y0, x1, y1) > extent:
            continue
        for c in (2, 3, 4, 5):
            if segment_rectangle_xyz(ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2],
                                     x0, y0, x1, y1, zlo, zhi)[0] < hr[c]:
                return False
    return True


# ---- measuring --------------------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy", inline="always")
def _set_reach_hit(row, q):
    row[M_RX], row[M_RY], row[M_RZ] = q[0], q[1], q[2]


@njit(cache=True, error_model="numpy", inline="always")
def separation(cap_r, reach, origin, grid_h, arm_len, fences, near, ra, rb, sh, tr, ha, hb, hr, lbs, ts, q,
               n_near, row):
    """d_HR: minimum distance between the robot capsules and the body capsules or reach volumes.

    Reach volumes first, nearest (capsule, arm) pair first: they usually hold the minimum, and the bound
    they give lets most body-capsule pairs be skipped after a one-line test. Writes distance,
    closest robot capsule, body part and both points into the metric row.
    """
    # (Hot loop: index arrays element-wise; slicing a row would create a reference-counted view each time.)
    best = np.inf
    best_cap = -1
    best_part = -1
    nc = cap_r.shape[0]
    # Reach volumes lie inside the arm-length ball around their shoulder, so |p - s| - L bounds the distance
    # from below. Visit (capsule, arm) pairs from the smallest bound up; stop when the bound passes the best.
    L = arm_len + 2.0 * grid_h
    for c in range(nc):
        abx, aby, abz = rb[c, 0] - ra[c, 0], rb[c, 1] - ra[c, 1], rb[c, 2] - ra[c, 2]
        ll = abx * abx + aby * aby + abz * abz
        for side in range(2):
            sx, sy, sz = sh[side, 0] - ra[c, 0], sh[side, 1] - ra[c, 1], sh[side, 2] - ra[c, 2]
            t = 0.0 if ll <= 0.0 else (sx * abx + sy * aby + sz * abz) / ll
            t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
            px, py, pz = t * abx - sx, t * aby - sy, t * abz - sz
            lbs[2 * c + side] = np.sqrt(px * px + py * py + pz * pz) - cap_r[c] - L
            ts[2 * c + side] = t
    while True:
        m = -1
        lo = best
        for i in range(2 * nc):
            if lbs[i] < lo:
                lo = lbs[i]
                m = i
        if m < 0:
            break
        lbs[m] = np.inf
        c, side = m // 2, m % 2
        r = cap_r[c]
        t = ts[m]
        px, py, pz = ra[c, 0] + t * (rb[c, 0] - ra[c, 0]), ra[c, 1] + t * (rb[c, 1] - ra[c, 1]), \
            ra[c, 2] + t * (rb[c, 2] - ra[c, 2])
        f = _reach_field(reach, origin, grid_h, sh, tr, side, px, py, pz)
        if n_near > 0 and f - r < best:  # (the fenced value is never below f: else it cannot be a new best)
            # (cutoff h above the best: a stand-in value must not round below it and pass for a new best)
            f = _fence_value(arm_len, fences, near, sh, side, n_near, f, px, py, pz, best + r + grid_h)
        d = f - r
        if d < best:
            best, best_cap, best_part = d, c, PART_LEFT_REACH + side
            row[M_RX], row[M_RY], row[M_RZ] = px, py, pz
        # trace only the part of the axis within reach of undercutting the best: |p - s| < best + r + L
        R = best + r + L
        abx, aby, abz = rb[c, 0] - ra[c, 0], rb[c, 1] - ra[c, 1], rb[c, 2] - ra[c, 2]
        ll = abx * abx + aby * aby + abz * abz
        if ll <= 0.0:
            continue
        fx, fy, fz = ra[c, 0] - sh[side, 0], ra[c, 1] - sh[side, 1], ra[c, 2] - sh[side, 2]
        bq = fx * abx + fy * aby + fz * abz
        cq = fx * fx + fy * fy + fz * fz - R * R
        disc = bq * bq - ll * cq
        if disc <= 0.0:
            continue
        root = np.sqrt(disc)
        t0 = (-bq - root) / ll
        t1 = (-bq + root) / ll
        t0 = 0.0 if t0 < 0.0 else t0
        t1 = 1.0 if t1 > 1.0 else t1
        if t1 <= t0:
            continue
        d = reach_to_segment(reach, origin, grid_h, arm_len, fences, near, sh, tr, side, n_near,
                             ra[c, 0] + t0 * (rb[c, 0] - ra[c, 0]), ra[c, 1] + t0 * (rb[c, 1] - ra[c, 1]),
                             ra[c, 2] + t0 * (rb[c, 2] - ra[c, 2]), ra[c, 0] + t1 * (rb[c, 0] - ra[c, 0]),
                             ra[c, 1] + t1 * (rb[c, 1] - ra[c, 1]), ra[c, 2] + t1 * (rb[c, 2] - ra[c, 2]),
                             r, best, q)
        if d < best:
            best, best_cap, best_part = d, c, PART_LEFT_REACH + side
            _set_reach_hit(row, q)
    for c in range(nc):
        r = cap_r[c]
        mx, my, mz = 0.5 * (ra[c, 0] + rb[c, 0]), 0.5 * (ra[c, 1] + rb[c, 1]), 0.5 * (ra[c, 2] + rb[c, 2])
        half = 0.5 * np.sqrt((rb[c, 0] - ra[c, 0]) ** 2 + (rb[c, 1] - ra[c, 1]) ** 2 + (rb[c, 2] - ra[c, 2]) ** 2)
        for h in range(N_BODY_CAPSULES):
            hx, hy, hz = 0.5 * (ha[h, 0] + hb[h, 0]), 0.5 * (ha[h, 1] + hb[h, 1]), 0.5 * (ha[h, 2] + hb[h, 2])
            hh = 0.5 * np.sqrt((hb[h, 0] - ha[h, 0]) ** 2 + (hb[h, 1] - ha[h, 1]) ** 2
                               + (hb[h, 2] - ha[h, 2]) ** 2)
            lb = np.sqrt((mx - hx) ** 2 + (my - hy) ** 2 + (mz - hz) ** 2) - half - hh - r - hr[h]
            if lb >= best:
                continue
            d2, c1x, c1y, c1z, c2x, c2y, c2z = segment_segment_xyz(
                ra[c, 0], ra[c, 1], ra[c, 2], rb[c, 0], rb[c, 1], rb[c, 2],
                ha[h, 0], ha[h, 1], ha[h, 2], hb[h, 0], hb[h, 1], hb[h, 2])
            d = np.sqrt(d2) - r - hr[h]
            if d < best:
                best, best_cap, best_part = d, c, h
                row[M_RX], row[M_RY], row[M_RZ] = c1x, c1y, c1z
                row[M_HX], row[M_HY], row[M_HZ] = c2x, c2y, c2z
    # surface points: step from the axis points towards each other by the radii
    if best_part >= PART_LEFT_REACH:
        s = sh[best_part - PART_LEFT_REACH]
        dx, dy, dz = s[0] - row[M_RX], s[1] - row[M_RY], s[2] - row[M_RZ]
        n = np.sqrt(dx * dx + dy * dy + dz * dz)
        if n > 0:
            dx, dy, dz = dx / n, dy / n, dz / n
        r = cap_r[best_cap]
        row[M_RX], row[M_RY], row[M_RZ] = row[M_RX] + r * dx, row[M_RY] + r * dy, row[M_RZ] + r * dz
        g = best if best > 0.0 else 0.0
        row[M_HX], row[M_HY], row[M_HZ] = row[M_RX] + g * dx, row[M_RY] + g * dy, row[M_RZ] + g * dz
    elif best_part >= 0:
        dx, dy, dz = row[M_HX] - row[M_RX], row[M_HY] - row[M_RY], row[M_HZ] - row[M_RZ]
        n = np.sqrt(dx * dx + dy * dy + dz * dz)
        if n > 0:
            dx, dy, dz = dx / n, dy / n, dz / n
        r, hr = cap_r[best_cap], hr[best_part]
        row[M_RX], row[M_RY], row[M_RZ] = row[M_RX] + r * dx, row[M_RY] + r * dy, row[M_RZ] + r * dz
        row[M_HX], row[M_HY], row[M_HZ] = row[M_HX] - hr * dx, row[M_HY] - hr * dy, row[M_HZ] - hr * dz
    row[M_D] = best if best > 0.0 else 0.0
    row[M_LINK] = best_cap
    row[M_PART] = best_part
    return best


# Not inlined: it is called from three entry points, and numba's IR inlining of this much nested code made a
# cold compile take 5 minutes instead of under 2 (for about 5 % of run time on baseline).
@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def sense_and_measure(P, state, W, row, action):
    """At the state's time: devices latch stops, the robot is posed, d_HR and v_R are measured."""
    dt = P.scal[C_DT]
    k = state[S_K]
    t = k * dt
    ha, hb, hr, sh, tr = W.ha, W.hb, W.hr, W.sh, W.tr
    pose_body(P.body, state[S_X], state[S_Y], state[S_HEADING], state[S_FWD], state[S_LAT], ha, hb, hr, sh, tr)
    n_near = collect_near_fences(P.fences, sh, W.near, P.body[B_ARM_LEN] + 0.05)
    seen = 0
    dev_kind, dev_rect, dev_poly, dev_verts, body = P.dev_kind, P.dev_rect, P.dev_poly, P.dev_verts, P.body
    for d in range(dev_kind.shape[0]):
        if device_sees(dev_kind, dev_rect, dev_poly, dev_verts, body, d, ha, hb, hr):
            seen |= 1 << d
            t_s = t + P.dev_resp[d]
            if t_s < state[S_TSTOP]:
                state[S_TSTOP] = t_s
                if state[S_TRIG_DEV] < 0:
                    state[S_TRIG_T] = t
                state[S_TRIG_DEV] = d
    v, phase, tau = robot_at(P, int(k), state[S_TSTOP], W)
    cap_r, reach, origin, grid_h, arm_len, fences = P.cap_r, P.reach, P.scal[C_REACH_ORIGIN], P.scal[C_REACH_H], \
        P.body[B_ARM_LEN], P.fences
    ra, rb, near, lbs, ts, q = W.ra, W.rb, W.near, W.lbs, W.ts, W.best_r
    if n_near == 0:
        # the common case, compiled separately so that the fence-detour code drops out of it
        d_hr = separation(cap_r, reach, origin, grid_h, arm_len, fences, near, ra, rb, sh, tr, ha, hb, hr, lbs, ts, q,
                          0, row)
    else:
        d_hr = separation(cap_r, reach, origin, grid_h, arm_len, fences, near, ra, rb, sh, tr, ha, hb, hr, lbs, ts, q,
                          n_near, row)
    unsafe = d_hr <= P.scal[C_DTOL] and v > P.scal[C_VTOL]
    row[M_T] = t
    row[M_X], row[M_Y], row[M_HEADING] = state[S_X], state[S_Y], state[S_HEADING]
    row[M_FWD], row[M_LAT] = state[S_FWD], state[S_LAT]
    row[M_V] = v
    row[M_SEEN] = seen
    row[M_PHASE] = phase
    row[M_UNSAFE] = 1.0 if unsafe else 0.0
    row[M_TAU] = tau
    row[M_ACTION] = action
    row[M_STEP] = k
    if unsafe:
        state[S_UNSAFE] = 1.0
    return unsafe


@njit(cache=True, error_model="numpy")
def reset_state(P, x, y, heading, state, W, row):
    state[:] = 0.0
    state[S_X], state[S_Y], state[S_HEADING] = x, y, heading
    state[S_TSTOP] = np.inf
    state[S_TRIG_DEV] = -1.0
    state[S_TRIG_T] = -1.0
    sense_and_measure(P, state, W, row, -1)


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def step_action(P, state, action, W, out, row0):
    """Play one action (P.spa time steps) from ``state`` in place; rows go to out[row0:]. Returns rows written.

    Stops early at the first unsafe step. A state that is already unsafe does not move.
    """
    if state[S_UNSAFE] != 0.0:
        return 0
    spa = P.spa
    h0, f0, l0 = state[S_HEADING], state[S_FWD], state[S_LAT]
    n = 0
    for j in range(1, spa + 1):
        move_worker(P, state, action, h0, f0, l0, j / spa, W)
        state[S_K] += 1.0
        unsafe = sense_and_measure(P, state, W, out[row0 + n], action)
        n += 1
        if unsafe:
            break
    state[S_ACTIONS] += 1.0
    return n


@njit(cache=True, error_model="numpy", inline="always")
def move_worker(P, state, action, h0, f0, l0, frac, W):
    """The worker's own motion over one time step of ``action`` (begun at heading h0 and posture f0, l0):
    ``frac`` of the action done. It depends on the actions and the fixed layout only, never on the robot."""
    walks = P.act[action, 0]
    body, fences, floor, table_verts, table_poly = P.body, P.fences, P.floor, P.table_verts, P.table_poly
    ha, hb, hr, sh, tr = W.ha, W.hb, W.hr, W.sh, W.tr
    x, y = state[S_X], state[S_Y]
    h = h0 + P.act[action, 1] * frac
    f = f0 + (P.act[action, 2] - f0) * frac
    lt = l0 + (P.act[action, 3] - l0) * frac
    nx, ny = x, y
    if walks != 0.0:
        stride = body[B_WALK_SPEED] * P.scal[C_DT]
        nx, ny = x + stride * np.cos(h), y + stride * np.sin(h)
        if not feet_ok(body[B_BODY_RADIUS], floor, table_verts, table_poly, fences, nx, ny):
            nx, ny = x, y
    pose_body(body, nx, ny, h, f, lt, ha, hb, hr, sh, tr)
    if not trunk_clear(body, fences, ha, hb, hr):
        # the new posture would put the trunk through a fence: keep the old posture where it stands
        pose_body(body, nx, ny, state[S_HEADING], state[S_FWD], state[S_LAT], ha, hb, hr, sh, tr)
        if trunk_clear(body, fences, ha, hb, hr):
            h, f, lt = state[S_HEADING], state[S_FWD], state[S_LAT]
        else:
            nx, ny, h, f, lt = x, y, state[S_HEADING], state[S_FWD], state[S_LAT]
    state[S_X], state[S_Y], state[S_HEADING], state[S_FWD], state[S_LAT] = nx, ny, h, f, lt


@njit(cache=True, error_model="numpy")
def worker_paths(P, s0, actions, W, out):
    """The worker's poses (x, y, heading, forward, lateral flexion) at every time step of each episode of
    ``actions`` (n, n_actions) played from s0, as if no contact ended it: the open-loop part of the simulation
    (``move_worker``), without robot, devices or measuring. out: (n, n_actions * spa, 5)."""
    state = np.empty(NS)
    spa = P.spa
    for e in range(actions.shape[0]):
        state[:] = s0
        k = 0
        for a in range(actions.shape[1]):
            h0, f0, l0 = state[S_HEADING], state[S_FWD], state[S_LAT]
            for j in range(1, spa + 1):
                move_worker(P, state, actions[e, a], h0, f0, l0, j / spa, W)
                out[e, k, 0], out[e, k, 1], out[e, k, 2] = state[S_X], state[S_Y], state[S_HEADING]
                out[e, k, 3], out[e, k, 4] = state[S_FWD], state[S_LAT]
                k += 1


@njit(cache=True, error_model="numpy")
def worker_point_distances(P, W, poses, points, out):
    """out[i, j]: distance from the worker at poses[i] (x, y, heading, forward, lateral flexion) to the point
    points[i, j], as ``separation`` measures the worker's side of d_HR: the nearer of the two reach volumes
    (fences respected) and the body capsules; inf for a NaN point. The robot plays no part."""
    arm, origin, grid_h = P.body[B_ARM_LEN], P.scal[C_REACH_ORIGIN], P.scal[C_REACH_H]
    ha, hb, hr, sh, tr = W.ha, W.hb, W.hr, W.sh, W.tr
    for i in range(poses.shape[0]):
        pose_body(P.body, poses[i, 0], poses[i, 1], poses[i, 2], poses[i, 3], poses[i, 4], ha, hb, hr, sh, tr)
        n_near = collect_near_fences(P.fences, sh, W.near, arm + 0.05)
        for j in range(points.shape[1]):
            px, py, pz = points[i, j, 0], points[i, j, 1], points[i, j, 2]
            if np.isnan(px):
                out[i, j] = np.inf
                continue
            best = np.inf
            for side in range(2):
                best = min(best, _reach_value(P.reach, origin, grid_h, arm, P.fences, W.near, sh, tr, side, n_near,
                                              px, py, pz))
            for c in range(N_BODY_CAPSULES):
                d2 = segment_segment_xyz(ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2],
                                         px, py, pz, px, py, pz)[0]
                best = min(best, np.sqrt(d2) - hr[c])
            out[i, j] = best


# ---- whole episodes ---------------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def run_episode(P, s0, actions, out):
    """Play ``actions`` from s0; out[0] is the initial row. Returns the number of rows written."""
    W = make_work(P)
    state = s0.copy()
    sense_and_measure(P, state, W, out[0], -1)
    n = 1
    for a in range(actions.shape[0]):
        n += step_action(P, state, actions[a], W, out, n)
        if state[S_UNSAFE] != 0.0:
            break
    return n


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _batch_episode(P, s0, actions, e, W, state, rows, d_end, v_end, unsafe_step, min_d):
    """Episode e of run_batch, on the given work arrays."""
    n_act = actions.shape[1]
    for i in range(s0.shape[0]):
        state[i] = s0[i]
    unsafe_step[e] = -1
    lo = np.inf
    for k in range(n_act):
        n = step_action(P, state, actions[e, k], W, rows, 0)
        for i in range(n):
            if rows[i, M_D] < lo:
                lo = rows[i, M_D]
        d_end[e, k] = rows[n - 1, M_D]
        v_end[e, k] = rows[n - 1, M_V]
        if state[S_UNSAFE] != 0.0:
            unsafe_step[e] = int(state[S_K])
            for kk in range(k + 1, n_act):
                d_end[e, kk] = np.nan
                v_end[e, kk] = np.nan
            break
    min_d[e] = lo


@njit(cache=True, error_model="numpy", parallel=True)
def run_batch(P, s0, actions, d_end, v_end, unsafe_step, min_d):
    """Many episodes from the same s0. For episode e and action k: d_HR and v_R at the action's end
    (d_end[e, k], v_end[e, k]; NaN after an unsafe end), unsafe_step[e] the first unsafe time step or -1,
    min_d[e] the smallest d_HR seen."""
    n_ep, n_act = actions.shape
    spa = P.spa
    # Work arrays per chunk of episodes, not per episode: an episode's results do not depend on what the
    # arrays held before (Simulator.step reuses one set for every call), and allocating them costs ~3 %.
    n_chunks = (n_ep + BATCH_CHUNK - 1) // BATCH_CHUNK
    for chunk in prange(n_chunks):
        W = make_work(P)
        state = s0.copy()
        rows = np.empty((spa, NM))
        for e in range(chunk * BATCH_CHUNK, min(n_ep, (chunk + 1) * BATCH_CHUNK)):
            _batch_episode(P, s0, actions, e, W, state, rows, d_end, v_end, unsafe_step, min_d)


# ---- one action at a time from Python ---------------------------------------------------------------------
# Calling a compiled function types every argument: SimParams and Work hold about 50 arrays, which costs
# ~9 us per call, more than an action's physics. A typed list holding both is typed in one look-up.
@njit(cache=True)
def make_handle(P, W):
    h = List()
    h.append((P, W))
    return h


@njit(cache=True, error_model="numpy")
def step_with_handle(h, state, action, out):
    """step_action(P, state, action, W, out, 0) for the (P, W) in handle h."""
    P, W = h[0]
    return step_action(P, state, action, W, out, 0)
