"""The compiled geometric primitives against brute force.

Every exact distance d returned by a kernel is checked two ways against a dense sampling of the shapes:

* the closest points it writes lie on the shapes and are d apart, so d >= the true minimum; and no sampled
  pair of points is closer than d (up to round-off), so d <= the true minimum. Together: d is exact and the
  closest points are genuine.
* the sampled minimum is no more than the sampling error above d. For N equally spaced samples on a segment
  of length L, the true closest point is within L / (2 (N - 1)) of a sample, so (triangle inequality) the
  sampled minimum exceeds the true one by at most the sum of those half-spacings over both shapes.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as MplPath
from scipy.spatial.distance import cdist

from cellstress.sim.geometry import (
    EPS,
    point_in_polygon,
    point_segment_2d,
    polygon_distance,
    segment_crosses_rectangle,
    segment_rectangle,
    segment_segment,
)

ROUND = 1e-9  # round-off allowance [m] for coordinates of order 1 m (float64 gives ~1e-15)
N_SEG = 401  # samples per segment
N_RECT = 81  # samples per rectangle side (a N_RECT x N_RECT grid)

SETTINGS = settings(max_examples=3000, deadline=None, derandomize=False, database=None,
                    suppress_health_check=[HealthCheck.too_slow])

coord = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)
point3 = st.tuples(coord, coord, coord).map(lambda t: np.array(t, dtype=float))
factor = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)


def samples(p, q, n=N_SEG):
    return p + np.linspace(0.0, 1.0, n)[:, None] * (q - p)


def dist_to_segment(x, p, q):
    """Euclidean distance from point x to segment pq (independent of the kernels: plain numpy)."""
    d = q - p
    den = float(d @ d)
    t = 0.0 if den == 0.0 else float(np.clip((x - p) @ d / den, 0.0, 1.0))
    return float(np.linalg.norm(x - (p + t * d)))


def unit(v):
    """v's direction; x for a vector too short to have one (a norm that underflows would blow v up to 1e40)."""
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-6 else np.array([1.0, 0.0, 0.0])


@st.composite
def segment_pairs(draw):
    """Two 3-D segments: general, degenerate (zero length), parallel, collinear, crossing or tiny."""
    kind = draw(st.sampled_from(["general", "point-seg", "seg-point", "point-point", "parallel",
                                 "collinear", "crossing", "tiny"]))
    p1, q1, p2, q2 = draw(point3), draw(point3), draw(point3), draw(point3)
    if kind == "point-seg":
        q1 = p1.copy()
    elif kind == "seg-point":
        q2 = p2.copy()
    elif kind == "point-point":
        q1, q2 = p1.copy(), p2.copy()
    elif kind == "parallel":
        q2 = p2 + draw(factor) * (q1 - p1)
    elif kind == "collinear":
        d = q1 - p1
        p2, q2 = p1 + draw(factor) * d, p1 + draw(factor) * d
    elif kind == "crossing":
        # the segments meet at x = p1 + s (q1 - p1) = p2 + t (q2 - p2) for s, t in [0, 1]
        s, t = draw(st.floats(0.0, 1.0)), draw(st.floats(0.0, 1.0))
        x = p1 + s * (q1 - p1)
        d2 = q2 - p2
        p2 = x - t * d2
        q2 = p2 + d2
    elif kind == "tiny":
        # millimetre-sized segments near each other
        scale = 1e-3
        p2 = p1 + scale * unit(p2 - p1) * draw(st.floats(0.0, 2.0))
        q1 = p1 + scale * unit(q1 - p1)
        q2 = p2 + scale * unit(q2 - p2)
    # coordinates stay of the order of a cell (the round-off allowances below assume metres, not 1e40 m)
    assert max(float(np.abs(v).max()) for v in (p1, q1, p2, q2)) <= 20.0
    return kind, p1, q1, p2, q2


