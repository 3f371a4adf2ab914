"""One time step: move the worker, sense (devices latch a stop), pose the robot, measure (the worker's own
motion and distances without the robot, for searchers that plan with it, are in ``kernels.worker``).

The lifecycle follows dm_control's composer: move the worker -> sense -> move the robot -> measure. The step
(step_action, sense_and_measure and the non-inlined helpers they call) allocates nothing and is compiled
without reference counting (``geometry.NO_REFCOUNT``).
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.human.body import CRAWL_SPEED
from cellstress.sim.geometry import NO_REFCOUNT
from cellstress.sim.kernels.body import pose_body
from cellstress.sim.kernels.doors import door_signals, muted, note_push, place_doors, push_doors, unlock_doors
from cellstress.sim.kernels.fences import collect_near_fences
from cellstress.sim.kernels.robot import live_path_time, other_robots, robot_at
from cellstress.sim.kernels.scaling import command, commands_due
from cellstress.sim.kernels.sensing import body_blocked, device_sees, feet_ok, is_prone, path_blocked
from cellstress.sim.kernels.separation import separation
from cellstress.sim.kernels.sweep import sweep_step
from cellstress.sim.layout import (
    A_DIR,
    A_DROP,
    A_FWD,
    A_HANG,
    A_LAT,
    A_Q0,
    A_SET_ARMS,
    A_SET_STANCE,
    A_SET_TRUNK,
    A_TURN,
    A_WALK,
    B_ARM_LEN,
    B_BODY_RADIUS,
    B_MODEL,
    B_N_CAPS,
    B_WALK_SPEED,
    C_ANY_MOTION,
    C_DT,
    C_DTOL,
    C_PHASE0,
    C_REACH_H,
    C_REACH_ORIGIN,
    C_STOP_DELAY,
    C_SWEEP,
    C_VTOL,
    DEV_DOOR,
    M_ACTION,
    M_DROP,
    M_FWD,
    M_HEADING,
    M_LAT,
    M_LINK,
    M_PHASE,
    M_ROBOT,
    M_SEEN,
    M_STEP,
    M_SWEPT,
    M_T,
    M_TAU,
    M_TC,
    M_UNSAFE,
    M_V,
    M_X,
    M_XPHASE,
    M_XTAU,
    M_Y,
    MAX_DOORS,
    MAX_ROBOTS,
    NO_WALK_BELOW,
    NS,
    PHASE_STOPPED,
    S_A_SIG,
    S_A_T,
    S_A_TAU,
    S_A_TGT,
    S_ACTIONS,
    S_ARM,
    S_D_SEP,
    S_DOOR_OPEN,
    S_DOOR_REQ,
    S_DROP,
    S_FWD,
    S_HEADING,
    S_K,
    S_LAT,
    S_LIVE,
    S_RESTARTS,
    S_SEP_LOW,
    S_SEP_LOW_S,
    S_SEP_LOW_T,
    S_SEP_ON,
    S_SEP_Q0,
    S_SLOW,
    S_SLOW_CLEAR,
    S_SLOW_SEEN,
    S_STOP_CLEAR,
    S_STOP_SEEN,
    S_TRIG_DEV,
    S_TRIG_T,
    S_TSLOW,
    S_TSTOP,
    S_UNSAFE,
    S_X,
    S_XTSTOP,
    S_Y,
    SEP_QUEUE,
)


# Not inlined: it is called from three entry points, and numba's IR inlining of this much nested code made a
# cold compile take 5 minutes instead of under 2 (for about 5 % of run time on baseline).
@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def sense_and_measure(P, state, W, row, action):
    """At the state's time: devices latch stops, the robot is posed, d_HR and v_R are measured."""
    dt = P.scal[C_DT]
    k = state[S_K]
    t = k * dt
    ha, hb, hr, sh, tr = W.ha, W.hb, W.hr, W.sh, W.tr
    pose_body(P.body, state[S_X], state[S_Y], state[S_HEADING], state[S_FWD], state[S_LAT], state, S_DROP,
              ha, hb, hr, sh, tr)
    seen = 0
    dev_kind, dev_rect, dev_poly, dev_verts, body = P.dev_kind, P.dev_rect, P.dev_poly, P.dev_verts, P.body
    for d in range(dev_kind.shape[0]):
        if muted(P, d, t):
            continue
        if door_signals(P, state, d, t) if dev_kind[d] == DEV_DOOR else \
                device_sees(dev_kind, dev_rect, dev_poly, dev_verts, body, d, ha, hb, hr):
            seen |= 1 << d
            if P.dev_speed[d] > 0.0:  # a warning field: a speed reduction, latched like a stop
                sense_warning(P, state, d, t)
            elif P.dev_speed[d] == 0.0:  # (a separation channel latches nothing: it commands below)
                sense_stop(P, state, d, t)
    commands_due(P, state, int(k))
    release(P, state, t)
    unlock_doors(P, state, t)
    place_doors(P, state, W.fences, t)
    n_near = collect_near_fences(W.fences, sh, W.near, P.body[B_ARM_LEN] + 0.05)
    v, phase, tau = robot_at(P, int(k), state, W)
    nx = P.x_scal.shape[0]
    if nx > 0:
        other_robots(P, np.int64(k), state, W)
    command(P, state, seen, int(k), W.ra, W.rb)  # a separation channel, if any (robot 0 posed at t)
    cap_r, reach, origin, grid_h, arm_len, fences = P.cap_r, P.reach, P.scal[C_REACH_ORIGIN], P.scal[C_REACH_H], \
        P.body[B_ARM_LEN], W.fences
    ra, rb, near, lbs, ts, q = W.ra, W.rb, W.near, W.lbs, W.ts, W.best_r
    # One inlined copy of separation: a second, fence-free copy (n_near the constant 0) cost ~8 s of a cold
    # compile for no measurable speed (the fence code is skipped by a branch on n_near either way).
    d_hr = separation(cap_r, reach, origin, grid_h, arm_len, fences, near, ra, rb, sh, tr, ha, hb, hr, lbs, ts, q,
                      n_near, row, int(P.body[B_N_CAPS]))
    # v_R is the speed of the robot that owns the nearest capsule: the contact criterion and the reward judge
    # the robot the worker is nearest (docs/architecture.md, several robots)
    link = int(row[M_LINK])
    owner = -1 if link < 0 else P.cap_robot[link]
    if owner > 0:
        v = W.xv[owner - 1]
    if P.scal[C_ANY_MOTION] != 0.0:  # (verify's arrival-window model: any robot that is not standing)
        moving = (phase if owner <= 0 else W.xphase[owner - 1]) != PHASE_STOPPED
    else:
        moving = v > P.scal[C_VTOL]
    unsafe = d_hr <= P.scal[C_DTOL] and moving
    row[M_ROBOT] = owner
    for r in range(MAX_ROBOTS - 1):
        row[M_XTAU + r] = W.xtau[r] if r < nx else -1.0  # (not NaN: rows are compared with array_equal)
        row[M_XPHASE + r] = W.xphase[r] if r < nx else -1.0
    row[M_T] = t
    row[M_X], row[M_Y], row[M_HEADING] = state[S_X], state[S_Y], state[S_HEADING]
    row[M_FWD], row[M_LAT] = state[S_FWD], state[S_LAT]
    for i in range(11):
        row[M_DROP + i] = state[S_DROP + i]
    row[M_V] = v
    row[M_SEEN] = seen
    row[M_PHASE] = phase
    row[M_UNSAFE] = 1.0 if unsafe else 0.0
    row[M_TC] = t if d_hr <= P.scal[C_DTOL] else -1.0
    row[M_SWEPT] = 0.0
    state[S_D_SEP] = d_hr  # where the swept test of the next step starts (not clipped: kernels.sweep)
    row[M_TAU] = tau
    row[M_ACTION] = action
    row[M_STEP] = k
    if unsafe:
        state[S_UNSAFE] = 1.0
    return unsafe


