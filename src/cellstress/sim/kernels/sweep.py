"""Contact in continuous time: between two time steps the worker moves along the straight line between its two
sampled poses (position, heading, flexions, stance and arm joints, each linearly) and the robot along its path,
and a contact anywhere in between counts.

The test on a step (t0, t1] starts from d_HR at both ends (``S_D_SEP``: separation's value, not clipped at 0).
Over a part [a, b] of the step nothing comes nearer than

    LB = ((d_a - h) + (d_b - h)) / (2 (1 + TRACE_REL_TOL)) - sqrt(3) (W_H + W_R) / 2

where W_H bounds how far any point of the worker moves over [a, b] (its pivot's travel plus, for every turn and
flexion, the angle times the worker's radius ``C_RHO``, and for the articulated worker the stance's drop and each
arm joint's angle times the arm's length), W_R how far any point of a robot capsule moves (its speed bound per
second of path time, ``SimParams.cap_speed``, times the path time the robot advances), sqrt(3) the largest slope
of the reach field (a trilinear interpolant of a distance transform), and h the reach field's spacing and
TRACE_REL_TOL what separation's tracing of a reach volume may overshoot the true minimum by. A part whose LB is
above the contact distance has no contact; one where every robot stands at both ends has no contact with a moving
robot. Any other part is halved: d_HR at its middle, the worker posed there and the robot at that moment's path
time (under the latches of the step's start: a latch the step's end makes takes effect later; a separation command
or release re-anchors at its own moment, ``_path_time``). A contact found so counts like one at a step, with its
own time (``M_TC``). After ``SWEEP_DEPTH`` halvings (1/32 of a step) a part that still cannot be cleared is tested
on certified lower bounds instead of separation's values (``_certified``: body capsules exactly, each reach volume
by its field on pieces of the capsule's axis at most ``CERT_STEP`` long, at each piece's middle less sqrt(3) times
half the piece, whole runs of pieces bounded at once where they cannot undercut the rest), halved ``SWEEP_CERTIFIED``
times more; what still cannot be cleared counts as a contact (``M_SWEPT`` 2): conservative, never a miss.
``benchmarks/sweep_check.py`` plays every built-in cell's episodes sampled ten times as finely and counts what the
swept test misses (nothing) and what it flags that the fine samples do not.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.human.body import PRONE_BEGIN_Z
from cellstress.sim.geometry import NO_REFCOUNT, segment_segment_xyz
from cellstress.sim.kernels.body import PRONE_TRAVEL, pose_body, prone_fraction
from cellstress.sim.kernels.fences import blocking_panel, collect_near_fences, fence_detour_bound
from cellstress.sim.kernels.params import SWEEP_CERTIFIED, SWEEP_DEPTH
from cellstress.sim.kernels.reach import TRACE_REL_TOL, reach_field_at
from cellstress.sim.kernels.robot import _robot_live, _segment, live_path_time, path_time
from cellstress.sim.kernels.sensing import body_blocked
from cellstress.sim.kernels.separation import separation
from cellstress.sim.layout import (
    A_DROP,
    A_FWD,
    A_LAT,
    A_Q0,
    A_TURN,
    B_ARM_LEN,
    B_HIP_Z,
    B_MODEL,
    B_N_CAPS,
    B_WALK_SPEED,
    C_ANY_MOTION,
    C_CYCLE,
    C_DT,
    C_DTOL,
    C_REACH_H,
    C_REACH_ORIGIN,
    C_RHO,
    C_VTOL,
    M_D,
    M_DROP,
    M_FWD,
    M_HEADING,
    M_HX,
    M_HY,
    M_HZ,
    M_LAT,
    M_LINK,
    M_PART,
    M_PHASE,
    M_ROBOT,
    M_RX,
    M_RY,
    M_RZ,
    M_SWEPT,
    M_TAU,
    M_TC,
    M_UNSAFE,
    M_V,
    M_X,
    M_Y,
    N_BODY_CAPSULES,
    PHASE_STOPPED,
    S_A_T,
    S_D_SEP,
    S_DROP,
    S_FWD,
    S_HEADING,
    S_K,
    S_LAT,
    S_LIVE,
    S_TSTOP,
    S_UNSAFE,
    S_X,
    S_XTSTOP,
    S_Y,
)

REACH_SLOPE = np.sqrt(3.0)  # the reach field's largest slope (a trilinear interpolant of a 1-Lipschitz grid)
CERT_STEP = 0.001  # m between the samples of a robot capsule's axis in a certified lower bound


@njit(cache=True, error_model="numpy", inline="always")
def _path_time(scal, prev, state, t0, t):
    """Robot 0's (path time, sigma, stop phase) at t in (t0, t1]: under the latches of the step's start, except
    after a re-anchoring (a separation command or a release) the step's end made within the step."""
    if state[S_LIVE] != 0.0 and state[S_A_T] > t0 and t >= state[S_A_T]:
        return live_path_time(scal, state, t)
    if prev[S_LIVE] != 0.0:
        return live_path_time(scal, prev, t)
    return path_time(scal, t, prev[S_TSTOP])


