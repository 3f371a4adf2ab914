"""d_HR: the least distance between the robot's capsules and the worker's body capsules or reach volumes."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim.geometry import segment_segment_xyz
from cellstress.sim.kernels.fences import shadow_bound
from cellstress.sim.kernels.reach import fenced_reach, reach_field_at, reach_to_segment
from cellstress.sim.layout import (
    M_D,
    M_HX,
    M_HY,
    M_HZ,
    M_LINK,
    M_PART,
    M_RX,
    M_RY,
    M_RZ,
    N_BODY_CAPSULES,
    PART_LEFT_REACH,
    PART_RIGHT_REACH,
)


@njit(cache=True, error_model="numpy", inline="always")
def _set_reach_hit(row, q):
    row[M_RX], row[M_RY], row[M_RZ] = q[0], q[1], q[2]


@njit(cache=True, error_model="numpy", inline="always")
def separation(cap_r, reach, origin, grid_h, arm_len, fences, near, ra, rb, sh, tr, ha, hb, hr, lbs, ts, q,
               n_near, row, n_caps):
    """d_HR: minimum distance between the robot capsules and the body capsules or reach volumes.

    ``n_caps`` body capsules: the paper's worker has six and its two reach volumes; the articulated worker has
    ten (its arms are capsules where they are) and no reach volumes.

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
    n_vol = nc if n_caps == N_BODY_CAPSULES else 0  # robot capsules to test against the reach volumes
    best_h = -1
    for c in range(n_vol):
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
        for i in range(2 * n_vol):
            if lbs[i] < lo:
                lo = lbs[i]
                m = i
        if m < 0:
            break
        lbs[m] = np.inf
        c, side = m // 2, m % 2
        r = cap_r[c]
        # a hand that must go round a panel to reach any point of this axis cannot come closer than that way
        if n_near > 0 and best < np.inf and shadow_bound(
                fences, near, np.int64(n_near), sh[side, 0], sh[side, 1], sh[side, 2], ra[c, 0], ra[c, 1], ra[c, 2],
                rb[c, 0], rb[c, 1], rb[c, 2]) - arm_len - r - 1e-9 >= best:
            continue
        t = ts[m]
        px, py, pz = ra[c, 0] + t * (rb[c, 0] - ra[c, 0]), ra[c, 1] + t * (rb[c, 1] - ra[c, 1]), \
            ra[c, 2] + t * (rb[c, 2] - ra[c, 2])
        f = reach_field_at(reach, origin, grid_h, sh, tr, side, px, py, pz)
        if n_near > 0 and f - r < best:  # (the fenced value is never below f: else it cannot be a new best)
            # (cutoff h above the best: a stand-in value must not round below it and pass for a new best)
            f = fenced_reach(arm_len, fences, near, sh, side, n_near, f, px, py, pz, best + r + grid_h)
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
        for h in range(n_caps):
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
                best, best_cap, best_part, best_h = d, c, (h if h < N_BODY_CAPSULES else h + 2), h
                row[M_RX], row[M_RY], row[M_RZ] = c1x, c1y, c1z
                row[M_HX], row[M_HY], row[M_HZ] = c2x, c2y, c2z
    # surface points: step from the axis points towards each other by the radii
    if PART_LEFT_REACH <= best_part <= PART_RIGHT_REACH:
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
        r, hr = cap_r[best_cap], hr[best_h]
        row[M_RX], row[M_RY], row[M_RZ] = row[M_RX] + r * dx, row[M_RY] + r * dy, row[M_RZ] + r * dz
        row[M_HX], row[M_HY], row[M_HZ] = row[M_HX] - hr * dx, row[M_HY] - hr * dy, row[M_HZ] - hr * dz
    row[M_D] = best if best > 0.0 else 0.0
    row[M_LINK] = best_cap
    row[M_PART] = best_part
    return best