def point_slack(*segments):
    """How far the kernel may be from the exact distance, by its own tolerance EPS (under a micrometre per metre
    of segment; the simulator's margins are millimetres):

    * a segment whose squared length is at most EPS is taken for its start point: up to its length;
    * two segments whose angle has sin^2 at most EPS are taken as parallel (Ericson's s = 0): the distance
      varies by at most sqrt(EPS) per metre along their overlap.
    """
    lengths = [float(np.linalg.norm(q - p)) for p, q in segments]
    slack = sum(n for n in lengths if n * n <= EPS * (1.0 + 1e-9))
    if len(segments) == 2 and min(lengths) > 1e-100:
        (p1, q1), (p2, q2) = segments
        u1, u2 = (q1 - p1) / lengths[0], (q2 - p2) / lengths[1]
        sin2 = float(np.sum(np.cross(u1, u2) ** 2))
        if sin2 <= EPS * (1.0 + 1e-6):
            slack += np.sqrt(EPS) * max(lengths)
    return slack


def check_segment_segment(p1, q1, p2, q2):
    c1, c2 = np.full(3, np.nan), np.full(3, np.nan)
    d2 = segment_segment(p1, q1, p2, q2, c1, c2)
    assert np.isfinite(d2) and d2 >= 0.0
    d = np.sqrt(d2)
    slack = point_slack((p1, q1), (p2, q2))
    # the closest points are on the segments and d apart
    assert dist_to_segment(c1, p1, q1) <= ROUND + slack
    assert dist_to_segment(c2, p2, q2) <= ROUND + slack
    assert abs(np.linalg.norm(c1 - c2) - d) <= ROUND
    # no sampled pair is closer than d; and d is not above the sampled minimum by more than the sampling error
    brute = cdist(samples(p1, q1), samples(p2, q2)).min()
    tol = (np.linalg.norm(q1 - p1) + np.linalg.norm(q2 - p2)) / (2 * (N_SEG - 1))
    assert d <= brute + ROUND + slack, f"segment_segment {d} > brute force {brute}"
    assert d >= brute - tol - ROUND, f"segment_segment {d} < brute force {brute} - {tol}"
    return d, c1, c2


@SETTINGS
@given(segment_pairs())
@example(("parallel", np.zeros(3), np.array([0.0, 0.0, 2.0]), np.zeros(3), np.array([0.0, 0.0, -2e-9])))
@example(("general", np.zeros(3), np.zeros(3), np.zeros(3), np.array([0.0, 0.0, 2.755e-8])))
@example(("general", np.zeros(3), np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]), np.array([0.0, 1e-7, 0.0])))
def test_segment_segment_matches_brute_force(pair):
    kind, p1, q1, p2, q2 = pair
    d, _, _ = check_segment_segment(p1, q1, p2, q2)
    if kind == "crossing":
        assert d <= ROUND + point_slack((p1, q1), (p2, q2))
    # symmetric in the two segments and in each segment's direction; a segment under a micrometre is taken for
    # one of its ends, which one depending on the direction (the full suite drew one 2e-9 m long, parallel to
    # the other: 2e-9 m apart one way, 0 the other)
    c1, c2 = np.zeros(3), np.zeros(3)
    allow = ROUND + point_slack((p1, q1), (p2, q2))
    for args in ((p2, q2, p1, q1), (q1, p1, q2, p2)):
        assert abs(np.sqrt(segment_segment(*args, c1, c2)) - d) <= allow


@pytest.mark.parametrize(
    ("p1", "q1", "p2", "q2", "expected"),
    [
        # skew perpendicular segments one above the other: distance 1 between the midpoints
        ((-1, 0, 0), (1, 0, 0), (0, -1, 1), (0, 1, 1), 1.0),
        # parallel, overlapping in projection
        ((0, 0, 0), (2, 0, 0), (1, 3, 0), (4, 3, 0), 3.0),
        # parallel, disjoint in projection: end to end
        ((0, 0, 0), (1, 0, 0), (4, 4, 0), (5, 4, 0), 5.0),
        # collinear, gap of 2
        ((0, 0, 0), (1, 0, 0), (3, 0, 0), (5, 0, 0), 2.0),
        # both degenerate
        ((1, 2, 3), (1, 2, 3), (4, 6, 3), (4, 6, 3), 5.0),
        # point against a segment, projecting beyond its end
        ((0, 0, 0), (0, 0, 0), (3, 4, 0), (6, 8, 0), 5.0),
        # crossing
        ((-1, 0, 0), (1, 0, 0), (0, -1, 0), (0, 1, 0), 0.0),
    ],
)
def test_segment_segment_known_values(p1, q1, p2, q2, expected):
    d, _, _ = check_segment_segment(*(np.asarray(v, dtype=float) for v in (p1, q1, p2, q2)))
    assert d == pytest.approx(expected, abs=1e-12)