@njit(cache=True, error_model="numpy", inline="always")
def _moving_time(cycle, seg_start, seg_move, seg_dwell, ta, tb):
    """How much of the path time between ta and tb the path spends moving (its dwells at the waypoints left out):
    nothing of a robot moves while its path dwells, whatever the path time does."""
    lo, hi = (ta, tb) if ta <= tb else (tb, ta)
    if hi - lo >= cycle:
        return hi - lo
    t = lo - cycle * np.floor(lo / cycle)
    left = hi - lo
    out = 0.0
    i = _segment(seg_start, t)
    n = seg_start.shape[0]
    for _ in range(2 * n + 2):  # at most once round the cycle (a padded row of another robot starts at inf)
        if left <= 0.0:
            return out
        # segment i: dwell on [seg_start, seg_start + dwell), then the move until the next segment's start
        move_from = seg_start[i] + seg_dwell[i]
        end = move_from + seg_move[i]
        if t < move_from:
            gap = move_from - t
            if gap >= left:
                return out
            t, left = move_from, left - gap
        run = end - t
        if run >= left:
            return out + left
        if run > 0.0:
            out += run
            left -= run
        t = end
        i += 1
        if i >= n or seg_start[i] == np.inf:  # round the cycle's end
            i, t = 0, 0.0
    return out if left <= 0.0 else hi - lo


@njit(cache=True, error_model="numpy", inline="always")
def _robot_travel(P, prev, state, t0, ta, tb):
    """How far any point of any robot capsule can move between ta and tb; and whether every robot stands
    throughout, stopped or dwelling at a waypoint (``still``: whether that holds for a reason other than a stop,
    which only the speed test may use)."""
    tau_a, _, ph_a = _path_time(P.scal, prev, state, t0, ta)
    tau_b, _, ph_b = _path_time(P.scal, prev, state, t0, tb)
    standing = ph_a == PHASE_STOPPED and ph_b == PHASE_STOPPED
    run0 = _moving_time(P.scal[C_CYCLE], P.seg_start, P.seg_move, P.seg_dwell, tau_a, tau_b)
    still = run0 == 0.0
    worst = 0.0
    nx = P.x_scal.shape[0]
    for c in range(P.cap_speed.shape[0]):
        r = P.cap_robot[c]
        if r == 0:
            move = P.cap_speed[c] * run0
        else:
            xs = P.x_scal[r - 1]
            xa, _, pa = path_time(xs, ta, prev[S_XTSTOP + r - 1])
            xb, _, pb = path_time(xs, tb, prev[S_XTSTOP + r - 1])
            run = _moving_time(xs[C_CYCLE], P.x_seg_start[r - 1], P.x_seg_move[r - 1], P.x_seg_dwell[r - 1], xa, xb)
            move = P.cap_speed[c] * run
            if r <= nx and not (pa == PHASE_STOPPED and pb == PHASE_STOPPED):
                standing = False
            if run != 0.0:
                still = False
        if move > worst:
            worst = move
    return worst, standing, still