@njit(cache=True, error_model="numpy", inline="always")
def sense_stop(P, state, d, t):
    """Device d sees the worker at t: a stop is latched, taking effect after its response time and the robot's
    controller delay (when braking begins; an earlier one replaces a later one), for each robot the device stops
    (robot 0 below; robots 1.. their own TSTOP and delay)."""
    t_sig = t + P.dev_resp[d]
    mask = P.dev_robots[d]
    for r in range(P.x_scal.shape[0]):
        t_r = t_sig + P.x_scal[r, C_STOP_DELAY]
        if mask >> (r + 1) & 1 and t_r < state[S_XTSTOP + r]:
            state[S_XTSTOP + r] = t_r
    if not mask & 1:
        return
    t_s = t_sig + P.scal[C_STOP_DELAY]
    # the clear time a latched stop waits for: its first device's, then the longest of those that see
    state[S_STOP_CLEAR] = P.dev_clear[d] if state[S_TSTOP] == np.inf else max(state[S_STOP_CLEAR], P.dev_clear[d])
    if t_s < state[S_TSTOP]:
        state[S_TSTOP] = t_s
        if state[S_TRIG_DEV] < 0:
            state[S_TRIG_T] = t
        state[S_TRIG_DEV] = d
    state[S_STOP_SEEN] = t


