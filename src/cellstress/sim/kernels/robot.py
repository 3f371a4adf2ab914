"""The robot: its cyclic path (minimum-jerk or linear moves), forward kinematics, capsules and speed, at any
time and stop.

The robot is a pure function of time and of the moment its stop takes effect: its path time advances one
second per second until the stop, then slows linearly to a standstill within the braking time, so
tau(t) = t_s + d - d^2 / (2 T) for d = t - t_s < T. Nothing is integrated, so nothing drifts. The stop takes
effect when braking begins: a controller's delay is added to the moment it is latched (``step.sense_stop``),
and a category 0 stop holds the pose where it took effect (``path_time``; docs/robot.md, Stopping).

With the safeguards of issue 18 (a stop released by an automatic restart, a warning field's speed reduction) the
time scaling sigma = dtau/dt is piecewise linear: from an anchor (a release's time, path time and sigma, kept in
the state) it ramps at 1 / T per second towards a target (1 after a restart, the reduced speed, 0 for a stop),
and the latched reduction and stop, when they take effect, lower the target. Every piece is integrated in closed
form (``live_path_time``), so the robot is still a pure function of the state and the time.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim.geometry import NO_REFCOUNT
from cellstress.sim.kernels.params import make_work
from cellstress.sim.layout import (
    C_CYCLE,
    C_DT,
    C_LINEAR,
    C_PHASE0,
    C_STOP_HOLD,
    C_STOP_TIME,
    JOINT_PRISMATIC,
    NS,
    PHASE_BRAKING,
    PHASE_PENDING,
    PHASE_REDUCED,
    PHASE_RUNNING,
    PHASE_STOPPED,
    S_A_SIG,
    S_A_T,
    S_A_TAU,
    S_A_TGT,
    S_LIVE,
    S_SEP_ON,
    S_SLOW,
    S_TSLOW,
    S_TSTOP,
    S_XTSTOP,
)


@njit(cache=True, error_model="numpy", inline="always")
def path_time(scal, t, t_stop):
    """(path time tau, time-scaling sigma = dtau/dt, stop phase) at time t for a stop effective at t_stop (the
    moment braking begins: the controller's delay is in t_stop). A category 0 stop (STOP_HOLD) holds the path
    time where it took effect, sigma still falling to 0 within T, so v_R is the speed there scaled down."""
    T = scal[C_STOP_TIME]
    tau0 = scal[C_PHASE0]
    if not t_stop < np.inf:
        return tau0 + t, 1.0, PHASE_RUNNING
    if t < t_stop:
        return tau0 + t, 1.0, PHASE_PENDING
    d = t - t_stop
    if scal[C_STOP_HOLD] != 0.0:  # category 0: posed where the stop took effect (docs/robot.md, Stopping)
        if d >= T:
            return tau0 + t_stop, 0.0, PHASE_STOPPED
        return tau0 + t_stop, 1.0 - d / T, PHASE_BRAKING
    if d >= T:
        return tau0 + t_stop + 0.5 * T, 0.0, PHASE_STOPPED
    return tau0 + t_stop + d - d * d / (2.0 * T), 1.0 - d / T, PHASE_BRAKING


@njit(cache=True, error_model="numpy", inline="always")
def _ramp(a_t, tau, sig, tgt, t, T):
    """(path time, sigma) at t >= a_t for sigma ramping from ``sig`` towards ``tgt`` at 1/T per second (the
    robot's braking rate: full speed to standstill in the stopping time T), then holding it."""
    d = t - a_t
    diff = tgt - sig
    if diff == 0.0:
        return tau + sig * d, sig
    dur = abs(diff) * T
    if d >= dur:
        return tau + 0.5 * (sig + tgt) * dur + tgt * (d - dur), tgt
    if diff > 0.0:
        return tau + sig * d + d * d / (2.0 * T), sig + d / T
    return tau + sig * d - d * d / (2.0 * T), sig - d / T


@njit(cache=True, error_model="numpy", inline="always")
def live_path_time(scal, state, t):
    """(path time, sigma, stop phase) at time t of a state whose robot left the plain model (``S_LIVE``): from
    the anchor, the latched reduction (target SLOW at TSLOW) and the latched stop (target 0 at TSTOP) in the
    order they take effect; an event at or before the anchor is already folded into its target."""
    T = scal[C_STOP_TIME]
    a_t, tau, sig, tgt = state[S_A_T], state[S_A_TAU], state[S_A_SIG], state[S_A_TGT]
    e1, g1 = state[S_TSLOW], state[S_SLOW]
    e2 = state[S_TSTOP]
    if not e1 > a_t:
        e1 = np.inf
    if not e2 > a_t:
        e2 = np.inf
    g2 = 0.0
    if e2 < e1:
        e1, g1, e2, g2 = e2, g2, e1, g1
    if e1 <= t:
        tau, sig = _ramp(a_t, tau, sig, tgt, e1, T)
        a_t, tgt = e1, min(tgt, g1)
        if e2 <= t:
            tau, sig = _ramp(a_t, tau, sig, tgt, e2, T)
            a_t, tgt = e2, min(tgt, g2)
    tau, sig = _ramp(a_t, tau, sig, tgt, t, T)
    t_stop = state[S_TSTOP]
    if t_stop <= t:
        phase = PHASE_BRAKING if sig > 0.0 else PHASE_STOPPED
    elif t_stop < np.inf:
        phase = PHASE_PENDING
    elif state[S_TSLOW] < np.inf or state[S_SEP_ON] < 1.0:  # (a separation command below full speed too)
        phase = PHASE_REDUCED
    else:
        phase = PHASE_RUNNING
    return scal[C_PHASE0] + tau, sig, phase


@njit(cache=True, error_model="numpy", inline="always")
def _segment(seg_start, tc):
    """The last segment i with seg_start[i] <= tc (seg_start[0] = 0): a binary search, as a trajectory file
    may have thousands of rows."""
    lo, hi = 0, seg_start.shape[0]
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if tc < seg_start[mid]:
            hi = mid
        else:
            lo = mid
    return lo


@njit(cache=True, error_model="numpy", inline="always")
def _joint_trajectory(scal, seg_start, seg_move, seg_dwell, wp, tau, sigma, q, qd):
    """Joint positions and velocities on the cyclic path at path time tau: segment i dwells at wp[i], then
    moves to the next row by a minimum-jerk or (C_LINEAR) a constant-speed move."""
    cycle = scal[C_CYCLE]
    tc = tau - cycle * np.floor(tau / cycle)
    nw = seg_start.shape[0]
    i = _segment(seg_start, tc)
    j = i + 1 if i + 1 < nw else 0
    T = seg_move[i]
    u = (tc - seg_start[i] - seg_dwell[i]) / T
    linear = scal[C_LINEAR] != 0.0
    nj = q.shape[0]
    # a linear move is under way at its first instant (u = 0): its rows carry no dwell
    if u < 0.0 or (u == 0.0 and not linear):
        for k in range(nj):
            q[k] = wp[i, k]
            qd[k] = 0.0
        return
    if u > 1.0:
        u = 1.0
    if linear:
        s = u
        ds = sigma / T
    else:
        s = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
        ds = 30.0 * u * u * (1.0 - u) * (1.0 - u) / T * sigma
    for k in range(nj):
        dq = wp[j, k] - wp[i, k]
        q[k] = wp[i, k] + s * dq
        qd[k] = ds * dq


@njit(cache=True, error_model="numpy", inline="always")
def _forward_kinematics(parents, placements, base, axes, jtype, q, rot, pos):
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
        kx, ky, kz = axes[j, 0], axes[j, 1], axes[j, 2]
        if jtype[j] == JOINT_PRISMATIC:  # a slide by q along the axis; the frame keeps its rotation
            for r in range(3):
                pos[j, r] += (rot[j, r, 0] * kx + rot[j, r, 1] * ky + rot[j, r, 2] * kz) * q[j]
            continue
        # rotation about the joint axis (Rodrigues)
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
def _fastest_joint_speed(anc, axes, jtype, qd, rot, pos):
    """v_R: the largest Cartesian speed of any joint origin (the paper's 'fastest robot joint')."""
    nj = qd.shape[0]
    best = 0.0
    for i in range(nj):
        vx = vy = vz = 0.0
        for j in range(i + 1):
            # a joint's own turning does not move its origin; its own sliding does
            if j == i and jtype[j] != JOINT_PRISMATIC:
                continue
            if j < i and anc[i, j] == 0.0:
                continue
            wx = rot[j, 0, 0] * axes[j, 0] + rot[j, 0, 1] * axes[j, 1] + rot[j, 0, 2] * axes[j, 2]
            wy = rot[j, 1, 0] * axes[j, 0] + rot[j, 1, 1] * axes[j, 1] + rot[j, 1, 2] * axes[j, 2]
            wz = rot[j, 2, 0] * axes[j, 0] + rot[j, 2, 1] * axes[j, 1] + rot[j, 2, 2] * axes[j, 2]
            if jtype[j] == JOINT_PRISMATIC:
                vx += qd[j] * wx
                vy += qd[j] * wy
                vz += qd[j] * wz
                continue
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
    tau, sigma, phase = path_time(P.scal, t, t_stop)
    v = _robot_live(P.scal, P.seg_start, P.seg_move, P.seg_dwell, P.wp, P.parents, P.placements, P.base,
                    P.axes, P.jtype, P.anc, P.cap_joint, P.cap_a, P.cap_b, W.q, W.qd, W.rot, W.pos, W.ra, W.rb,
                    tau, sigma)
    return v, phase, tau


# Not inlined: robot_live (the pre-stop table, pictures) and robot_at (the step, after a stop) share one
# compiled copy. It takes arrays only and allocates nothing (NO_REFCOUNT).
@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _robot_live(scal, seg_start, seg_move, seg_dwell, wp, parents, placements, base, axes, jtype, anc, cap_joint,
                cap_a, cap_b, q, qd, rot, pos, ra, rb, tau, sigma):
    _joint_trajectory(scal, seg_start, seg_move, seg_dwell, wp, tau, sigma, q, qd)
    _forward_kinematics(parents, placements, base, axes, jtype, q, rot, pos)
    _robot_capsules(cap_joint, cap_a, cap_b, base, rot, pos, ra, rb)
    return _fastest_joint_speed(anc, axes, jtype, qd, rot, pos)


# The same with SimParams / Work, for callers outside the hot loop (tests, scene, the ISO check).
@njit(cache=True, error_model="numpy")
def joint_trajectory(P, tau, sigma, q, qd):
    _joint_trajectory(P.scal, P.seg_start, P.seg_move, P.seg_dwell, P.wp, tau, sigma, q, qd)


@njit(cache=True, error_model="numpy")
def forward_kinematics(P, q, rot, pos):
    _forward_kinematics(P.parents, P.placements, P.base, P.axes, P.jtype, q, rot, pos)


@njit(cache=True, error_model="numpy")
def fastest_joint_speed(P, qd, rot, pos):
    return _fastest_joint_speed(P.anc, P.axes, P.jtype, qd, rot, pos)


@njit(cache=True, error_model="numpy")
def robot_capsules(P, rot, pos, ra, rb):
    _robot_capsules(P.cap_joint, P.cap_a, P.cap_b, P.base, rot, pos, ra, rb)


@njit(cache=True, error_model="numpy", inline="always")
def robot_at(P, k, state, W):
    """The robot at step k. Until a stop takes effect every episode moves the robot identically, so those
    steps come from a table made once per cell by the same code (bit-identical to computing them). Once the
    robot stands, its pose no longer changes: W.stopped = (t_stop, v_R) marks that W.ra/W.rb hold the
    standstill pose for that stop (NaN: they do not). A state that left the plain model (a released stop, a
    speed reduction: ``S_LIVE``) is posed live at every step, from ``live_path_time``."""
    scal, ra, rb, stopped = P.scal, W.ra, W.rb, W.stopped
    t = k * scal[C_DT]
    t_stop = state[S_TSTOP]
    if state[S_LIVE] != 0.0:
        stopped[0] = np.nan
        tau, sigma, phase = live_path_time(scal, state, t)
        v = _robot_live(scal, P.seg_start, P.seg_move, P.seg_dwell, P.wp, P.parents, P.placements, P.base, P.axes,
                        P.jtype, P.anc, P.cap_joint, P.cap_a, P.cap_b, W.q, W.qd, W.rot, W.pos, ra, rb, tau, sigma)
        return v, phase, tau
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
    tau, sigma, phase = path_time(scal, t, t_stop)
    v = _robot_live(scal, P.seg_start, P.seg_move, P.seg_dwell, P.wp, P.parents, P.placements, P.base, P.axes,
                    P.jtype, P.anc, P.cap_joint, P.cap_a, P.cap_b, W.q, W.qd, W.rot, W.pos, ra, rb, tau, sigma)
    if phase == PHASE_STOPPED:
        stopped[0], stopped[1] = t_stop, v
    else:
        stopped[0] = np.nan
    return v, phase, tau


# Not inlined, and called only when a cell has several robots: a one-robot step compiles and runs as before.
@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def other_robots(P, k, state, W):
    """Robots 1.. at step k: each one's capsules into its rows of W.ra/W.rb, its v_R, path time and stop phase
    into W.xv, W.xtau, W.xphase. Each follows ``path_time`` with its own stopping time, phase and latched stop
    (state[S_XTSTOP + r]); before that stop it comes from the pre-stop table, as robot 0 does."""
    ra, rb, xra, xrb = W.ra, W.rb, W.xra, W.xrb
    for r in range(P.x_scal.shape[0]):
        scal = P.x_scal[r]
        t = k * scal[C_DT]
        t_stop = state[S_XTSTOP + r]
        c0 = P.x_cap0[r]
        if t < t_stop and k < P.pre_xv.shape[0]:
            for c in range(c0, c0 + P.x_ncap[r]):
                for i in range(3):
                    ra[c, i] = P.pre_ra[k, c, i]
                    rb[c, i] = P.pre_rb[k, c, i]
            W.xv[r], W.xtau[r] = P.pre_xv[k, r], P.pre_xtau[k, r]
            W.xphase[r] = PHASE_RUNNING if t_stop == np.inf else PHASE_PENDING
            continue
        tau, sigma, phase = path_time(scal, t, t_stop)
        W.xv[r] = _robot_live(scal, P.x_seg_start[r], P.x_seg_move[r], P.x_seg_dwell[r], P.x_wp[r], P.x_parents[r],
                              P.x_placements[r], P.x_base[r], P.x_axes[r], P.x_jtype[r], P.x_anc[r],
                              P.x_cap_joint[r], P.x_cap_a[r], P.x_cap_b[r], W.xq, W.xqd, W.xrot, W.xpos, xra, xrb,
                              tau, sigma)
        W.xtau[r], W.xphase[r] = tau, phase
        for c in range(P.x_ncap[r]):
            for i in range(3):
                ra[c0 + c, i] = xra[c, i]
                rb[c0 + c, i] = xrb[c, i]


@njit(cache=True, error_model="numpy")
def robot_table(P, n, ra, rb, v, tau, xv, xtau):
    """Fill the pre-stop robot table for steps 0..n-1 (robots 1.. too, into xv and xtau)."""
    W = make_work(P)
    state = np.full(NS, np.inf)  # only the robots' stops are read: none latched
    nx = P.x_scal.shape[0]
    for k in range(n):
        v[k], _, tau[k] = robot_live(P, k * P.scal[C_DT], np.inf, W)
        if nx > 0:
            other_robots(P, np.int64(k), state, W)
            for r in range(nx):
                xv[k, r], xtau[k, r] = W.xv[r], W.xtau[r]
        ra[k] = W.ra
        rb[k] = W.rb