@njit(cache=True, error_model="numpy", inline="always")
def _worker_travel(P, prev, state):
    """How far any point of the worker can move over the whole step (see the module)."""
    b = P.body
    dx, dy = state[S_X] - prev[S_X], state[S_Y] - prev[S_Y]
    turn = abs(state[S_HEADING] - prev[S_HEADING]) + abs(state[S_FWD] - prev[S_FWD]) + \
        abs(state[S_LAT] - prev[S_LAT])
    out = np.sqrt(dx * dx + dy * dy) + P.scal[C_RHO] * turn
    if b[B_MODEL] != 0.0:
        out += abs(state[S_DROP] - prev[S_DROP])
        # tipping towards prone (body.pose_body): prone_fraction is monotone in the drop, which moves linearly
        out += P.scal[C_RHO] * PRONE_TRAVEL * abs(prone_fraction(b[B_HIP_Z] + state[S_DROP]) -
                                                  prone_fraction(b[B_HIP_Z] + prev[S_DROP]))
        for i in range(1, 11):
            out += b[B_ARM_LEN] * abs(state[S_DROP + i] - prev[S_DROP + i])
    return out


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _sample(P, prev, state, W, s, t0, out):
    """d_HR at fraction s of the step (worker and robots posed then) into out (a metric row's fields D, LINK,
    PART, the points, V, ROBOT, TAU, PHASE and the pose); returns (separation's value, moving, contact time)."""
    scal = P.scal
    dt = scal[C_DT]
    t = t0 + s * dt
    x = prev[S_X] + s * (state[S_X] - prev[S_X])
    y = prev[S_Y] + s * (state[S_Y] - prev[S_Y])
    h = prev[S_HEADING] + s * (state[S_HEADING] - prev[S_HEADING])
    f = prev[S_FWD] + s * (state[S_FWD] - prev[S_FWD])
    lt = prev[S_LAT] + s * (state[S_LAT] - prev[S_LAT])
    ext = W.ext2
    for i in range(11):
        ext[i] = prev[S_DROP + i] + s * (state[S_DROP + i] - prev[S_DROP + i])
    pose_body(P.body, x, y, h, f, lt, ext, 0, W.ha, W.hb, W.hr, W.sh, W.tr)
    tau, sigma, phase = _path_time(scal, prev, state, t0, t)
    W.stopped[0] = np.nan  # W.ra and W.rb no longer hold a standstill pose of the step (robot_at's cache)
    v = _robot_live(scal, P.seg_start, P.seg_move, P.seg_dwell, P.wp, P.parents, P.placements, P.base, P.axes,
                    P.jtype, P.anc, P.cap_joint, P.cap_a, P.cap_b, W.q, W.qd, W.rot, W.pos, W.ra, W.rb, tau, sigma)
    for r in range(P.x_scal.shape[0]):
        xs = P.x_scal[r]
        xtau, xsig, xphase = path_time(xs, t, prev[S_XTSTOP + r])
        W.xv[r] = _robot_live(xs, P.x_seg_start[r], P.x_seg_move[r], P.x_seg_dwell[r], P.x_wp[r], P.x_parents[r],
                              P.x_placements[r], P.x_base[r], P.x_axes[r], P.x_jtype[r], P.x_anc[r],
                              P.x_cap_joint[r], P.x_cap_a[r], P.x_cap_b[r], W.xq, W.xqd, W.xrot, W.xpos, W.xra,
                              W.xrb, xtau, xsig)
        W.xphase[r] = xphase
        c0 = P.x_cap0[r]
        for c in range(P.x_ncap[r]):
            for i in range(3):
                W.ra[c0 + c, i] = W.xra[c, i]
                W.rb[c0 + c, i] = W.xrb[c, i]
    arm_len = P.body[B_ARM_LEN]
    n_near = collect_near_fences(W.fences, W.sh, W.near, arm_len + 0.05)
    d = separation(P.cap_r, P.reach, scal[C_REACH_ORIGIN], scal[C_REACH_H], arm_len, W.fences, W.near, W.ra, W.rb,
                   W.sh, W.tr, W.ha, W.hb, W.hr, W.lbs, W.ts, W.best_r, n_near, out, int(P.body[B_N_CAPS]))
    link = int(out[M_LINK])
    owner = -1 if link < 0 else P.cap_robot[link]
    ph = phase
    if owner > 0:
        v, ph = W.xv[owner - 1], W.xphase[owner - 1]
    if scal[C_ANY_MOTION] != 0.0:
        moving = ph != PHASE_STOPPED
    else:
        moving = v > scal[C_VTOL]
    out[M_V], out[M_ROBOT], out[M_TAU], out[M_PHASE] = v, owner, tau, phase
    out[M_X], out[M_Y], out[M_HEADING], out[M_FWD], out[M_LAT] = x, y, h, f, lt
    for i in range(11):
        out[M_DROP + i] = ext[i]
    return d, moving, t