@njit(cache=True, error_model="numpy")
def latch_seen(P, state, seen, t):
    """What ``sense_and_measure`` does to the state at t when the devices in the bit mask ``seen`` see the worker:
    the latches and the releases, without moving or measuring anything (``Simulator`` replays a cut action's
    rows with it)."""
    for d in range(P.dev_kind.shape[0]):
        if seen >> d & 1:
            if P.dev_kind[d] == DEV_DOOR:
                note_push(P, state, d, t)
            if P.dev_speed[d] > 0.0:
                sense_warning(P, state, d, t)
            elif P.dev_speed[d] == 0.0:
                sense_stop(P, state, d, t)
    release(P, state, t)
    unlock_doors(P, state, t)


@njit(cache=True, error_model="numpy", inline="always")
def sense_warning(P, state, d, t):
    """Warning field d sees the worker at t: its speed reduction is latched (the first one's fraction holds
    until it is released), taking effect after the response time and the controller's delay; the robot leaves the
    plain path model."""
    t_w = t + P.dev_resp[d] + P.scal[C_STOP_DELAY]
    if state[S_TSLOW] == np.inf:
        state[S_SLOW] = P.dev_speed[d]
        state[S_SLOW_CLEAR] = P.dev_clear[d]
    else:
        state[S_SLOW_CLEAR] = max(state[S_SLOW_CLEAR], P.dev_clear[d])
    if t_w < state[S_TSLOW]:
        state[S_TSLOW] = t_w
    state[S_LIVE] = 1.0
    state[S_SLOW_SEEN] = t


@njit(cache=True, error_model="numpy", inline="always")
def release(P, state, t):
    """Automatic restart: a latched stop (or speed reduction) is released at t once no device that latched it
    has seen the worker for the longest clear time among them (never if one of them restarts manually: its
    clear time is inf). The path is re-anchored there, in closed form, and ramps back up to full speed (or to
    the reduced speed, if a reduction is in effect); a later detection latches anew."""
    if state[S_TSTOP] < np.inf and t - state[S_STOP_SEEN] >= state[S_STOP_CLEAR]:
        _reanchor(P, state, t, min(state[S_SEP_ON], state[S_SLOW] if state[S_TSLOW] <= t else 1.0))
        state[S_TSTOP] = np.inf
        state[S_STOP_CLEAR] = np.inf
        state[S_RESTARTS] += 1.0
    if state[S_TSLOW] < np.inf and t - state[S_SLOW_SEEN] >= state[S_SLOW_CLEAR]:
        _reanchor(P, state, t, 0.0 if state[S_TSTOP] <= t else state[S_SEP_ON])
        state[S_TSLOW] = np.inf
        state[S_SLOW_CLEAR] = np.inf


@njit(cache=True, error_model="numpy", inline="always")
def _reanchor(P, state, t, target):
    state[S_LIVE] = 1.0  # (the anchor of reset is the plain model's path: phase + t, braking from TSTOP)
    tau, sig, _ = live_path_time(P.scal, state, t)
    state[S_A_T], state[S_A_TAU], state[S_A_SIG], state[S_A_TGT] = t, tau - P.scal[C_PHASE0], sig, target


