"""The reach field (signed distance to the arm's workspace) against the arm's forward kinematics.

Everything is in the RIGHT shoulder frame: x forward, y to the body's left, z up. The reference here is
cellstress.human.reach.arm_points (the arm model itself); the field is a rasterised, closed and
distance-transformed sampling of it, so it may be off by about a grid spacing h, not more:

* every point of the arm, in any configuration within the joint ranges, is inside the field's surface or
  within one voxel diagonal of it (distance <= h sqrt(3));
* nothing farther than arm length + 2 h from the shoulder is inside (the arm can't reach there);
* points the field calls clearly inside (distance < -2 h) are touched by the arm, to within 2 h, in some
  configuration that an optimiser finds.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.spatial import cKDTree

from cellstress.human.reach import JOINT_RANGES_DEG, arm_points, reach_field

LENGTHS = (0.30, 0.31, 0.18)  # upper arm, forearm, hand [m]
ARM = float(sum(LENGTHS))
LO, HI = np.deg2rad(JOINT_RANGES_DEG).T
BOUNDS = list(zip(LO, HI, strict=True))


@pytest.fixture(scope="module")
def field():
    return reach_field(*LENGTHS)


# ---- independent references -------------------------------------------------------------------------------
def _rx(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def arm_chain(qs, lengths=LENGTHS):
    """Vectorised FK of the documented arm model for qs (m, 5) -> (m, 4, 3): shoulder, elbow, wrist, tip.

    Hanging straight down at q = 0; the upper arm's frame is abduction (about x, away from the body = -y),
    then flexion (about y, forward = +x), then rotation about the arm's own axis; elbow and wrist flex about
    the local y axis. Each segment points along its frame's -z."""
    qs = np.atleast_2d(qs)
    down = np.array([0.0, 0.0, -1.0])
    r = _rx(-qs[:, 1]) @ _ry(-qs[:, 0]) @ _rz(qs[:, 2])
    out = np.zeros((len(qs), 4, 3))
    out[:, 1] = lengths[0] * (r @ down)
    r = r @ _ry(-qs[:, 3])
    out[:, 2] = out[:, 1] + lengths[1] * (r @ down)
    r = r @ _ry(-qs[:, 4])
    out[:, 3] = out[:, 2] + lengths[2] * (r @ down)
    return out


def chain_points(chain, n):
    """n + 1 points along each of the three segments of every chain: (m, 3 (n + 1), 3)."""
    f = np.linspace(0.0, 1.0, n + 1)[None, None, :, None]
    a, b = chain[:, :-1, None, :], chain[:, 1:, None, :]
    return (a + f * (b - a)).reshape(len(chain), -1, 3)


def trilinear(field, pts):
    """numpy trilinear lookup, with the kernel's rule outside the grid (the distance to the grid added)."""
    v, h, o = field.values.astype(float), field.spacing, field.origin
    n = v.shape[0]
    top = o + (n - 1) * h
    c = np.clip(pts, o, top)
    extra = np.linalg.norm(pts - c, axis=-1)
    g = (c - o) / h
    i = np.minimum(g.astype(int), n - 2)
    f = g - i
    out = np.zeros(len(pts))
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                w = ((f[:, 0] if dx else 1 - f[:, 0]) * (f[:, 1] if dy else 1 - f[:, 1])
                     * (f[:, 2] if dz else 1 - f[:, 2]))
                out += w * v[i[:, 0] + dx, i[:, 1] + dy, i[:, 2] + dz]
    return out + extra


def random_configs(rng, n, at_limit=0.0):
    """Uniform in the joint box; with probability at_limit each joint sits exactly at one of its limits
    (the workspace's surface is made of configurations with joints at their limits)."""
    q = rng.uniform(LO, HI, (n, 5))
    if at_limit:
        pick = rng.random((n, 5)) < at_limit
        q = np.where(pick, np.where(rng.random((n, 5)) < 0.5, LO, HI), q)
    return q


# ---- the arm model and the lookup themselves --------------------------------------------------------------
def test_arm_points_matches_vectorised_reference():
    rng = np.random.default_rng(0)
    qs = random_configs(rng, 500, at_limit=0.2)
    ref = arm_chain(qs)
    for q, r in zip(qs, ref, strict=True):
        np.testing.assert_allclose(arm_points(q, np.asarray(LENGTHS)), r[1:], atol=1e-14)


