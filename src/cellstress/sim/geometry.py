"""Compiled geometric primitives: distances between segments, vertical rectangles and polygons.

Every function works on plain floats and arrays so numba compiles it into the simulator's hot loop.
"""

from __future__ import annotations

import numpy as np
from numba import njit

EPS = 1e-12


@njit(cache=True, error_model="numpy", inline="always")
def _clamp01(x):
    return 0.0 if x < 0.0 else (1.0 if x > 1.0 else x)


@njit(cache=True, error_model="numpy", inline="always")
def segment_segment(p1, q1, p2, q2, c1, c2):
    """Squared distance between segments p1q1 and p2q2; closest points written to c1, c2.

    Ericson, *Real-Time Collision Detection* (2005), sec. 5.1.9, with both degenerate cases handled.
    """
    d1x, d1y, d1z = q1[0] - p1[0], q1[1] - p1[1], q1[2] - p1[2]
    d2x, d2y, d2z = q2[0] - p2[0], q2[1] - p2[1], q2[2] - p2[2]
    rx, ry, rz = p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2]
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
    c1[0], c1[1], c1[2] = p1[0] + d1x * s, p1[1] + d1y * s, p1[2] + d1z * s
    c2[0], c2[1], c2[2] = p2[0] + d2x * t, p2[1] + d2y * t, p2[2] + d2z * t
    dx, dy, dz = c1[0] - c2[0], c1[1] - c2[1], c1[2] - c2[2]
    return dx * dx + dy * dy + dz * dz


@njit(cache=True, error_model="numpy")
def point_segment_2d(px, py, ax, ay, bx, by):
    """Distance from point p to segment ab in the plane."""
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    t = 0.0 if den <= EPS else _clamp01(((px - ax) * dx + (py - ay) * dy) / den)
    ex, ey = px - (ax + t * dx), py - (ay + t * dy)
    return np.sqrt(ex * ex + ey * ey)


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
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
    zlo and zhi. Closest points go to c1 (segment) and c2 (rectangle). scratch is a (4, 3) work array.
    """
    x0, y0, x1, y1, zlo, zhi = rect[0], rect[1], rect[2], rect[3], rect[4], rect[5]
    ux, uy = x1 - x0, y1 - y0
    w = np.sqrt(ux * ux + uy * uy)
    ux /= w
    uy /= w
    nx, ny = -uy, ux
    # signed distances of the endpoints from the rectangle's plane
    sa = (a[0] - x0) * nx + (a[1] - y0) * ny
    sb = (b[0] - x0) * nx + (b[1] - y0) * ny
    if sa * sb <= 0.0 and sa != sb:
        t = sa / (sa - sb)
        cx, cy, cz = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])
        u = (cx - x0) * ux + (cy - y0) * uy
        if 0.0 <= u <= w and zlo <= cz <= zhi:
            c1[0], c1[1], c1[2] = cx, cy, cz
            c2[0], c2[1], c2[2] = cx, cy, cz
            return 0.0
    best = np.inf
    # endpoints against the rectangle face
    for k in range(2):
        p = a if k == 0 else b
        u = (p[0] - x0) * ux + (p[1] - y0) * uy
        u = 0.0 if u < 0.0 else (w if u > w else u)
        z = zlo if p[2] < zlo else (zhi if p[2] > zhi else p[2])
        qx, qy = x0 + u * ux, y0 + u * uy
        d2 = (p[0] - qx) ** 2 + (p[1] - qy) ** 2 + (p[2] - z) ** 2
        if d2 < best:
            best = d2
            c1[0], c1[1], c1[2] = p[0], p[1], p[2]
            c2[0], c2[1], c2[2] = qx, qy, z
    # the segment against the four edges
    e0 = scratch[0]
    e1 = scratch[1]
    t1 = scratch[2]
    t2 = scratch[3]
    for k in range(4):
        if k == 0:
            e0[0], e0[1], e0[2], e1[0], e1[1], e1[2] = x0, y0, zlo, x1, y1, zlo
        elif k == 1:
            e0[0], e0[1], e0[2], e1[0], e1[1], e1[2] = x0, y0, zhi, x1, y1, zhi
        elif k == 2:
            e0[0], e0[1], e0[2], e1[0], e1[1], e1[2] = x0, y0, zlo, x0, y0, zhi
        else:
            e0[0], e0[1], e0[2], e1[0], e1[1], e1[2] = x1, y1, zlo, x1, y1, zhi
        d2 = segment_segment(a, b, e0, e1, t1, t2)
        if d2 < best:
            best = d2
            c1[0], c1[1], c1[2] = t1[0], t1[1], t1[2]
            c2[0], c2[1], c2[2] = t2[0], t2[1], t2[2]
    return np.sqrt(best)


@njit(cache=True, error_model="numpy")
def segment_crosses_rectangle(a, b, rect):
    """True when segment ab passes through the vertical rectangle (strictly crossing its plane)."""
    x0, y0, x1, y1, zlo, zhi = rect[0], rect[1], rect[2], rect[3], rect[4], rect[5]
    ux, uy = x1 - x0, y1 - y0
    nx, ny = -uy, ux
    sa = (a[0] - x0) * nx + (a[1] - y0) * ny
    sb = (b[0] - x0) * nx + (b[1] - y0) * ny
    if sa * sb >= 0.0:
        return False
    t = sa / (sa - sb)
    cx, cy, cz = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])
    u = ((cx - x0) * ux + (cy - y0) * uy) / (ux * ux + uy * uy)
    return 0.0 <= u <= 1.0 and zlo <= cz <= zhi
