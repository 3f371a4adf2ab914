"""Plane geometry in plain Python, for checks outside the compiled simulator (a cell file's start points)."""

from __future__ import annotations

import math
from collections.abc import Sequence

Point2 = tuple[float, float]


def point_segment_distance(px: float, py: float, a: Point2, b: Point2) -> float:
    """Distance from point p to segment ab."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    den = dx * dx + dy * dy
    t = 0.0 if den <= 1e-24 else min(1.0, max(0.0, ((px - a[0]) * dx + (py - a[1]) * dy) / den))
    return math.hypot(px - (a[0] + t * dx), py - (a[1] + t * dy))


def point_in_polygon(px: float, py: float, poly: Sequence[Point2]) -> bool:
    """Crossing-number test."""
    inside = False
    j = len(poly) - 1
    for i in range(len(poly)):
        (xi, yi), (xj, yj) = poly[i], poly[j]
        if (yi > py) != (yj > py) and px < xi + (py - yi) * (xj - xi) / (yj - yi):
            inside = not inside
        j = i
    return inside


def polygon_distance(px: float, py: float, poly: Sequence[Point2]) -> float:
    """Distance from p to the polygon's region: 0 inside, else the distance to its boundary."""
    if point_in_polygon(px, py, poly):
        return 0.0
    return min(point_segment_distance(px, py, poly[i - 1], poly[i]) for i in range(len(poly)))


def _meets(a: Point2, b: Point2, c: Point2, d: Point2) -> list[float]:
    """Where segment ab meets segment cd, as parameters t of ab (0 at a, 1 at b): one where they cross or touch,
    the two ends of the shared stretch where they overlap, none otherwise."""
    rx, ry, sx, sy = b[0] - a[0], b[1] - a[1], d[0] - c[0], d[1] - c[1]
    den = rx * sy - ry * sx
    qx, qy = c[0] - a[0], c[1] - a[1]
    if abs(den) < 1e-15:
        if abs(qx * ry - qy * rx) > 1e-12:
            return []  # parallel, apart
        rr = rx * rx + ry * ry
        if rr < 1e-24:
            return []
        t0, t1 = (qx * rx + qy * ry) / rr, ((d[0] - a[0]) * rx + (d[1] - a[1]) * ry) / rr
        lo, hi = max(0.0, min(t0, t1)), min(1.0, max(t0, t1))
        return [lo, hi] if lo <= hi else []
    t = (qx * sy - qy * sx) / den
    u = (qx * ry - qy * rx) / den
    return [t] if -1e-12 <= t <= 1 + 1e-12 and -1e-12 <= u <= 1 + 1e-12 else []


def _inside_or_on(p: Point2, poly: Sequence[Point2], tol: float) -> bool:
    return point_in_polygon(p[0], p[1], poly) or \
        min(point_segment_distance(p[0], p[1], poly[i - 1], poly[i]) for i in range(len(poly))) <= tol


def polygon_outside_point(inner: Sequence[Point2], outer: Sequence[Point2], tol: float = 1e-9) -> Point2 | None:
    """A point of the simple polygon ``inner`` (its region, boundary included) that lies outside ``outer``, or
    None when ``outer`` contains ``inner`` (sharing boundary allowed).

    ``inner`` leaves ``outer`` only where one of its edges meets ``outer``'s boundary: so it is contained iff its
    vertices are, and the midpoint of every piece of its edges between two such meeting points is."""
    for p in inner:
        if not _inside_or_on(p, outer, tol):
            return (float(p[0]), float(p[1]))
    n, m = len(inner), len(outer)
    for i in range(n):
        a, b = inner[i], inner[(i + 1) % n]
        ts = sorted({0.0, 1.0, *(t for j in range(m) for t in _meets(a, b, outer[j], outer[(j + 1) % m]))})
        for t0, t1 in zip(ts, ts[1:], strict=False):
            t = 0.5 * (t0 + t1)
            mid = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
            if not _inside_or_on(mid, outer, tol):
                return mid
    return None
