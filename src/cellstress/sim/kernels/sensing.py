"""What the worker's body touches without the robot: the devices that see it, and the limits of where it
can stand (floor, table, fences) and lean (no trunk through a fence)."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.human.body import PRONE_HEIGHT, WALK_BLOCK_HEIGHT
from cellstress.sim.geometry import (
    NO_REFCOUNT,
    capsule_touches_prism,
    point_in_polygon,
    point_segment_2d,
    polygon_distance,
    segment_rectangle_xyz,
    segment_segment_xyz,
)
from cellstress.sim.kernels.body import pose_body, prone_fraction
from cellstress.sim.layout import (
    B_ARM_LEN,
    B_HEAD_RISE,
    B_HIP_Z,
    B_MODEL,
    B_N_CAPS,
    B_R_HEAD,
    B_R_TRUNK,
    B_SHOULDER_HALF,
    DEV_SCANNER,
    S_DROP,
    S_FWD,
    S_HEADING,
    S_LAT,
    S_X,
    S_Y,
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
            if body[B_MODEL] != 0.0:  # the articulated worker: the whole capsule (a crawler lies along the plane)
                if capsule_meets_plane_region(a0, a1, a2, b0, b1, b2, r, H, dev_verts, start, count):
                    return True
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
def capsule_meets_plane_region(a0, a1, a2, b0, b1, b2, r, H, verts, start, count):
    """The capsule (axis a-b, radius r) reaches the polygon (verts[start:start + count]) lying in the plane z = H:
    the axis's distance to that region is at most r. It is attained where the axis crosses the plane over the
    polygon, at an end of the axis over or beside the polygon, or against one of its edges."""
    if a2 != b2 and (a2 - H) * (b2 - H) <= 0.0:
        t = (H - a2) / (b2 - a2)
        if point_in_polygon(a0 + t * (b0 - a0), a1 + t * (b1 - a1), verts, start, count):
            return True
    r2 = r * r
    for e in range(2):
        px, py, pz = (a0, a1, a2) if e == 0 else (b0, b1, b2)
        dp = polygon_distance(px, py, verts, start, count)
        if dp * dp + (pz - H) * (pz - H) <= r2:
            return True
    for i in range(count):
        j = start + i
        k = start + (i + 1) % count
        if segment_segment_xyz(a0, a1, a2, b0, b1, b2, verts[j, 0], verts[j, 1], H, verts[k, 0], verts[k, 1],
                               H)[0] <= r2:
            return True
    return False


@njit(cache=True, error_model="numpy", inline="always")
def panel_stops_body(bottom, prone):
    """Whether a fence panel (or door leaf) whose bottom edge is ``bottom`` [m] above the floor stops the worker's
    body passing under it: walking, below WALK_BLOCK_HEIGHT (above it the worker ducks); prone (the articulated
    worker's crawl), unless the gap is higher than the prone body, PRONE_HEIGHT (human.body). The one rule every
    kernel applies (through feet_ok), and the height analysis.openings names."""
    if prone:
        return bottom <= PRONE_HEIGHT
    return bottom < WALK_BLOCK_HEIGHT


@njit(cache=True, error_model="numpy", inline="always")
def is_prone(body, drop):
    """The articulated worker lies prone (crawls) with its hip ``drop`` below standing (``prone_fraction`` 1)."""
    return body[B_MODEL] != 0.0 and prone_fraction(body[B_HIP_Z] + drop) >= 1.0


@njit(cache=True, error_model="numpy", inline="always")
def feet_ok(r, fl, obs_verts, obs_poly, fences, x, y, prone):
    """The footprint circle (radius r) stays on the floor, off every obstacle (the table's among them: the worker
    never climbs onto one, however low) and clear of the fence panels that stop it (``panel_stops_body``)."""
    if x - r < fl[0] or x + r > fl[1] or y - r < fl[2] or y + r > fl[3]:
        return False
    for t in range(obs_poly.shape[0]):
        if polygon_distance(x, y, obs_verts, obs_poly[t, 0], obs_poly[t, 1]) < r:
            return False
    for f in range(fences.shape[0]):
        if panel_stops_body(fences[f, 4], prone) and \
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
    hands) are held off obstacles as well: its arms do not pass through the table. Its legs too, once they leave
    the plumb (tipping towards prone they turn back about the hip and lie along the floor behind it, where
    walking's own blocking no longer keeps them off a wall or a table); plumb, they stay as the paper's.
    """
    nh = int(body[B_N_CAPS])
    first = 0 if nh != 6 and (ha[0, 0] != hb[0, 0] or ha[0, 1] != hb[0, 1]) else 2
    blocked = 0
    if obs_poly.shape[0]:
        blocked = obstacles_blocked(obs_verts, obs_poly, obs_box, ha, hb, hr, first, 4 if nh == 6 else nh)
        if blocked and nh == 6:
            return blocked
    extent = body[B_HEAD_RISE] + body[B_R_HEAD] + body[B_SHOULDER_HALF]
    if nh != 6:
        extent += body[B_ARM_LEN]
    for f in range(fences.shape[0]):
        x0, y0, x1, y1, zlo, zhi = fences[f, 0], fences[f, 1], fences[f, 2], fences[f, 3], fences[f, 4], fences[f, 5]
        if point_segment_2d(ha[2, 0], ha[2, 1], x0, y0, x1, y1) > extent:
            continue
        for c in range(first, nh):
            if blocked >> c & 1:
                continue
            # (a capsule whose box misses the panel's by more than its radius cannot touch it: the articulated
            # worker's eight capsules are tested against every panel within an arm's length, so most are skipped)
            r = hr[c]
            if nh != 6 and one_side(x0, y0, x1, y1, r, ha[c, 0], ha[c, 1], hb[c, 0], hb[c, 1], ha[c, 0], ha[c, 1],
                                    hb[c, 0], hb[c, 1]):
                continue
            if segment_rectangle_xyz(ha[c, 0], ha[c, 1], ha[c, 2], hb[c, 0], hb[c, 1], hb[c, 2],
                                     x0, y0, x1, y1, zlo, zhi)[0] < r:
                blocked |= 1 << c
                if nh == 6:
                    return blocked
    return blocked


@njit(cache=True, error_model="numpy", inline="always")
def one_side(x0, y0, x1, y1, r, ax, ay, bx, by, cx, cy, dx, dy):
    """Points a, b, c, d (plan view) all further than r from the vertical plane through the panel (x0, y0)-(x1,
    y1), on the same side: nothing between them can touch the panel."""
    nx, ny = y0 - y1, x1 - x0
    n = np.sqrt(nx * nx + ny * ny)
    if n == 0.0:
        return False
    nx, ny = nx / n, ny / n
    da = (ax - x0) * nx + (ay - y0) * ny
    db = (bx - x0) * nx + (by - y0) * ny
    dc = (cx - x0) * nx + (cy - y0) * ny
    dd = (dx - x0) * nx + (dy - y0) * ny
    return min(da, db, dc, dd) > r or max(da, db, dc, dd) < -r


@njit(cache=True, error_model="numpy", inline="always")
def trunk_clear(body, fences, obs_verts, obs_poly, obs_box, ha, hb, hr):
    """No body capsule passes through a fence panel or into an obstacle (``body_blocked``)."""
    return body_blocked(body, fences, obs_verts, obs_poly, obs_box, ha, hb, hr) == 0


SWEEP_ANGLE = 0.3  # rad: the largest change of any angle (heading, trunk, arm joint) between checked poses


@njit(cache=True, error_model="numpy", inline="always")
def path_blocked(body, fences, obs_verts, obs_poly, obs_box, state, x1, y1, h1, f1, l1, ext1, W):
    """body_blocked along the articulated worker's way from the state's pose to (x1, y1, h1, f1, l1, ext1), not
    only where it ends: at in-between poses (linear in every coordinate, no angle more than SWEEP_ANGLE apart),
    and along the paths of the capsules' ends (and the arms' middles) from one in-between pose to the next,
    which must not cross a fence panel. Otherwise an arm could pass through a panel between two time steps: it
    moves up to 45 degrees in one. The chords stand for the arcs to within 12 mm at 0.3 rad (a point 1.1 m from
    the axis it turns about), less than the thinnest capsule's radius. Returns the blocked capsules' bits at
    the first in-between pose that fails (0: the whole way is clear)."""
    ha, hb, hr, sh, tr, ext, pa, pb = W.ha, W.hb, W.hr, W.sh, W.tr, W.ext2, W.pa, W.pb
    x0, y0, h0, f0, l0 = state[S_X], state[S_Y], state[S_HEADING], state[S_FWD], state[S_LAT]
    big = max(abs(h1 - h0), abs(f1 - f0), abs(l1 - l0))
    for i in range(1, 11):
        big = max(big, abs(ext1[i] - state[S_DROP + i]))
    # tipping towards prone turns the trunk and legs (pose_body) by up to pi times the change of prone_fraction
    hip = body[B_HIP_Z]
    big = max(big, np.pi * abs(prone_fraction(hip + ext1[0]) - prone_fraction(hip + state[S_DROP])))
    # (moving the feet or the hip alone moves every point on a straight line, which the paths below follow
    # exactly: only turning needs poses in between)
    n = max(1, int(np.ceil(big / SWEEP_ANGLE)))
    n_caps = int(body[B_N_CAPS])
    for s in range(n + 1):
        u = s / n
        for i in range(11):
            ext[i] = state[S_DROP + i] if s == 0 else (ext1[i] if s == n else
                                                       state[S_DROP + i] + (ext1[i] - state[S_DROP + i]) * u)
        pose_body(body, x0 + (x1 - x0) * u, y0 + (y1 - y0) * u, h0 + (h1 - h0) * u, f0 + (f1 - f0) * u,
                  l0 + (l1 - l0) * u, ext, 0, ha, hb, hr, sh, tr)
        if s > 0:
            blocked = body_blocked(body, fences, obs_verts, obs_poly, obs_box, ha, hb, hr)
            if blocked == 0:
                blocked = swept_blocked(body, fences, pa, pb, ha, hb, hr, n_caps)
            if blocked != 0:
                return blocked
        for c in range(n_caps):
            for r in range(3):
                pa[c, r], pb[c, r] = ha[c, r], hb[c, r]
    return 0


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def swept_blocked(body, fences, pa, pb, ha, hb, hr, n_caps):
    """Bit c set: a path from capsule c's ends (pa, pb) to its ends now (ha, hb), or of an arm capsule's middle,
    comes within the capsule's radius of a fence panel (trunk, head and arms: 2 .. n_caps - 1). A capsule whose
    four ends are all on one side of the panel's plane, further than its radius, is skipped: most are."""
    blocked = 0
    for f in range(fences.shape[0]):
        x0, y0, x1, y1, zlo, zhi = fences[f, 0], fences[f, 1], fences[f, 2], fences[f, 3], fences[f, 4], fences[f, 5]
        for c in range(2, n_caps):
            if blocked >> c & 1:
                continue
            r = hr[c]
            if min(pa[c, 2], pb[c, 2], ha[c, 2], hb[c, 2]) - r > zhi or \
                    max(pa[c, 2], pb[c, 2], ha[c, 2], hb[c, 2]) + r < zlo or \
                    one_side(x0, y0, x1, y1, r, pa[c, 0], pa[c, 1], pb[c, 0], pb[c, 1], ha[c, 0], ha[c, 1],
                             hb[c, 0], hb[c, 1]):
                continue
            for w in range(3 if c >= 4 else 2):
                if w == 0:
                    sx, sy, sz, ex, ey, ez = pa[c, 0], pa[c, 1], pa[c, 2], ha[c, 0], ha[c, 1], ha[c, 2]
                elif w == 1:
                    sx, sy, sz, ex, ey, ez = pb[c, 0], pb[c, 1], pb[c, 2], hb[c, 0], hb[c, 1], hb[c, 2]
                else:
                    sx, sy, sz = 0.5 * (pa[c, 0] + pb[c, 0]), 0.5 * (pa[c, 1] + pb[c, 1]), 0.5 * (pa[c, 2] + pb[c, 2])
                    ex, ey, ez = 0.5 * (ha[c, 0] + hb[c, 0]), 0.5 * (ha[c, 1] + hb[c, 1]), 0.5 * (ha[c, 2] + hb[c, 2])
                if segment_rectangle_xyz(sx, sy, sz, ex, ey, ez, x0, y0, x1, y1, zlo, zhi)[0] < r:
                    blocked |= 1 << c
                    break
    return blocked


# Not inlined: move_worker is inlined into step_action and worker_paths, and one shared compiled copy of this
# loop costs a cold compile less than two inlined ones (it runs once per time step either way).
@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def obstacles_blocked(obs_verts, obs_poly, obs_box, ha, hb, hr, first, n_caps):
    """Bit c set: capsule c (of ``first`` .. n_caps - 1: the tipped legs, trunk, head and the articulated
    worker's arms) enters an obstacle's prism."""
    blocked = 0
    for o in range(obs_poly.shape[0]):
        h = obs_box[o, 4]
        for c in range(first, n_caps):
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
