"""Fence panels in the hand's way: which panels are near, whether a straight path crosses one, and the
shortest way round them (over the top edge or around an end) with a lower bound of it."""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import njit
from cellstress.sim.geometry import NO_REFCOUNT, point_segment_2d, segment_segment_xyz

# m: two panel ends this close meet, and a panel whose direction is off another's by at most this (as a sine)
# continues it in a straight line. Such a seam is closed: the hand passes neither through it nor round it.
SEAM = 1e-6


@njit(cache=True, error_model="numpy")
def near_fences(P, W, margin):
    """Collect into W.near the fence panels within ``margin`` of either shoulder (plan view)."""
    return collect_near_fences(P.fences, W.sh, W.near, margin)


@njit(cache=True, error_model="numpy", inline="always")
def collect_near_fences(fences, sh, near, margin):
    """The panels within ``margin`` of either shoulder (plan view), and every panel that continues one of
    them in a straight line (``_continues``): a wall of collinear runs is near as a whole, so the hand's way
    round it is the way round the wall, wherever its seams lie. Their count; ``near`` (of ``params.near_size``) also
    holds which near panel continues each of them at each end (``continuation``)."""
    n = 0
    for f in range(fences.shape[0]):
        x0, y0, x1, y1 = fences[f, 0], fences[f, 1], fences[f, 2], fences[f, 3]
        d0 = point_segment_2d(sh[0, 0], sh[0, 1], x0, y0, x1, y1)
        d1 = point_segment_2d(sh[1, 0], sh[1, 1], x0, y0, x1, y1)
        if d0 < margin or d1 < margin:
            near[n] = f
            n += 1
    return _add_continuations(fences, near, n)


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _add_continuations(fences, near, n):
    """Append to ``near[:n]`` every panel that continues one of them in a straight line; the new count. For each
    near panel i and end e, ``near[_link(fences, i, e)]`` is 2 m + far for the first near panel ``near[m]`` that
    continues i there (far: which of its ends lies away from i), -1 for none."""
    k = 0
    while k < n:
        i = near[k]
        for end in range(2):
            link = -1
            for j in range(fences.shape[0]):
                far = _continues(fences, i, end, j)
                if far >= 0:
                    m = 0
                    while m < n and near[m] != j:
                        m += 1
                    if m == n:
                        near[n] = j
                        n += 1
                    if link < 0 or m < link >> 1:
                        link = 2 * m + far
            near[_link(fences, i, end)] = link
        k += 1
    return n


@njit(cache=True, error_model="numpy", inline="always")
def _link(fences, i, end):
    return fences.shape[0] + 1 + 2 * i + end


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
    return blocking_panel(fences, near, n_near, ax, ay, az, bx, by, bz) < 0


@njit(cache=True, error_model="numpy", inline="always")
def _panel_across(fences, i, ax, ay, az, bx, by, bz):
    """Fence panel i lies across the straight segment a-b."""
    ux, uy = fences[i, 2] - fences[i, 0], fences[i, 3] - fences[i, 1]
    nx, ny = -uy, ux
    sa = (ax - fences[i, 0]) * nx + (ay - fences[i, 1]) * ny
    sb = (bx - fences[i, 0]) * nx + (by - fences[i, 1]) * ny
    if not ((sa < 0.0 < sb) or (sb < 0.0 < sa)):  # strictly opposite signs (a product may underflow)
        return False
    t = sa / (sa - sb)
    cx, cy, cz = ax + t * (bx - ax), ay + t * (by - ay), az + t * (bz - az)
    u = ((cx - fences[i, 0]) * ux + (cy - fences[i, 1]) * uy) / (ux * ux + uy * uy)
    return 0.0 <= u <= 1.0 and fences[i, 4] <= cz <= fences[i, 5]


@njit(cache=True, error_model="numpy", inline="always")
def _continues(fences, i, end, j):
    """Which end of panel j (0 or 1) lies beyond panel i's end ``end`` (0: its first point, 1: its second) when
    j lies in i's line and covers that end and the 1 cm beyond it (j continues i there, from that point or from
    behind it: a run that meets i end to end, or one i overlaps, as a door leaf in its wall); -1 when not."""
    ex, ey = fences[i, 2 * end], fences[i, 2 * end + 1]
    ux, uy = ex - fences[i, 2 - 2 * end], ey - fences[i, 3 - 2 * end]
    w2 = ux * ux + uy * uy
    if j == i or w2 <= SEAM * SEAM:
        return -1
    # both of j's ends on i's line (squared, unnormalised: most panels fail here, and this runs at every step)
    ax, ay = fences[j, 0] - ex, fences[j, 1] - ey
    bx, by = fences[j, 2] - ex, fences[j, 3] - ey
    tol2 = SEAM * SEAM * w2
    if (ax * uy - ay * ux) ** 2 > tol2 or (bx * uy - by * ux) ** 2 > tol2:
        return -1
    w = np.sqrt(w2)
    sa, sb = (ax * ux + ay * uy) / w, (bx * ux + by * uy) / w  # along i's outward direction, from its end
    if min(sa, sb) <= SEAM and max(sa, sb) > SEAM:
        return 0 if sa > sb else 1
    return -1


