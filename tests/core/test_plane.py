"""Plane geometry of core.plane: polygon containment against dense sampling (issue 29: a warning field must
contain its protective field)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cellstress.core.plane import point_in_polygon, polygon_distance, polygon_outside_point


def _star(rng: np.random.Generator, n: int, cx: float, cy: float, r0: float, r1: float) -> tuple:
    """A random simple polygon: n corners at increasing angles around (cx, cy), radii in [r0, r1]."""
    angles = np.sort(rng.uniform(0.0, 2 * math.pi, n))
    radii = rng.uniform(r0, r1, n)
    return tuple((float(cx + r * math.cos(a)), float(cy + r * math.sin(a))) for a, r in zip(angles, radii,
                                                                                             strict=True))


def _samples(poly: tuple, per_edge: int = 150) -> list[tuple[float, float]]:
    pts = []
    for i in range(len(poly)):
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % len(poly)]
        pts += [(ax + t * (bx - ax), ay + t * (by - ay)) for t in np.linspace(0.0, 1.0, per_edge)]
    return pts


@pytest.mark.parametrize("seed", range(40))
def test_containment_agrees_with_dense_sampling(seed):
    rng = np.random.default_rng(seed)
    outer = _star(rng, int(rng.integers(3, 12)), 0.0, 0.0, 0.6, 1.6)
    inner = _star(rng, int(rng.integers(3, 12)), *rng.uniform(-0.3, 0.3, 2), 0.1, 0.9)
    found = polygon_outside_point(inner, outer)
    outside = [p for p in _samples(inner) if not point_in_polygon(*p, outer)
               and polygon_distance(*p, outer) > 1e-7]
    if found is None:
        assert outside == [], f"contained, but sampling finds {outside[:3]} outside"
    else:  # the point it names is in inner's region (its boundary) and really outside outer
        assert polygon_distance(*found, outer) > 0.0
        assert polygon_distance(*found, inner) <= 1e-9


def test_the_sampled_cases_include_both_verdicts():
    verdicts = set()
    for seed in range(40):
        rng = np.random.default_rng(seed)
        outer = _star(rng, int(rng.integers(3, 12)), 0.0, 0.0, 0.6, 1.6)
        inner = _star(rng, int(rng.integers(3, 12)), *rng.uniform(-0.3, 0.3, 2), 0.1, 0.9)
        verdicts.add(polygon_outside_point(inner, outer) is None)
    assert verdicts == {True, False}


def test_shared_edges_and_corners_count_as_inside():
    square = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))
    assert polygon_outside_point(square, square) is None
    # an edge along the boundary of a concave outer polygon, through its reflex corners
    u = ((0.0, 0.0), (3.0, 0.0), (3.0, 3.0), (2.0, 3.0), (2.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0))
    assert polygon_outside_point(((0.5, 0.5), (2.5, 0.5), (2.0, 1.0), (1.0, 1.0)), u) is None
    assert polygon_outside_point(((0.5, 2.0), (2.5, 2.0), (1.5, 0.5)), u) is not None
