"""Compiled geometric primitives: distances between segments, vertical rectangles and polygons.

Every function works on plain floats and arrays so numba compiles it into the simulator's hot loop.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.jit import CPUTargetOptions, njit

EPS = 1e-12

# Numba reference-counts every array that crosses a call or is bound to a new name, with an atomic
# increment and decrement; in the simulator's hot loop that bookkeeping cost a third of the run time.
# Functions that allocate nothing and return no array do not need it: they are compiled with numba's
# (private) ``_nrt=False`` flag, so their callers must keep the arrays alive, as every caller here does.
# Should a numba release drop the flag, they compile with reference counting as usual.
NO_REFCOUNT = {"_nrt": False} if hasattr(CPUTargetOptions, "_nrt") else {}


@njit(cache=True, error_model="numpy", inline="always")
def _clamp01(x):
    return 0.0 if x < 0.0 else (1.0 if x > 1.0 else x)


@njit(cache=True, error_model="numpy", inline="always")
def segment_segment(p1, q1, p2, q2, c1, c2):
    """Squared distance between segments p1q1 and p2q2; closest points written to c1, c2."""
    d2, c1[0], c1[1], c1[2], c2[0], c2[1], c2[2] = segment_segment_xyz(
        p1[0], p1[1], p1[2], q1[0], q1[1], q1[2], p2[0], p2[1], p2[2], q2[0], q2[1], q2[2])
    return d2


@njit(cache=True, error_model="numpy", inline="always")
def segment_segment_xyz(p1x, p1y, p1z, q1x, q1y, q1z, p2x, p2y, p2z, q2x, q2y, q2z):
    """(squared distance, closest point on p1q1, closest point on p2q2) for two segments given by coordinates.

    Ericson, *Real-Time Collision Detection* (2005), sec. 5.1.9, with both degenerate cases handled.
    (Scalars in and out: the hot loops call this, and arrays or row views would be reference-counted.)
    """
    d1x, d1y, d1z = q1x - p1x, q1y - p1y, q1z - p1z
    d2x, d2y, d2z = q2x - p2x, q2y - p2y, q2z - p2z
    rx, ry, rz = p1x - p2x, p1y - p2y, p1z - p2z
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    if a <= EPS and e <= EPS:
        s = 0.0
        t = 0.0
    elif a <= EPS:
        s = 0.0
        t = _clamp01(f / e)
    else:
        c = d1x * rx + d1y * ry + d1z * rz
        if e <= EPS:
            t = 0.0
            s = _clamp01(-c / a)
        else:
            b = d1x * d2x + d1y * d2y + d1z * d2z
            denom = a * e - b * b  # = a e sin^2(angle): parallel test relative to the lengths (scale-free)
            s = _clamp01((b * f - c * e) / denom) if denom > EPS * a * e else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                t = 0.0
                s = _clamp01(-c / a)
            elif t > 1.0:
                t = 1.0
                s = _clamp01((b - c) / a)
    c1x, c1y, c1z = p1x + d1x * s, p1y + d1y * s, p1z + d1z * s
    c2x, c2y, c2z = p2x + d2x * t, p2y + d2y * t, p2z + d2z * t
    dx, dy, dz = c1x - c2x, c1y - c2y, c1z - c2z
    return dx * dx + dy * dy + dz * dz, c1x, c1y, c1z, c2x, c2y, c2z


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def point_segment_2d(px, py, ax, ay, bx, by):
    """Distance from point p to segment ab in the plane."""
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    t = 0.0 if den <= EPS else _clamp01(((px - ax) * dx + (py - ay) * dy) / den)
    ex, ey = px - (ax + t * dx), py - (ay + t * dy)
    return np.sqrt(ex * ex + ey * ey)


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def point_in_polygon(px, py, verts, start, count):
    """Crossing-number test against polygon verts[start:start+count]."""
    inside = False
    j = start + count - 1
    for i in range(start, start + count):
        xi, yi = verts[i, 0], verts[i, 1]
        xj, yj = verts[j, 0], verts[j, 1]
        if (yi > py) != (yj > py):
            xc = xi + (py - yi) * (xj - xi) / (yj - yi)
            if px < xc:
                inside = not inside
        j = i
    return inside


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def polygon_distance(px, py, verts, start, count):
    """Distance from p to the polygon's region: 0 inside, else distance to its boundary."""
    if point_in_polygon(px, py, verts, start, count):
        return 0.0
    best = np.inf
    j = start + count - 1
    for i in range(start, start + count):
        d = point_segment_2d(px, py, verts[j, 0], verts[j, 1], verts[i, 0], verts[i, 1])
        if d < best:
            best = d
        j = i
    return best


@njit(cache=True, error_model="numpy")
def segment_rectangle(a, b, rect, c1, c2, scratch):
    """Distance between segment ab and a vertical rectangle.

    rect = (x0, y0, x1, y1, zlo, zhi): the rectangle spans the floor segment (x0, y0)-(x1, y1) between heights
    zlo and zhi. Closest points go to c1 (segment) and c2 (rectangle). (scratch is unused, kept for callers.)
    """
    d, c1[0], c1[1], c1[2], c2[0], c2[1], c2[2] = segment_rectangle_xyz(
        a[0], a[1], a[2], b[0], b[1], b[2], rect[0], rect[1], rect[2], rect[3], rect[4], rect[5])
    return d