@njit(cache=True, error_model="numpy", inline="always")
def continuation(fences, near, n_near, i, end):
    """(m, far): the near panel ``near[m]`` that continues the near panel i in a straight line past its end
    ``end`` and which of its ends lies away from i (``_continues``); (-1, 0) if none does. Fence runs that meet
    end to end make one wall: the way round is past the wall's ends, not past the seam. The near panels hold
    every panel that continues one of them, and which one does (``collect_near_fences``), so the whole wall is
    there. (The first such near panel, should two continue i at one end.)"""
    link = near[_link(fences, i, end)]
    if link < 0:
        return -1, 0
    return link >> 1, link & 1


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def blocking_panel(fences, near, n_near, ax, ay, az, bx, by, bz):
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
def _edge_term(sx, sy, sz, ax, ay, az, bx, by, bz, seg, ex, ey, ez, dx, dy, dz, length):
    """No path from s through the edge (ex, ey, ez) + t d, t in [0, length], to the target is shorter. The
    target is the point a (``seg`` False: the exact shortest such path, ``_edge_detour``) or any point of the
    segment ab (``seg`` True: |s - edge| + |edge - ab|, a lower bound). (``seg`` is a constant at every call,
    so each inlined copy keeps one branch.)"""
    if not seg:
        return _edge_detour(sx, sy, sz, ax, ay, az, ex, ey, ez, dx, dy, dz, length)[0]
    fx, fy, fz = ex + length * dx, ey + length * dy, ez + length * dz
    d_s = segment_segment_xyz(ex, ey, ez, fx, fy, fz, sx, sy, sz, sx, sy, sz)[0]
    d_q = segment_segment_xyz(ex, ey, ez, fx, fy, fz, ax, ay, az, bx, by, bz)[0]
    return np.sqrt(d_s) + np.sqrt(d_q)


@njit(cache=True, error_model="numpy", inline="always")
def _vertical_detour(sx, sy, sz, ax, ay, az, bx, by, bz, seg, x, y, z0, z1):
    """``_edge_term`` for the vertical edge at (x, y) from height z0 up to z1."""
    return _edge_term(sx, sy, sz, ax, ay, az, bx, by, bz, seg, x, y, z0, 0.0, 0.0, 1.0, z1 - z0)


@njit(cache=True, error_model="numpy", inline="always")
def _level_detour(fences, i, col, sx, sy, sz, ax, ay, az, bx, by, bz, seg):
    """``_edge_term`` for panel i's horizontal edge at height fences[i, col] (5: the top, 4: the bottom)."""
    ux, uy = fences[i, 2] - fences[i, 0], fences[i, 3] - fences[i, 1]
    w = np.sqrt(ux * ux + uy * uy)
    return _edge_term(sx, sy, sz, ax, ay, az, bx, by, bz, seg, fences[i, 0], fences[i, 1], fences[i, col], ux / w,
                      uy / w, 0.0, w)


@njit(cache=True, error_model="numpy", inline="always")
def _bottom_detour(fences, i, sx, sy, sz, ax, ay, az, bx, by, bz, seg):
    """``_level_detour`` over panel i's bottom edge where that edge counts (see ``_around_panel``), else inf."""
    if fences[i, 4] < min(sz, az, bz):
        return np.inf
    return _level_detour(fences, i, 4, sx, sy, sz, ax, ay, az, bx, by, bz, seg)


@njit(cache=True, error_model="numpy", inline="always")
def _past_end(fences, near, n_near, i, end, sx, sy, sz, ax, ay, az, bx, by, bz, seg, own):
    """A lower bound on the paths from s to the target (``_edge_term``) that cross the wall's plane beyond
    panel i's end ``end``, given the term ``own`` of that end edge: ``own`` where no panel continues i there;
    else the least term over the border of the wall the continuing panels make with i (their top and bottom
    edges, the steps where two of them differ in height, the last one's far end edge)."""
    best = np.inf
    k, e = i, end
    for _ in range(n_near):
        m, far = continuation(fences, near, n_near, k, e)
        if m < 0:
            if k == i:
                return own
            return min(best, _vertical_detour(sx, sy, sz, ax, ay, az, bx, by, bz, seg, fences[k, 2 * e],
                                              fences[k, 2 * e + 1], fences[k, 4], fences[k, 5]))
        j = near[m]
        # the steps in the wall's top and bottom where the two meet: at k's end, and at j's near end (the same
        # point where j starts there; inside k where k overlaps j)
        for x, y in ((fences[k, 2 * e], fences[k, 2 * e + 1]), (fences[j, 2 - 2 * far], fences[j, 3 - 2 * far])):
            for z in range(4, 6):
                if fences[k, z] != fences[j, z]:
                    best = min(best, _vertical_detour(sx, sy, sz, ax, ay, az, bx, by, bz, seg, x, y,
                                                      min(fences[k, z], fences[j, z]), max(fences[k, z], fences[j, z])))
        best = min(best, _level_detour(fences, j, 5, sx, sy, sz, ax, ay, az, bx, by, bz, seg),
                   _bottom_detour(fences, j, sx, sy, sz, ax, ay, az, bx, by, bz, seg))
        k, e = j, far
    return min(best, own)  # not reached: each continuation lies further along the line