@njit(cache=True, error_model="numpy", inline="always")
def _possible(P, W):
    """Whether the worker can be in the pose ``_sample`` left in W: no body part through a fence panel or into an
    obstacle (``sensing.body_blocked``, the test every step's end pose passes). The straight line between two
    allowed poses can cross a panel (a bent trunk turning beside a wall swings a shoulder through it, and the
    reach volumes hanging on it reach round the panel for free); the worker cannot be there, so no contact
    counts from there."""
    return body_blocked(P.body, W.fences, P.obs_verts, P.obs_poly, P.obs_box, W.ha, W.hb, W.hr) == 0


@njit(cache=True, error_model="numpy", inline="always")
def _axis_bound(P, W, c, side, r, length, levels, n_near, through, best):
    """``best`` lowered by robot capsule c's distance to reach volume ``side`` (see ``_certified``).

    The axis is cut into 2**levels pieces, each at most ``CERT_STEP`` long, grouped in aligned blocks of a power
    of two. A block is bounded from below at its middle by the field less its slope times half the block, and
    the fence detour's lower bound less half the block. Each middle m lowers ``best`` to v(m) less the slack of a
    single piece, v the larger of the field and the detour bound there, less the radius; a block whose bound is
    not below ``best`` is done. Every point of the axis ends in a done block, whose bound was at least ``best``
    then, so the ``best`` returned is a lower bound; and it is at least the smallest v less a piece's slack,
    which is what sampling every piece guarantees. Depth first over the pieces without a stack: at piece i the
    blocks that begin there are tried largest first."""
    ra, rb = W.ra, W.rb
    arm_len = P.body[B_ARM_LEN]
    origin, grid_h = P.scal[C_REACH_ORIGIN], P.scal[C_REACH_H]
    sx, sy, sz = W.sh[side, 0], W.sh[side, 1], W.sh[side, 2]
    n = 1 << levels
    piece = REACH_SLOPE * 0.5 * length / n  # the slack of one piece
    i = 0
    while i < n:
        size = n
        while i % size != 0:
            size >>= 1
        while True:
            u = (i + 0.5 * size) / n
            half = 0.5 * length * size / n
            px, py, pz = ra[c, 0] + u * (rb[c, 0] - ra[c, 0]), ra[c, 1] + u * (rb[c, 1] - ra[c, 1]), \
                ra[c, 2] + u * (rb[c, 2] - ra[c, 2])
            v = reach_field_at(P.reach, origin, grid_h, W.sh, W.tr, side, px, py, pz) - r
            low = v - REACH_SLOPE * half
            if low < best and n_near > 0 and not through:
                # only the lower bound is wanted: a zero cutoff returns it before any bend is tried
                g = fence_detour_bound(W.fences, W.near, np.int64(n_near), sx, sy, sz, px, py, pz,
                                       0.0)[1] - arm_len - r
                if g > v:
                    v = g
                if g - half > low:
                    low = g - half
            if v - piece < best:
                best = v - piece
            if low >= best or size == 1:  # (a piece's own bound is never below v less its slack)
                break
            size >>= 1
        i += size
    return best


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _certified(P, W):
    """A lower bound on the distance between the robot and the worker as posed in W (by ``_sample``): body
    capsules exactly; each reach volume by its field along each robot capsule's axis, on pieces at most
    ``CERT_STEP`` long each bounded by the field at its middle less the field's slope times half its length,
    less the radius (``_axis_bound`` skips whole runs of pieces that cannot undercut the bound found so far: the
    same guarantee as sampling every piece). Fences only lengthen a reach: where a near panel holds the hand
    back, the fence detour's lower bound (1-Lipschitz along an axis that crosses no panel) less half the piece
    bounds it too, and the larger of the two holds (without it, a reach held back by a panel near the robot could
    never be cleared)."""
    ra, rb, cap_r, ha, hb, hr = W.ra, W.rb, P.cap_r, W.ha, W.hb, W.hr
    n_caps = int(P.body[B_N_CAPS])
    arm_len = P.body[B_ARM_LEN]
    arm = arm_len + 2.0 * P.scal[C_REACH_H]  # every reach volume lies within this of its shoulder
    n_near = collect_near_fences(W.fences, W.sh, W.near, arm_len + 0.05)  # as separation gathers them
    best = np.inf
    for c in range(cap_r.shape[0]):  # the body capsules first: their exact distances prune the reach volumes
        r = cap_r[c]
        for k in range(n_caps):
            d2 = segment_segment_xyz(ra[c, 0], ra[c, 1], ra[c, 2], rb[c, 0], rb[c, 1], rb[c, 2],
                                     ha[k, 0], ha[k, 1], ha[k, 2], hb[k, 0], hb[k, 1], hb[k, 2])[0]
            d = np.sqrt(d2) - r - hr[k]
            if d < best:
                best = d
    if n_caps != N_BODY_CAPSULES:
        return best  # (the articulated worker has no reach volumes)
    for c in range(cap_r.shape[0]):
        r = cap_r[c]
        length = np.sqrt((rb[c, 0] - ra[c, 0]) ** 2 + (rb[c, 1] - ra[c, 1]) ** 2 + (rb[c, 2] - ra[c, 2]) ** 2)
        levels = 0
        while length > CERT_STEP * (1 << levels) and levels < 40:
            levels += 1
        through = n_near > 0 and blocking_panel(W.fences, W.near, np.int64(n_near), ra[c, 0], ra[c, 1], ra[c, 2],
                                                rb[c, 0], rb[c, 1], rb[c, 2]) >= 0
        for side in range(2):
            sx, sy, sz = W.sh[side, 0], W.sh[side, 1], W.sh[side, 2]
            # the whole axis beyond the arm's ball around the shoulder, less the radius, cannot undercut the best
            d2 = segment_segment_xyz(ra[c, 0], ra[c, 1], ra[c, 2], rb[c, 0], rb[c, 1], rb[c, 2],
                                     sx, sy, sz, sx, sy, sz)[0]
            if np.sqrt(d2) - arm - r >= best:
                continue
            best = _axis_bound(P, W, c, side, r, length, levels, n_near, through, best)
    return best