@njit(cache=True, error_model="numpy")
def reset_state(P, x, y, heading, state, W, row):
    state[:] = 0.0
    state[S_X], state[S_Y], state[S_HEADING] = x, y, heading
    state[S_TSTOP] = np.inf
    state[S_TRIG_DEV] = -1.0
    state[S_TRIG_T] = -1.0
    # the safeguards' slots: the anchor of the plain path (phase + t), nothing latched, nothing seen
    state[S_A_SIG] = state[S_A_TGT] = 1.0
    state[S_TSLOW] = np.inf
    state[S_SLOW] = 1.0
    state[S_STOP_SEEN] = state[S_SLOW_SEEN] = -1.0
    state[S_STOP_CLEAR] = state[S_SLOW_CLEAR] = np.inf  # nothing to release (a stop set by hand holds, as before)
    for i in range(MAX_DOORS):  # every door closed, none pushed
        state[S_DOOR_REQ + i] = state[S_DOOR_OPEN + i] = np.inf
    for r in range(MAX_ROBOTS - 1):
        state[S_XTSTOP + r] = np.inf
    state[S_SEP_ON] = state[S_SEP_LOW] = 1.0  # full speed, no command in flight
    for i in range(SEP_QUEUE):
        state[S_SEP_Q0 + i] = -1.0  # none in flight (not NaN: states are compared with ==)
    state[S_SEP_LOW_T] = state[S_SEP_LOW_S] = -1.0
    sense_and_measure(P, state, W, row, np.int64(-1))  # not a literal: see batch.py


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def step_action(P, state, action, W, out, row0):
    """Play one action (P.spa time steps) from ``state`` in place; rows go to out[row0:]. Returns rows written.

    Stops early at the first unsafe step. A state that is already unsafe does not move.
    """
    if state[S_UNSAFE] != 0.0:
        return 0
    spa = P.spa
    h0, f0, l0 = state[S_HEADING], state[S_FWD], state[S_LAT]
    begin_action(P, state, W)
    n = 0
    sweep = P.scal[C_SWEEP] != 0.0
    prev = W.prev
    for j in range(1, spa + 1):
        if sweep:
            for i in range(NS):
                prev[i] = state[i]
        move_worker(P, state, action, h0, f0, l0, j / spa, W)
        state[S_K] += 1.0
        unsafe = sense_and_measure(P, state, W, out[row0 + n], action)
        if sweep and not unsafe:
            unsafe = sweep_step(P, prev, state, W, out[row0 + n])
        n += 1
        if unsafe:
            break
    state[S_ACTIONS] += 1.0
    return n


@njit(cache=True, error_model="numpy", inline="always")
def begin_action(P, state, W):
    """Keep the articulated worker's stance and arm joints as the action begins (move_worker moves from them)."""
    if P.body[B_MODEL] != 0.0:
        for i in range(11):
            W.ext0[i] = state[S_DROP + i]