@pytest.mark.parametrize(
    ("q_deg", "elbow", "tip"),
    [
        ((0, 0, 0, 0, 0), (0, 0, -0.30), (0, 0, -ARM)),  # hanging down
        ((90, 0, 0, 0, 0), (0.30, 0, 0), (ARM, 0, 0)),  # flexed: straight forward
        ((180, 0, 0, 0, 0), (0, 0, 0.30), (0, 0, ARM)),  # straight up
        ((0, 90, 0, 0, 0), (0, -0.30, 0), (0, -ARM, 0)),  # abducted: sideways away from the body (-y)
        ((-60, 0, 0, 0, 0), (-0.30 * np.sin(np.pi / 3), 0, -0.15), None),  # extended backwards
        ((0, 0, 0, 90, 0), (0, 0, -0.30), (0.49, 0, -0.30)),  # elbow flexed: forearm forward
        ((0, 0, 90, 90, 0), (0, 0, -0.30), (0, 0.49, -0.30)),  # ... rotated inwards: across the body (+y)
        ((0, 0, 0, 90, 80), (0, 0, -0.30),  # and the wrist flexed: hand turned up, 10 deg short of vertical
         (0.31 + 0.18 * np.sin(np.pi / 18), 0, -0.30 + 0.18 * np.cos(np.pi / 18))),
    ],
)
def test_arm_points_conventions(q_deg, elbow, tip):
    pts = arm_points(np.deg2rad(np.asarray(q_deg, float)), np.asarray(LENGTHS))
    np.testing.assert_allclose(pts[0], elbow, atol=1e-12)
    if tip is not None:
        np.testing.assert_allclose(pts[2], tip, atol=1e-12)
    # segment lengths are kept
    chain = np.vstack([np.zeros(3), pts])
    np.testing.assert_allclose(np.linalg.norm(np.diff(chain, axis=0), axis=1), LENGTHS, atol=1e-12)


def test_field_grid_covers_the_arm(field):
    n = field.values.shape[0]
    assert field.values.shape == (n, n, n) and field.values.dtype == np.float32
    assert field.spacing == pytest.approx(0.02)
    assert field.arm_length == pytest.approx(ARM)
    assert field.origin <= -ARM - 2 * field.spacing
    assert field.origin + (n - 1) * field.spacing >= ARM + 2 * field.spacing
    # the shoulder is deep inside, the corners of the grid are outside
    assert field.distance(np.zeros((1, 3)))[0] < -0.2
    assert field.values[0, 0, 0] > 0 and field.values[-1, -1, -1] > 0


def test_lookup_is_trilinear(field):
    """ReachField.distance (the kernel's reach_lookup) against the numpy reference, on and off the grid."""
    rng = np.random.default_rng(4)
    h, o = field.spacing, field.origin
    n = field.values.shape[0]
    nodes = rng.integers(0, n, (200, 3))
    np.testing.assert_allclose(field.distance(o + h * nodes), field.values[tuple(nodes.T)], atol=1e-6)
    pts = rng.uniform(-1.2, 1.2, (3000, 3))  # partly beyond the grid
    np.testing.assert_allclose(field.distance(pts), trilinear(field, pts), atol=1e-6)


# ---- the field against the arm ----------------------------------------------------------------------------
def _arm_field_max(q, field, n=20):
    """The largest field distance over n + 1 points on each arm segment in configuration q."""
    return trilinear(field, chain_points(arm_chain(q[None]), n)[0]).max()