@njit(cache=True, error_model="numpy", inline="always")
def _copy_contact(src, row, t, swept):
    """A contact found between the steps into the step's row (its own time in M_TC)."""
    for i in (M_D, M_LINK, M_PART, M_RX, M_RY, M_RZ, M_HX, M_HY, M_HZ, M_V, M_ROBOT, M_TAU, M_PHASE, M_X, M_Y,
              M_HEADING, M_FWD, M_LAT):
        row[i] = src[i]
    for i in range(11):
        row[M_DROP + i] = src[M_DROP + i]
    if row[M_D] < 0.0:
        row[M_D] = 0.0
    row[M_TC] = t
    row[M_SWEPT] = swept


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def sweep_step(P, prev, state, W, row):
    """The swept contact test of the step from ``prev`` to ``state`` (whose own sample was not unsafe; ``row``
    its metric row): True when a contact of the criterion's kernel test lies between them, written into ``row``
    and ``state`` as the kernels mark an unsafe step. For a criterion that judges contacts itself, the first
    contact found is written into the row for it to judge, and False is returned (see the module)."""
    scal = P.scal
    dt, dtol = scal[C_DT], scal[C_DTOL]
    judged = scal[C_VTOL] == np.inf and scal[C_ANY_MOTION] == 0.0  # the Simulator judges the row's contact
    h = scal[C_REACH_H]
    t1 = state[S_K] * dt
    t0 = t1 - dt
    travel = _worker_travel(P, prev, state)
    stack = W.stack
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3], stack[0, 4], stack[0, 5] = \
        0.0, 1.0, prev[S_D_SEP], state[S_D_SEP], 0.0, 0.0
    top = 1
    found_t = np.inf
    found = 0
    while top > 0:
        top -= 1
        sa, sb, da, db, depth, cert = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3], stack[top, 4], \
            stack[top, 5]
        ta, tb = t0 + sa * dt, t0 + sb * dt
        if ta >= found_t:
            continue  # after the contact already found
        robot, standing, still = _robot_travel(P, prev, state, t0, ta, tb)
        if not judged and (standing or (still and scal[C_ANY_MOTION] == 0.0)):
            continue  # no contact with a moving robot (a dwelling one has v_R 0; the arrival-window test asks
            # only whether it is stopped)
        moves = 0.5 * REACH_SLOPE * (travel * (sb - sa) + robot)
        if cert != 0.0:  # certified lower bounds at both ends
            near = 0.5 * (da + db) - moves
        else:  # separation's values, each lowered by what its tracing of a reach volume may overshoot
            near = 0.5 * ((da - h) + (db - h)) / (1.0 + TRACE_REL_TOL) - moves
        if near > dtol:
            continue
        if depth >= SWEEP_DEPTH + SWEEP_CERTIFIED:
            if not judged:  # cannot be cleared at the finest sub-step: a contact, conservatively, unless the
                # nearest robot moves at neither end (its speed taken as monotone over the part's 0.05 ms: braking
                # it only falls, leaving a dwell it only rises) or the worker can be at neither end
                _, moving_a, _ = _sample(P, prev, state, W, sa, t0, W.srow)
                possible_a = _possible(P, W)
                _, moving_b, _ = _sample(P, prev, state, W, sb, t0, W.srow)
                possible_b = _possible(P, W)
                if not (moving_a or moving_b) or not (possible_a or possible_b):
                    continue
                found_t = ta
                found = 2
                # the row: an end the worker can be in, where the robot moves if it moves at one end only (a
                # dwell's end), else the nearer one; with that end's own moment (the contact's time in M_TC)
                rank_a = 4 * possible_a + 2 * moving_a + (da <= db)
                rank_b = 4 * possible_b + 2 * moving_b + (db < da)
                _, _, t_end = _sample(P, prev, state, W, sa if rank_a >= rank_b else sb, t0, W.srow)
                _copy_contact(W.srow, W.crow, t_end, 2.0)
            continue
        if depth >= SWEEP_DEPTH and cert == 0.0:  # go on with certified lower bounds at both ends
            _sample(P, prev, state, W, sa, t0, W.srow)
            da = _certified(P, W)
            _sample(P, prev, state, W, sb, t0, W.srow)
            db = _certified(P, W)
            cert = 1.0
        sm = 0.5 * (sa + sb)
        dm, moving, tm = _sample(P, prev, state, W, sm, t0, W.srow)
        if dm <= dtol and (moving or judged) and tm < found_t and _possible(P, W):
            found_t = tm
            found = 1
            _copy_contact(W.srow, W.crow, tm, 1.0)
        if cert != 0.0:
            dm = _certified(P, W)
        # the later half first onto the stack, so that the earlier one is tested first
        stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3], stack[top, 4], stack[top, 5] = \
            sm, sb, dm, db, depth + 1, cert
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2], stack[top + 1, 3], stack[top + 1, 4], \
            stack[top + 1, 5] = sa, sm, da, dm, depth + 1, cert
        top += 2
    if found == 0:
        return False
    _copy_contact(W.crow, row, W.crow[M_TC], float(found))  # the moment of the pose it holds (a flag: an end's)
    if judged:
        return False
    row[M_UNSAFE] = 1.0
    state[S_UNSAFE] = 1.0
    return True