@njit(cache=True, error_model="numpy", inline="always")
def move_worker(P, state, action, h0, f0, l0, frac, W):
    """The worker's own motion over one time step of ``action`` (begun at heading h0 and posture f0, l0, and
    for the articulated worker the stance and arms in W.ext0): ``frac`` of the action done. It depends on the
    actions and the fixed layout only, never on the robot, except through a door with guard locking (it opens
    once the robot is at rest: ``doors.unlock_doors``)."""
    act = P.act
    walks = act[action, A_WALK]
    body, fences, floor, obs_verts, obs_poly, obs_box = P.body, W.fences, P.floor, P.obs_verts, P.obs_poly, P.obs_box
    ha, hb, hr, sh, tr = W.ha, W.hb, W.hr, W.sh, W.tr
    articulated = body[B_MODEL] != 0.0
    x, y = state[S_X], state[S_Y]
    t = state[S_K] * P.scal[C_DT]
    place_doors(P, state, fences, t)
    h = h0 + act[action, A_TURN] * frac
    f_to = act[action, A_FWD] if act[action, A_SET_TRUNK] != 0.0 else f0
    l_to = act[action, A_LAT] if act[action, A_SET_TRUNK] != 0.0 else l0
    f = f0 + (f_to - f0) * frac
    lt = l0 + (l_to - l0) * frac
    ext = W.ext1
    if articulated:
        blend_limbs(act, action, W.ext0, state, f, 1.0 / P.spa, ext)
    prone = articulated and is_prone(body, state[S_DROP])
    speed = min(CRAWL_SPEED, body[B_WALK_SPEED]) if prone else body[B_WALK_SPEED]
    if articulated and state[S_DROP] < NO_WALK_BELOW and not prone:
        walks = 0.0  # crouched or kneeling: the feet stay (prone, the worker crawls)
    nx, ny = x, y
    if walks != 0.0:
        stride = speed * P.scal[C_DT] * walks
        nx, ny = x + stride * np.cos(h + act[action, A_DIR]), y + stride * np.sin(h + act[action, A_DIR])
        if not feet_ok(body[B_BODY_RADIUS], floor, obs_verts, obs_poly, fences, nx, ny, prone):
            # walking into a closed door pushes it (at the time of the step being taken)
            push_doors(P, state, body[B_BODY_RADIUS], nx, ny, t + P.scal[C_DT])
            nx, ny = x, y
    # If the new pose would put a body part through a fence (or the articulated worker's arm into an obstacle),
    # the articulated worker first holds the arm that is in the way where it was; then either keeps the old
    # posture where it stands; if that fails too, stays put. (A loop, so that pose_body and body_blocked are
    # inlined once: each copy cost seconds of a cold compile, in step_action and worker_paths alike.) The
    # articulated worker's motion is checked along the way, not only where it ends (path_blocked).
    final = False
    for attempt in range(3):
        if articulated and final and nx == x and ny == y:
            break  # the pose the worker is in: nothing to check
        if articulated:
            blocked = path_blocked(body, fences, obs_verts, obs_poly, obs_box, state, nx, ny, h, f, lt, ext, W)
        else:
            pose_body(body, nx, ny, h, f, lt, ext, 0, ha, hb, hr, sh, tr)
            blocked = body_blocked(body, fences, obs_verts, obs_poly, obs_box, ha, hb, hr)
        if blocked == 0:
            break
        if final:
            nx, ny = x, y
            break
        if attempt == 0 and articulated and blocked >> 4 != 0:
            for k in range(2):
                if (blocked >> (4 + k) | blocked >> (6 + k) | blocked >> (8 + k)) & 1:
                    for j in range(5):
                        ext[1 + 5 * k + j] = state[S_ARM + 5 * k + j]
            continue
        h, f, lt = state[S_HEADING], state[S_FWD], state[S_LAT]
        if articulated:
            for i in range(11):
                ext[i] = state[S_DROP + i]
        final = True
    state[S_X], state[S_Y], state[S_HEADING], state[S_FWD], state[S_LAT] = nx, ny, h, f, lt
    if articulated:
        for i in range(11):
            state[S_DROP + i] = ext[i]


@njit(cache=True, error_model="numpy", inline="always")
def blend_limbs(act, action, ext0, state, fwd, per_step, ext):
    """The articulated worker's stance and arm joints one time step on towards the action's targets: each from
    where it is (the state) by ``per_step`` of the way from where the action began (ext0) to its target, so an
    arm that was held moves on from where it was held, at its speed; a target the action does not set stays
    where it was; hanging arms follow the trunk's flexion ``fwd``."""
    set_arms = act[action, A_SET_ARMS] != 0.0
    for i in range(11):
        if i == 0:
            to = act[action, A_DROP] if act[action, A_SET_STANCE] != 0.0 else ext0[0]
        else:
            to = act[action, A_Q0 + (i - 1) % 5] if set_arms else ext0[i]
            if set_arms and (i - 1) % 5 == 0 and act[action, A_HANG] != 0.0:
                to = fwd
        cur = state[S_DROP + i]
        rate = abs(to - ext0[i]) * per_step
        if i > 0 and set_arms and (i - 1) % 5 == 0 and act[action, A_HANG] != 0.0:
            rate = max(rate, abs(fwd - state[S_FWD]))  # keep up with the trunk it hangs from
        gap = to - cur
        ext[i] = to if abs(gap) <= rate * (1.0 + 1e-12) else cur + (rate if gap > 0.0 else -rate)
