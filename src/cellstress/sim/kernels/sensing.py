"""What the worker's body touches without the robot: the devices that see it, and the limits of where it
can stand (floor, table, fences) and lean (no trunk through a fence)."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.human.body import WALK_BLOCK_HEIGHT
from cellstress.sim.geometry import (
    NO_REFCOUNT,
    capsule_touches_prism,
    point_segment_2d,
    polygon_distance,
    segment_rectangle_xyz,
)
from cellstress.sim.layout import (
    B_ARM_LEN,
    B_HEAD_RISE,
    B_MODEL,
    B_N_CAPS,
    B_R_HEAD,
    B_R_TRUNK,
    B_SHOULDER_HALF,
    DEV_SCANNER,
)


@njit(cache=True, error_model="numpy", inline="always")
def device_sees(dev_kind, dev_rect, dev_poly, dev_verts, body, d, ha, hb, hr):
    """Does device d detect the worker: a body capsule (legs, trunk, head, arms) in its region?

    The paper worker's reach volumes are not seen: they stand for where an arm *could* strike, and the
    worst-case worker keeps the arm back until it can. ISO 13855's reach allowance C covers exactly this. The
    articulated worker's arms are capsules where they are, and are seen there.
    """
    nh = int(body[B_N_CAPS])
    if dev_kind[d] == DEV_SCANNER:
        H = dev_rect[d, 4]
        start, count = dev_poly[d, 0], dev_poly[d, 1]
        for c in range(nh):
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
        if body[B_MODEL] != 0.0:
            extent += body[B_ARM_LEN]
        if point_segment_2d(ha[2, 0], ha[2, 1], x0, y0, x1, y1) > extent:
            return False
        for c in range(nh):
            if segment_rectangle_xyz(ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2],
                                     x0, y0, x1, y1, zlo, zhi)[0] <= hr[c]:
                return True
    return False


@njit(cache=True, error_model="numpy", inline="always")
def feet_ok(r, fl, obs_verts, obs_poly, fences, x, y):
    """The footprint circle (radius r) stays on the floor, off every obstacle (the table's among them: the worker
    never climbs onto one, however low) and clear of fence panels."""
    if x - r < fl[0] or x + r > fl[1] or y - r < fl[2] or y + r > fl[3]:
        return False
    for t in range(obs_poly.shape[0]):
        if polygon_distance(x, y, obs_verts, obs_poly[t, 0], obs_poly[t, 1]) < r:
            return False
    for f in range(fences.shape[0]):
        if fences[f, 4] < WALK_BLOCK_HEIGHT and \
                point_segment_2d(x, y, fences[f, 0], fences[f, 1], fences[f, 2], fences[f, 3]) < r:
            return False
    return True


@njit(cache=True, error_model="numpy", inline="always")
def body_blocked(body, fences, obs_verts, obs_poly, obs_box, ha, hb, hr):
    """Bit c set: body capsule c passes through a fence panel or into an obstacle; 0: the pose is allowed.

    Trunk, head and arms are held off fence panels, and trunk and head off obstacles. The shoulders matter most
    for the paper's worker: the reach volumes hang on them, so a shoulder past a panel would reach around it
    for free. (Where its hands can get past a panel is limited separately, by fence_detour.) Its hanging arms
    are not held off obstacles: bent over a table they would hit its top, which its fixed arm pose cannot
    avoid; the reach volumes ignore obstacles likewise. The articulated worker's arms (upper arms, forearms,
    hands) are held off obstacles as well: its arms do not pass through the table.
    """
    nh = int(body[B_N_CAPS])
    blocked = 0
    if obs_poly.shape[0]:
        blocked = obstacles_blocked(obs_verts, obs_poly, obs_box, ha, hb, hr, 4 if nh == 6 else nh)
        if blocked and nh == 6:
            return blocked
    extent = body[B_HEAD_RISE] + body[B_R_HEAD] + body[B_SHOULDER_HALF]
    if nh != 6:
        extent += body[B_ARM_LEN]
    for f in range(fences.shape[0]):
        x0, y0, x1, y1, zlo, zhi = fences[f, 0], fences[f, 1], fences[f, 2], fences[f, 3], fences[f, 4], fences[f, 5]
        if point_segment_2d(ha[2, 0], ha[2, 1], x0, y0, x1, y1) > extent:
            continue
        for c in range(2, nh):
            if blocked >> c & 1:
                continue
            if segment_rectangle_xyz(ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2],
                                     x0, y0, x1, y1, zlo, zhi)[0] < hr[c]:
                blocked |= 1 << c
                if nh == 6:
                    return blocked
    return blocked


@njit(cache=True, error_model="numpy", inline="always")
def trunk_clear(body, fences, obs_verts, obs_poly, obs_box, ha, hb, hr):
    """No body capsule passes through a fence panel or into an obstacle (``body_blocked``)."""
    return body_blocked(body, fences, obs_verts, obs_poly, obs_box, ha, hb, hr) == 0


# Not inlined: move_worker is inlined into step_action and worker_paths, and one shared compiled copy of this
# loop costs a cold compile less than two inlined ones (it runs once per time step either way).
@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def obstacles_blocked(obs_verts, obs_poly, obs_box, ha, hb, hr, n_caps):
    """Bit c set: capsule c (of 2 .. n_caps - 1: trunk, head and the articulated worker's arms) enters an
    obstacle's prism."""
    blocked = 0
    for o in range(obs_poly.shape[0]):
        h = obs_box[o, 4]
        for c in range(2, n_caps):
            if blocked >> c & 1:
                continue
            r = hr[c]
            if min(ha[c, 2], hb[c, 2]) - r >= h:
                continue
            if min(ha[c, 0], hb[c, 0]) - r > obs_box[o, 1] or max(ha[c, 0], hb[c, 0]) + r < obs_box[o, 0] or \
                    min(ha[c, 1], hb[c, 1]) - r > obs_box[o, 3] or max(ha[c, 1], hb[c, 1]) + r < obs_box[o, 2]:
                continue
            if capsule_touches_prism(ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2], r, obs_verts,
                                     obs_poly[o, 0], obs_poly[o, 1], h):
                blocked |= 1 << c
                if n_caps == 4:
                    return blocked
    return blocked
