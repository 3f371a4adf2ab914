"""plan with the articulated worker (issue 20): it measures the worker's side of d_HR to the body capsules at each
pose, as the kernel measures d_HR itself, so its predictions tell arm actions apart; the paper worker keeps the
reach volumes."""

from __future__ import annotations

import numpy as np

from cellstress.searchers import search
from cellstress.searchers.plan import _Model, capsule_distances
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

WITNESS = "walk+upright,walk+upright,stand+bend-forward,stand+bend-forward,stand+bend-forward,stand+reach-over"


def test_capsule_distances_match_point_by_point() -> None:
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(4, 5, 3)), rng.normal(size=(4, 5, 3))
    b[0, 0] = a[0, 0]  # a sphere
    r = rng.uniform(0.01, 0.2, size=(4, 5))
    pts = rng.normal(size=(4, 7, 3))
    pts[1, 2] = np.nan
    got = capsule_distances(a, b, r, pts)
    for i in range(4):
        for j in range(7):
            if i == 1 and j == 2:
                assert got[i, j] == np.inf
                continue
            want = min(_segment_distance(pts[i, j], a[i, c], b[i, c]) - r[i, c] for c in range(5))
            assert abs(got[i, j] - want) < 1e-12


def _segment_distance(p, a, b) -> float:
    ab = b - a
    t = 0.0 if not ab.any() else float(np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def test_the_articulated_worker_is_measured_as_d_hr_is() -> None:
    sim = Simulator("reach-over")
    rows = sim.run(WITNESS.split(",")).rows[1:]
    points = rows[:, None, [L.M_RX, L.M_RY, L.M_RZ]]
    d = _Model(sim).distances(rows[:, L.POSE_ROW], points)[:, 0]
    np.testing.assert_allclose(d, rows[:, L.M_D], atol=1e-3)  # the robot point is the nearest: offset 0
    # the reach volumes, blind to the arms, put the robot within reach long before the hand gets there
    envelope = sim.worker_distances(rows[:, L.POSE_ROW], points)[:, 0]
    assert (envelope[:-1] < rows[:-1, L.M_D] - 0.5).any()


def test_the_paper_worker_keeps_the_reach_volumes() -> None:
    sim = Simulator("s3-fence-gap")
    rows = sim.run(["walk+bend-right", "turn-left-45+bend-forward-left", "walk+bend-forward"]).rows[1:]
    points = rows[:, None, [L.M_RX, L.M_RY, L.M_RZ]]
    poses = rows[:, L.POSE_ROW]
    assert np.array_equal(_Model(sim).distances(poses, points), sim.worker_distances(poses, points))


def test_plan_reaches_over_the_panel() -> None:
    sim = Simulator("reach-over")
    r = search(sim, "plan", budget=60, seed=0)
    assert r.found and r.episodes <= 30
    assert sim.run(list(r.hazards[0].actions)).unsafe