def flag_distance(P) -> float:
    """The largest true distance at which the swept test can still count a contact it could not rule out
    (``M_SWEPT`` 2): a lower bound on the distance above this everywhere proves that no step is unsafe (the
    verifier's distance bound uses it). From the worst travel in one step: the worker's (a stride, and every turn
    and flexion the action table allows in one step times the worker's radius; the articulated worker's stance
    and arms too) and the robot's (its fastest capsule for one step of path time), halved ``SWEEP_DEPTH +
    SWEEP_CERTIFIED`` times, and the certified bound's sampling slack."""
    act, spa, scal, b = P.act, P.spa, P.scal, P.body
    span = lambda col: float(act[:, col].max(initial=0.0) - act[:, col].min(initial=0.0))  # noqa: E731
    dt = float(scal[C_DT])
    worker = float(b[B_WALK_SPEED]) * dt + float(scal[C_RHO]) * (
        float(np.abs(act[:, A_TURN]).max(initial=0.0)) + span(A_FWD) + span(A_LAT)) / spa
    if b[B_MODEL] != 0.0:  # the stance, and both arms' joints, each moving the hand at most the arm's length out
        arms = sum(span(A_Q0 + j) for j in range(5)) + span(A_FWD)  # (a hanging arm follows the trunk's flexion)
        worker += (span(A_DROP) + 2.0 * float(b[B_ARM_LEN]) * arms) / spa
        if float(b[B_HIP_Z]) + float(act[:, A_DROP].min(initial=0.0)) < PRONE_BEGIN_Z:
            worker += float(scal[C_RHO]) * PRONE_TRAVEL  # tipping to prone may all happen in one step
    robot = float(P.cap_speed.max(initial=0.0)) * dt
    leaf = (worker + robot) / 2 ** (SWEEP_DEPTH + SWEEP_CERTIFIED)
    # a flagged part's certified ends average at most dtol + the leaf's travel term, and each end is a lower bound
    # on the true distance within the sampling slack of a reach volume
    return float(scal[C_DTOL]) + 0.5 * REACH_SLOPE * leaf + 0.5 * REACH_SLOPE * CERT_STEP