@njit(cache=True, error_model="numpy", inline="always")
def _around_panel(fences, near, n_near, i, sx, sy, sz, ax, ay, az, bx, by, bz, seg, top, end0, end1):
    """A lower bound on any path from s to the target (the point a, or any point of the segment ab with
    ``seg``) that passes panel i, when every straight path from s to the target crosses it, given the panel's
    edge terms ``top``, ``end0``, ``end1`` (``_panel_edges``, ``_edge_term``).

    The path must cross the wall's plane outside the wall (panel i and the near panels that continue it in
    a straight line, ``continuation``), and for a target point q, |s - c| + |c - q| over the plane is convex
    with its minimum inside panel i, so the shortest such crossing lies on the wall's border: the least of its
    edge terms. A panel's bottom edge counts only if s or q lies at or below it: otherwise a path below the
    panel would have to dip under the panel and come back up, and the segment from such a crossing to the
    straight path's crossing enters the panel through an end edge or the top, at no greater length."""
    lb = min(top, _bottom_detour(fences, i, sx, sy, sz, ax, ay, az, bx, by, bz, seg))
    lb = min(lb, _past_end(fences, near, n_near, i, 0, sx, sy, sz, ax, ay, az, bx, by, bz, seg, end0))
    return min(lb, _past_end(fences, near, n_near, i, 1, sx, sy, sz, ax, ay, az, bx, by, bz, seg, end1))


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
            a = _around_panel(fences, near, n_near, near[m], sx, sy, sz, qx, qy, qz, qx, qy, qz, False, e[0],
                              e[2], e[4])
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
                if length < best:
                    c = continuation(fences, near, n_near, i, edge - 1)[0]
                    if c >= 0 and fences[near[c], 4] <= ez <= fences[near[c], 5]:
                        continue  # a seam: the bend lies in the panel that continues this one
            if (length < best and _path_clear(fences, near, n_near, sx, sy, sz, ex, ey, ez)
                    and _path_clear(fences, near, n_near, ex, ey, ez, qx, qy, qz)):
                best = length
    return best, around


# A wrapper of fence_detour_bound, not a second inlined copy of _detour_and_bound: that copy cost ~5 s of a
# cold compile. (cutoff has no default: an omitted argument would be typed apart and compile the callee again.)
@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def fence_detour(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff):
    """Length of the shortest arm path from shoulder s to q around the near fence panels, over their top
    edge or around their ends (inf if every such path is blocked); |s - q| when nothing is in the way.

    A finite ``cutoff`` says that any length from it up will do: the result is exact below it and ``cutoff``
    otherwise, and bends that are not shorter are not checked for crossings (most of the cost). If even the
    way around one of the panels in the way is that long, no bend is looked at."""
    return fence_detour_bound(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff)[0]


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def fence_detour_bound(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff):
    """``fence_detour`` and its 1-Lipschitz lower bound (see ``_detour_and_bound``)."""
    return _detour_and_bound(fences, near, n_near, sx, sy, sz, qx, qy, qz, cutoff)


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def shadow_bound(fences, near, n_near, sx, sy, sz, ax, ay, az, bx, by, bz):
    """A lower bound on the length of every path from s to a point of the segment ab that passes no near
    panel (a hand's way round the fences to a robot capsule's axis); 0 when no near panel lies across every
    straight path from s to the segment.

    A panel across s-a and s-b is across s-q for every q of ab: the straight paths from s meet the panel's
    plane along a segment between the two crossings, which the convex panel holds. For each q the bound of
    ``_around_panel`` holds, and each of its edge terms with the segment for target is no larger."""
    lb = 0.0
    for m in range(n_near):
        i = near[m]
        if not (_panel_across(fences, i, sx, sy, sz, ax, ay, az) and _panel_across(fences, i, sx, sy, sz, bx, by, bz)):
            continue
        top = _level_detour(fences, i, 5, sx, sy, sz, ax, ay, az, bx, by, bz, True)
        # an end edge counts only where no panel continues the wall there (_past_end)
        end0 = np.inf if continuation(fences, near, n_near, i, 0)[0] >= 0 else _vertical_detour(
            sx, sy, sz, ax, ay, az, bx, by, bz, True, fences[i, 0], fences[i, 1], fences[i, 4], fences[i, 5])
        end1 = np.inf if continuation(fences, near, n_near, i, 1)[0] >= 0 else _vertical_detour(
            sx, sy, sz, ax, ay, az, bx, by, bz, True, fences[i, 2], fences[i, 3], fences[i, 4], fences[i, 5])
        g = _around_panel(fences, near, n_near, i, sx, sy, sz, ax, ay, az, bx, by, bz, True, top, end0, end1)
        lb = g if g > lb else lb
    return lb
