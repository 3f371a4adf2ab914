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
