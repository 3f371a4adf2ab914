"""The reach volumes on the worker: the signed distance from a point, or the least one along a capsule's
axis, to where an arm can reach, with the hand's detours around fence panels.

The field itself (a trilinear lookup in the shoulder frame) belongs to the human model (``human.reach``);
here it is placed on the posed shoulders and combined with the fences.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.human.reach import reach_lookup
from cellstress.sim.kernels.fences import blocking_panel, fence_detour, fence_detour_bound
from cellstress.sim.layout import B_ARM_LEN, C_REACH_H, C_REACH_ORIGIN

TRACE_REL_TOL = 0.05  # far from contact, d_HR needs only relative accuracy (it feeds a smooth reward)

# The non-inlined fence kernels get n_near as np.int64(n_near): should a caller ever pass a constant (as a
# fence-free copy of separation once did), numba would type it as a literal and compile each of them once more
# for it (that cost ~10 s of a cold start).


@njit(cache=True, error_model="numpy", inline="always")
def reach_field_at(reach, origin, h, sh, tr, side, px, py, pz):
    """Signed distance from p to the reach volume of arm ``side`` (0 left, 1 right), fences ignored."""
    dx, dy, dz = px - sh[side, 0], py - sh[side, 1], pz - sh[side, 2]
    l0 = tr[0, 0] * dx + tr[1, 0] * dy + tr[2, 0] * dz
    ly = tr[0, 1] * dx + tr[1, 1] * dy + tr[2, 1] * dz
    l1 = -ly if side == 0 else ly
    l2 = tr[0, 2] * dx + tr[1, 2] * dy + tr[2, 2] * dz
    return reach_lookup(reach, origin, h, l0, l1, l2)


@njit(cache=True, error_model="numpy", inline="always")
def fenced_reach(arm_len, fences, near, sh, side, n_near, f, px, py, pz, cutoff):
    """The reach value ``f`` raised where the near fence panels make the hand go the long way round; exact
    below ``cutoff``, and at least ``cutoff`` otherwise."""
    g = fence_detour(fences, near, np.int64(n_near), sh[side, 0], sh[side, 1], sh[side, 2], px, py, pz,
                     cutoff + arm_len) - arm_len
    return g if g > f else f


@njit(cache=True, error_model="numpy", inline="always")
def reach_value_at(reach, origin, h, arm_len, fences, near, sh, tr, side, n_near, px, py, pz):
    """Signed distance from p to the reach volume of arm ``side`` (0 left, 1 right), fences respected."""
    f = reach_field_at(reach, origin, h, sh, tr, side, px, py, pz)
    if n_near > 0:
        f = fenced_reach(arm_len, fences, near, sh, side, n_near, f, px, py, pz, np.inf)
    return f


@njit(cache=True, error_model="numpy")
def reach_value(P, p, side, W, n_near):
    """Signed distance from point p to the reach volume of arm ``side`` at the pose in W (outside the hot loop)."""
    return reach_value_at(P.reach, P.scal[C_REACH_ORIGIN], P.scal[C_REACH_H], P.body[B_ARM_LEN], P.fences, W.near,
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
    through = n_near > 0 and blocking_panel(fences, near, np.int64(n_near), ax, ay, az, bx, by, bz) >= 0
    sx, sy, sz = sh[side, 0], sh[side, 1], sh[side, 2]
    while True:
        tt = t / L if L > 0.0 else 0.0
        px, py, pz = ax + tt * (bx - ax), ay + tt * (by - ay), az + tt * (bz - az)
        fl = reach_field_at(reach, origin, h, sh, tr, side, px, py, pz)
        f = fl
        lb = fl
        # The fenced value is never below fl, so where fl >= best it cannot be a new best, and where
        # fl >= bound + r it cannot matter to the caller (which ignores results >= bound): skip the detour.
        # Nor does its exact value from bound + r + h up: it is no new best then, and the steps below use
        # only its lower bound there.
        if n_near > 0 and fl < best and fl < bound + r:
            g, g_lb = fence_detour_bound(fences, near, np.int64(n_near), sx, sy, sz, px, py, pz,
                                          bound + r + h + arm_len)
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
