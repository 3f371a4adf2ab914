"""Speed scaling from a measured separation (speed and separation monitoring, ISO/TS 15066:2016 5.5.4).

A channel whose ``dev_speed`` is ``layout.SEPARATION`` (its rule a row of ``dev_sep``) measures at every time
step the horizontal separation between the worker it sees and robot 0, and commands the speed fraction its
rule allows (full speed where it does not see the worker). Each step's command is queued in the state
(``SEP_Q*``, by step modulo ``SEP_QUEUE``) and takes effect at its measuring time plus the channel's response
time and the robot's controller delay: the path is re-anchored there, in closed form, towards the commanded
fraction, and its time scaling ramps to it at the robot's own braking rate (``robot.live_path_time``). The robot
stays a pure function of the state and the time; a cell without such a channel never enters here.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim.geometry import point_segment_2d
from cellstress.sim.kernels.robot import live_path_time
from cellstress.sim.layout import (
    B_BODY_RADIUS,
    C_DT,
    C_PHASE0,
    C_STOP_DELAY,
    S_A_SIG,
    S_A_T,
    S_A_TAU,
    S_A_TGT,
    S_LIVE,
    S_SEP_LOW,
    S_SEP_LOW_S,
    S_SEP_LOW_T,
    S_SEP_ON,
    S_SEP_Q0,
    S_SLOW,
    S_TSLOW,
    S_TSTOP,
    S_X,
    S_Y,
    SEP_QUEUE,
)


@njit(cache=True, error_model="numpy")
def commands_due(P, state, k):
    """Every queued command whose time came in (t - dt, t], t = k dt, takes effect, in the order measured: the
    path is re-anchored at its exact time towards its fraction (no higher than a latched stop or reduction
    allows then). A command equal to the one in effect changes nothing."""
    if P.dev_sep.shape[0] == 0:
        return
    dt = P.scal[C_DT]
    resp = P.dev_resp[int(P.dev_sep[0, 5])] + P.scal[C_STOP_DELAY]  # a command acts after the controller's delay
    t_prev, t = (k - 1) * dt, k * dt
    for j in range(max(0, k - SEP_QUEUE + 1), k):
        t_c = j * dt + resp
        f = state[S_SEP_Q0 + j % SEP_QUEUE]
        if not (t_prev < t_c <= t) or f < 0.0 or f == state[S_SEP_ON]:
            continue
        tgt = f
        if state[S_TSTOP] <= t_c:
            tgt = 0.0
        if state[S_TSLOW] <= t_c:
            tgt = min(tgt, state[S_SLOW])
        state[S_LIVE] = 1.0
        tau, sig, _ = live_path_time(P.scal, state, t_c)
        state[S_A_T], state[S_A_TAU], state[S_A_SIG], state[S_A_TGT] = t_c, tau - P.scal[C_PHASE0], sig, tgt
        state[S_SEP_ON] = f


@njit(cache=True, error_model="numpy", inline="always")
def worker_separation(P, state, ra, rb):
    """Horizontal separation [m] between the worker's footprint (a circle of the body radius at its position)
    and robot 0's capsules (their axes projected on the floor, less their radii); 0 if they overlap."""
    x, y = state[S_X], state[S_Y]
    best = np.inf
    for c in range(P.cap_r.shape[0]):
        if P.cap_robot[c] != 0:
            continue
        best = min(best, point_segment_2d(x, y, ra[c, 0], ra[c, 1], rb[c, 0], rb[c, 1]) - P.cap_r[c])
    return max(0.0, best - P.body[B_BODY_RADIUS])


@njit(cache=True, error_model="numpy", inline="always")
def fraction_for(rule, sep):
    """The largest fraction s in [0, 1] with v_h (T_r + T_s) + s v_max (T_r + T_s / 2) + allowance <= sep."""
    v_h, v_max, t_r, t_s, rest = rule[0], rule[1], rule[2], rule[3], rule[4]
    return min(1.0, max(0.0, (sep - v_h * (t_r + t_s) - rest) / (v_max * (t_r + t_s / 2.0))))


@njit(cache=True, error_model="numpy")
def command(P, state, seen, k, ra, rb):
    """After robot 0 is posed at step k: the separation channel measures and queues its command (full speed
    where it does not see the worker); the lowest command so far is noted with its time and separation."""
    if P.dev_sep.shape[0] == 0:
        return
    rule = P.dev_sep[0]
    sep, f = -1.0, 1.0
    if seen >> int(rule[5]) & 1:
        sep = worker_separation(P, state, ra, rb)
        f = fraction_for(rule, sep)
    state[S_SEP_Q0 + k % SEP_QUEUE] = f
    if f < state[S_SEP_LOW]:
        state[S_SEP_LOW], state[S_SEP_LOW_T], state[S_SEP_LOW_S] = f, k * P.scal[C_DT], sep