def test_every_arm_point_is_inside_or_within_a_voxel(field):
    """No point of the arm is outside the field by more than a voxel diagonal (h sqrt(3)), in 40 000 random
    configurations (half with joints at their limits, where the workspace's surface is), 21 points per
    segment; then, from the 12 worst of them, a local search that pushes the arm as far out of the field as
    it can (holes in the surface sit between the joint samples the field was rasterised from)."""
    h = field.spacing
    bound = h * np.sqrt(3)
    rng = np.random.default_rng(2024)
    qs = np.concatenate([random_configs(rng, 20_000), random_configs(rng, 20_000, at_limit=0.5)])
    d = np.concatenate([trilinear(field, chain_points(arm_chain(chunk), 20).reshape(-1, 3))
                        .reshape(len(chunk), -1).max(axis=1) for chunk in np.array_split(qs, 4)])
    k = int(np.argmax(d))
    assert d[k] <= bound, (f"{np.sum(d > bound)} configurations reach beyond the field; worst "
                           f"{d[k] / h:.2f} h at q = {np.round(np.rad2deg(qs[k]), 1)} deg")
    worst, worst_q = d[k], qs[k]
    for start in qs[np.argsort(-d)[:12]]:
        res = minimize(lambda q: -_arm_field_max(q, field), start, method="Nelder-Mead", bounds=BOUNDS,
                       options={"maxfev": 250, "xatol": 1e-4, "fatol": 1e-6})
        if -res.fun > worst:
            worst, worst_q = -res.fun, res.x
    assert worst <= bound, f"the arm reaches {worst / h:.2f} h beyond the field at q = " \
                           f"{np.round(np.rad2deg(worst_q), 1)} deg"
    # the same through the simulator's own lookup for the worst configuration
    assert field.distance(chain_points(arm_chain(worst_q[None]), 20)[0]).max() <= bound


def test_nothing_beyond_arm_length_is_inside(field):
    """The workspace lies in the ball of radius ARM; the field's surface sits at most a voxel beyond it, so
    every point p with |p| > ARM + 2 h is outside, and by at least |p| - ARM - 1.5 h (half a voxel for the
    surface offset, a half-diagonal for the rasterisation)."""
    h = field.spacing
    rng = np.random.default_rng(8)
    u = rng.normal(size=(20000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    radius = ARM + 2 * h + rng.uniform(0.0, 0.6, len(u)) ** 2  # dense just beyond, some past the grid
    pts = u * radius[:, None]
    d = trilinear(field, pts)
    assert np.all(d > 0.0), pts[np.argmin(d)]
    assert np.all(d >= radius - ARM - 1.5 * h)
    np.testing.assert_allclose(field.distance(pts[:500]), d[:500], atol=1e-6)


def _polyline_distance(q, x):
    """Distance from x to the arm (three segments) in configuration q."""
    chain = np.vstack([np.zeros(3), arm_points(q, np.asarray(LENGTHS))])
    a, b = chain[:-1], chain[1:]
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", x - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
    return float(np.min(np.linalg.norm(x - (a + t[:, None] * ab), axis=1)))


@pytest.mark.slow
def test_clearly_inside_points_are_reachable(field):
    """Grid nodes the field puts more than 2 h inside are within 2 h of the arm in some configuration: a
    random pool of configurations first, then a bounded optimisation from the pool's best candidates."""
    h = field.spacing
    rng = np.random.default_rng(77)
    n = field.values.shape[0]
    grid = field.origin + h * np.indices((n, n, n)).reshape(3, -1).T
    vals = field.values.ravel()
    deep = np.flatnonzero(vals < -2 * h)
    rim = np.flatnonzero((vals < -2 * h) & (vals > -3.5 * h))  # just inside the threshold: the hardest
    picks = np.concatenate([rng.choice(deep, 150, replace=False), rng.choice(rim, 150, replace=False)])
    targets = grid[picks]

    pool_q = random_configs(rng, 60_000, at_limit=0.3)
    pool_pts = chain_points(arm_chain(pool_q), 10)
    per = pool_pts.shape[1]
    tree = cKDTree(pool_pts.reshape(-1, 3))
    dist, idx = tree.query(targets, k=64)
    unreached = []
    optimised = 0
    for x, drow, irow in zip(targets, dist, idx, strict=True):
        if drow[0] <= 2 * h:
            continue
        optimised += 1
        best = drow[0]
        starts = list(dict.fromkeys(irow // per))[:6]  # distinct configurations, nearest first
        for s in starts:
            res = minimize(_polyline_distance, pool_q[s], args=(x,), method="L-BFGS-B", bounds=BOUNDS)
            best = min(best, res.fun)
            if best <= 2 * h:
                break
        if best > 2 * h:
            unreached.append((x, best, trilinear(field, x[None])[0]))
    assert not unreached, f"{len(unreached)} of {len(targets)} inside points not reached: {unreached[:3]}"
    assert optimised < len(targets)  # the pool alone settles most; the optimiser handles the rest