# ---- segment against a vertical rectangle ------------------------------------------------------------------
def rect_samples(rect, n=N_RECT):
    x0, y0, x1, y1, zlo, zhi = rect
    u = np.linspace(0.0, 1.0, n)
    uu, vv = np.meshgrid(u, u, indexing="ij")
    uu, vv = uu.ravel(), vv.ravel()
    return np.stack([x0 + uu * (x1 - x0), y0 + uu * (y1 - y0), zlo + vv * (zhi - zlo)], axis=1)


def dist_to_rect(x, rect):
    """Exact distance from point(s) x (..., 3) to the rectangle, by clamping in-plane coordinates (numpy)."""
    x = np.asarray(x, dtype=float)
    x0, y0, x1, y1, zlo, zhi = rect
    ex, ey = x1 - x0, y1 - y0
    w = np.hypot(ex, ey)
    u = np.clip(((x[..., 0] - x0) * ex + (x[..., 1] - y0) * ey) / w, 0.0, w)
    q = np.stack([x0 + u * ex / w, y0 + u * ey / w, np.clip(x[..., 2], zlo, zhi)], axis=-1)
    return np.linalg.norm(x - q, axis=-1)


@st.composite
def segment_and_rectangle(draw):
    kind = draw(st.sampled_from(["general", "general", "point", "in-plane", "parallel-to-plane", "piercing",
                                 "near-edge"]))
    x0, y0 = draw(coord), draw(coord)
    ang = draw(st.floats(0.0, 2 * np.pi))
    w = draw(st.floats(0.05, 3.0))
    zlo = draw(st.floats(0.0, 1.0))
    zhi = zlo + draw(st.floats(0.0, 2.0))  # zero height (a horizontal line) included
    rect = np.array([x0, y0, x0 + w * np.cos(ang), y0 + w * np.sin(ang), zlo, zhi])
    a, b = draw(point3), draw(point3)
    a[2] += 1.0
    b[2] += 1.0
    ux, uy = np.cos(ang), np.sin(ang)
    n = np.array([-uy, ux, 0.0])
    if kind == "point":
        b = a.copy()
    elif kind == "in-plane":  # the segment lies in the rectangle's plane
        a = a - ((a[0] - x0) * n[0] + (a[1] - y0) * n[1]) * n
        b = b - ((b[0] - x0) * n[0] + (b[1] - y0) * n[1]) * n
    elif kind == "parallel-to-plane":  # both ends at the same signed distance
        sa = (a[0] - x0) * n[0] + (a[1] - y0) * n[1]
        sb = (b[0] - x0) * n[0] + (b[1] - y0) * n[1]
        b = b + (sa - sb) * n
    elif kind == "piercing":  # passes through a point of the rectangle
        fu, fz, ft = draw(st.floats(0.0, 1.0)), draw(st.floats(0.0, 1.0)), draw(st.floats(0.0, 1.0))
        x = np.array([x0 + fu * w * ux, y0 + fu * w * uy, zlo + fz * (zhi - zlo)])
        d = b - a
        a = x - ft * d
        b = a + d
    elif kind == "near-edge":  # a short segment just outside an edge or corner
        fu = draw(st.sampled_from([0.0, 1.0, 0.5]))
        fz = draw(st.sampled_from([0.0, 1.0, 0.5]))
        x = np.array([x0 + fu * w * ux, y0 + fu * w * uy, zlo + fz * (zhi - zlo)])
        a = x + 0.01 * (a - x)
        b = x + 0.01 * (b - x)
    return kind, a, b, rect