@njit(cache=True, error_model="numpy", inline="always")
def segment_rectangle_xyz(ax, ay, az, bx, by, bz, x0, y0, x1, y1, zlo, zhi):
    """(distance, closest point on the segment, closest point on the rectangle) for segment ab and the
    vertical rectangle over the floor segment (x0, y0)-(x1, y1) between heights zlo and zhi."""
    ux, uy = x1 - x0, y1 - y0
    w = np.sqrt(ux * ux + uy * uy)
    ux /= w
    uy /= w
    nx, ny = -uy, ux
    # signed distances of the endpoints from the rectangle's plane
    sa = (ax - x0) * nx + (ay - y0) * ny
    sb = (bx - x0) * nx + (by - y0) * ny
    # signs, not the product: two tiny distances of one sign multiply to 0.0 (underflow) and would pass
    if ((sa <= 0.0 and sb >= 0.0) or (sa >= 0.0 and sb <= 0.0)) and sa != sb:
        t = sa / (sa - sb)
        cx, cy, cz = ax + t * (bx - ax), ay + t * (by - ay), az + t * (bz - az)
        u = (cx - x0) * ux + (cy - y0) * uy
        if 0.0 <= u <= w and zlo <= cz <= zhi:
            return 0.0, cx, cy, cz, cx, cy, cz
    best = np.inf
    c1x = c1y = c1z = c2x = c2y = c2z = 0.0
    # endpoints against the rectangle face
    for k in range(2):
        px, py, pz = (ax, ay, az) if k == 0 else (bx, by, bz)
        u = (px - x0) * ux + (py - y0) * uy
        u = 0.0 if u < 0.0 else (w if u > w else u)
        z = zlo if pz < zlo else (zhi if pz > zhi else pz)
        qx, qy = x0 + u * ux, y0 + u * uy
        d2 = (px - qx) ** 2 + (py - qy) ** 2 + (pz - z) ** 2
        if d2 < best:
            best = d2
            c1x, c1y, c1z = px, py, pz
            c2x, c2y, c2z = qx, qy, z
    # the segment against the four edges
    for k in range(4):
        if k == 0:
            e0x, e0y, e0z, e1x, e1y, e1z = x0, y0, zlo, x1, y1, zlo
        elif k == 1:
            e0x, e0y, e0z, e1x, e1y, e1z = x0, y0, zhi, x1, y1, zhi
        elif k == 2:
            e0x, e0y, e0z, e1x, e1y, e1z = x0, y0, zlo, x0, y0, zhi
        else:
            e0x, e0y, e0z, e1x, e1y, e1z = x1, y1, zlo, x1, y1, zhi
        d2, t1x, t1y, t1z, t2x, t2y, t2z = segment_segment_xyz(ax, ay, az, bx, by, bz, e0x, e0y, e0z, e1x, e1y, e1z)
        if d2 < best:
            best = d2
            c1x, c1y, c1z = t1x, t1y, t1z
            c2x, c2y, c2z = t2x, t2y, t2z
    return np.sqrt(best), c1x, c1y, c1z, c2x, c2y, c2z


@njit(cache=True, error_model="numpy", inline="always")
def capsule_touches_prism(ax, ay, az, bx, by, bz, r, verts, start, count, h):
    """True when the capsule (segment ab, radius r) comes closer than r to the prism that raises the polygon
    verts[start:start+count] from the floor to height h.

    Only the part of the segment at most r above the top can come that close, so it is clipped to z <= h + r.
    A point of that part over the polygon is within r of the prism (inside it, or above its top); otherwise the
    closest point lies on a side wall, and a part that passes over the polygon crosses a wall's plan line
    below h + r, within r of that wall. So: an end of the clipped part over the polygon, or a side wall within r.
    """
    top = h + r
    if az > top and bz > top:
        return False
    if az > top:
        t = (top - bz) / (az - bz)
        ax, ay, az = bx + t * (ax - bx), by + t * (ay - by), top
    elif bz > top:
        t = (top - az) / (bz - az)
        bx, by, bz = ax + t * (bx - ax), ay + t * (by - ay), top
    if point_in_polygon(ax, ay, verts, start, count) or point_in_polygon(bx, by, verts, start, count):
        return True
    j = start + count - 1
    for i in range(start, start + count):
        if segment_rectangle_xyz(ax, ay, az, bx, by, bz, verts[j, 0], verts[j, 1], verts[i, 0], verts[i, 1],
                                 0.0, h)[0] < r:
            return True
        j = i
    return False


@njit(cache=True, error_model="numpy")
def segment_crosses_rectangle(a, b, rect):
    """True when segment ab passes through the vertical rectangle (strictly crossing its plane)."""
    x0, y0, x1, y1, zlo, zhi = rect[0], rect[1], rect[2], rect[3], rect[4], rect[5]
    ux, uy = x1 - x0, y1 - y0
    nx, ny = -uy, ux
    sa = (a[0] - x0) * nx + (a[1] - y0) * ny
    sb = (b[0] - x0) * nx + (b[1] - y0) * ny
    if not ((sa < 0.0 < sb) or (sb < 0.0 < sa)):  # strictly opposite signs (a product may underflow)
        return False
    t = sa / (sa - sb)
    cx, cy, cz = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])
    u = ((cx - x0) * ux + (cy - y0) * uy) / (ux * ux + uy * uy)
    return 0.0 <= u <= 1.0 and zlo <= cz <= zhi