@SETTINGS
@given(segment_and_rectangle())
def test_segment_rectangle_matches_brute_force(case):
    kind, a, b, rect = case
    c1, c2 = np.full(3, np.nan), np.full(3, np.nan)
    d = segment_rectangle(a, b, rect, c1, c2, np.zeros((4, 3)))
    assert np.isfinite(d) and d >= 0.0
    # the kernel measures the segment against the rectangle's four edges, each within its own tolerance
    x0, y0, x1, y1, zlo, zhi = rect
    corners = [np.array(c) for c in ((x0, y0, zlo), (x1, y1, zlo), (x1, y1, zhi), (x0, y0, zhi))]
    slack = max(point_slack((a, b), (corners[k], corners[(k + 1) % 4])) for k in range(4))
    # closest points on the segment / on the rectangle and d apart
    assert dist_to_segment(c1, a, b) <= ROUND
    assert dist_to_rect(c2, rect) <= ROUND
    assert abs(np.linalg.norm(c1 - c2) - d) <= ROUND
    # brute force: samples of the segment against samples of the rectangle
    seg = samples(a, b, 201)
    brute = cdist(seg, rect_samples(rect)).min()
    w = np.hypot(rect[2] - rect[0], rect[3] - rect[1])
    h = rect[5] - rect[4]
    tol = np.linalg.norm(b - a) / (2 * 200) + 0.5 * np.hypot(w, h) / (N_RECT - 1)
    assert d <= brute + ROUND + slack, f"segment_rectangle {d} > brute force {brute}"
    assert d >= brute - tol - ROUND, f"segment_rectangle {d} < brute force {brute} - {tol}"
    # tighter: samples of the segment against the exact point-rectangle distance
    fine = dist_to_rect(samples(a, b, 1001), rect).min()
    assert d <= fine + ROUND + slack
    assert d >= fine - np.linalg.norm(b - a) / (2 * 1000) - ROUND
    if kind == "piercing":
        assert d <= ROUND + slack
    # a strict crossing of the plane inside the rectangle means contact
    if segment_crosses_rectangle(a, b, rect):
        assert d <= ROUND + slack


def test_segment_rectangle_known_values():
    rect = np.array([0.0, 0.0, 2.0, 0.0, 0.5, 1.5])  # in the plane y = 0, x in [0, 2], z in [0.5, 1.5]
    c1, c2, scratch = np.zeros(3), np.zeros(3), np.zeros((4, 3))
    cases = [
        ((1.0, -1.0, 1.0), (1.0, 1.0, 1.0), 0.0),  # pierces the middle
        ((1.0, 3.0, 1.0), (1.0, 1.0, 1.0), 1.0),  # points at the face from 1 m
        ((3.0, 0.0, 1.0), (5.0, 0.0, 1.0), 1.0),  # in plane, beyond the right edge
        ((1.0, -1.0, 2.5), (1.0, 1.0, 2.5), 1.0),  # passes 1 m above the top edge
        ((-3.0, 4.0, 1.0), (-3.0, 4.0, 1.0), 5.0),  # a point off the left edge
        ((3.0, 1.0, 3.5), (3.0, 1.0, 3.5), np.sqrt(1 + 1 + 4)),  # a point off the top right corner
        ((-1.0, -1.0, 1.0), (3.0, 1.0, 1.0), 0.0),  # diagonal through the face
    ]
    for a, b, expected in cases:
        d = segment_rectangle(np.array(a, float), np.array(b, float), rect, c1, c2, scratch)
        assert d == pytest.approx(expected, abs=1e-12), (a, b)


# ---- polygons ---------------------------------------------------------------------------------------------
BASELINE_POLYGONS = [
    # the baseline cell's U-shaped table and the scanner field around it (non-convex)
    [[-1.1, -0.5], [1.1, -0.5], [1.1, 1.4], [0.5, 1.4], [0.5, 0.4], [-0.5, 0.4], [-0.5, 1.4], [-1.1, 1.4]],
    [[-2.0, 3.3], [2.0, 3.3], [2.0, 1.4], [0.5, 1.4], [0.5, 0.4], [-0.5, 0.4], [-0.5, 1.4], [-2.0, 1.4]],
]


def star_polygon(rng, n):
    """A random simple (star-shaped, generally non-convex) polygon with n vertices, either orientation."""
    ang = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    r = rng.uniform(0.2, 1.0, n)
    c = rng.uniform(-1.0, 1.0, 2)
    poly = c + np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1)
    return poly[::-1].copy() if rng.random() < 0.5 else poly


def random_polygons():
    rng = np.random.default_rng(20240601)
    polys = [np.asarray(p, float) for p in BASELINE_POLYGONS]
    polys += [star_polygon(rng, n) for n in rng.integers(3, 16, 60)]
    # axis-aligned shapes whose edges pass exactly through sample coordinates
    polys.append(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))
    polys.append(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [1.0, 1.0], [0.0, 2.0]]))
    return polys


def boundary_distance(pts, poly, n_per_edge):
    """Distance from each point to the densely sampled boundary; returns (distances, sampling error)."""
    edges = list(zip(poly, np.roll(poly, -1, axis=0), strict=True))
    bnd = np.concatenate([samples(a, b, n_per_edge) for a, b in edges])
    longest = max(np.linalg.norm(b - a) for a, b in edges)
    return cdist(pts, bnd).min(axis=1), longest / (2 * (n_per_edge - 1))


def packed(polys):
    """All polygons in one vertex array, as the simulator stores them (start, count per polygon)."""
    index, start = [], 0
    for p in polys:
        index.append((start, len(p)))
        start += len(p)
    return np.ascontiguousarray(np.concatenate(polys)), index


def test_point_in_polygon_matches_matplotlib():
    polys = random_polygons()
    verts, index = packed(polys)
    rng = np.random.default_rng(7)
    checked = disagree = 0
    for poly, (start, count) in zip(polys, index, strict=True):
        lo, hi = poly.min(axis=0) - 0.3, poly.max(axis=0) + 0.3
        pts = rng.uniform(lo, hi, (400, 2))
        # grid points too: they share x or y with vertices of the axis-aligned shapes
        g = np.linspace(lo, hi, 21)
        pts = np.concatenate([pts, np.stack(np.meshgrid(g[:, 0], g[:, 1]), axis=-1).reshape(-1, 2), poly])
        edge_d = np.array([min(point_segment_2d(x, y, *a, *b) for a, b in
                               zip(poly, np.roll(poly, -1, axis=0), strict=True)) for x, y in pts])
        path = MplPath(poly, closed=False)
        for (x, y), e in zip(pts, edge_d, strict=True):
            if e < 1e-9:  # on the boundary: either answer is acceptable
                continue
            checked += 1
            if bool(point_in_polygon(x, y, verts, start, count)) != bool(path.contains_point((x, y))):
                disagree += 1
    assert checked > 20000
    assert disagree == 0


def test_polygon_distance_matches_boundary_sampling():
    polys = random_polygons()
    verts, index = packed(polys)
    rng = np.random.default_rng(11)
    n_per_edge = 2001
    for poly, (start, count) in zip(polys, index, strict=True):
        lo, hi = poly.min(axis=0) - 1.0, poly.max(axis=0) + 1.0
        pts = rng.uniform(lo, hi, (150, 2))
        brute, tol = boundary_distance(pts, poly, n_per_edge)
        inside = MplPath(poly).contains_points(pts)
        d = np.array([polygon_distance(x, y, verts, start, count) for x, y in pts])
        assert np.all(d >= 0.0)
        clear = brute > 1e-6
        # inside: zero; outside: the distance to the boundary, exact up to the sampling error
        np.testing.assert_array_equal(d[inside & clear], 0.0)
        out = ~inside & clear
        assert np.all(d[out] <= brute[out] + ROUND)
        assert np.all(d[out] >= brute[out] - tol - ROUND)
        assert np.all(d[out] > 0.0)


@pytest.mark.parametrize(
    ("x", "y", "expected"),
    [
        (0.0, 0.0, 0.0),  # inside the U, in its base
        (0.0, 1.0, 0.5),  # in the notch: 0.5 m from both inner walls
        (0.0, 2.0, np.hypot(0.5, 0.6)),  # in front of the notch: nearest a tip's inner corner
        (0.0, -1.5, 1.0),  # behind the table
        (-2.1, 0.0, 1.0),  # beside it
        (1.5, 1.8, np.hypot(0.4, 0.4)),  # off a corner
        (-0.8, 1.0, 0.0),  # in a leg
    ],
)
def test_polygon_distance_known_values(x, y, expected):
    verts, index = packed([np.asarray(p, float) for p in BASELINE_POLYGONS])
    start, count = index[0]
    assert polygon_distance(x, y, verts, start, count) == pytest.approx(expected, abs=1e-12)
    assert bool(point_in_polygon(x, y, verts, start, count)) == (expected == 0.0)


def test_point_segment_2d_against_formula():
    rng = np.random.default_rng(3)
    for _ in range(2000):
        p, a, b = rng.uniform(-2, 2, (3, 2))
        if rng.random() < 0.1:
            b = a.copy()
        ref = dist_to_segment(np.append(p, 0.0), np.append(a, 0.0), np.append(b, 0.0))
        assert point_segment_2d(*p, *a, *b) == pytest.approx(ref, abs=1e-12)
