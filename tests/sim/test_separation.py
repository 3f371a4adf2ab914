"""d_HR as the kernel measures it, against brute force: every robot capsule axis sampled every 2 mm, each sample's
exact fenced reach value (``kernels.reach_value``: the reach field, and the hand's detour around the near panels),
and the body capsules by exact segment distances; and the closest (robot capsule, body part) pair it names
against that pair's own brute-force minimum.

The kernel sphere-traces the axes and skips the detour where it cannot matter, so it must never report less
than the true minimum (up to the brute force's own sampling error) and never more than its stated tolerance:
one grid spacing plus 5 % of the distance (docs/architecture.md). States are taken from random episodes,
preferring steps with fence panels within reach, where the detour decides.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim import scene
from cellstress.sim.geometry import segment_segment_xyz
from cellstress.sim.simulator import Simulator

SAMPLE = 0.002  # brute-force spacing along a capsule axis (m)


def brute_force_d(sim: Simulator, row: np.ndarray) -> tuple[float, int, dict[tuple[int, int], float]]:
    """(d_HR by brute force, number of fence panels near the shoulders, the minimum of each (robot capsule,
    body part) pair) for one metric row."""
    P = sim.params
    W = K.make_work(P)
    K.human_pose(P, L.row_pose(row), W)
    n_near = int(K.near_fences(P, W, P.body[L.B_ARM_LEN] + 0.05))
    ra, rb = scene.robot_capsules(sim.layout, row[L.M_TAU])
    pairs: dict[tuple[int, int], float] = {}
    for c in range(len(P.cap_r)):
        r = float(P.cap_r[c])
        n = max(2, int(np.linalg.norm(rb[c] - ra[c]) / SAMPLE) + 1)
        for side in (0, 1):
            pairs[c, L.PART_LEFT_REACH + side] = min(float(K.reach_value(P, p, side, W, n_near)) - r
                                                     for p in np.linspace(ra[c], rb[c], n))
        for h in range(L.N_BODY_CAPSULES):
            d2 = segment_segment_xyz(*ra[c], *rb[c], *W.ha[h], *W.hb[h])[0]
            pairs[c, h] = math.sqrt(d2) - r - float(W.hr[h])
    return min(pairs.values()), n_near, pairs


def sampled_rows(sim: Simulator, episodes: int, seed: int) -> list[np.ndarray]:
    """Three metric rows from each of ``episodes`` random episodes."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(episodes):
        rows = sim.run(rng.integers(0, sim.n_actions, size=sim.actions_per_episode)).rows
        out.extend(rows[k] for k in rng.choice(len(rows), size=min(3, len(rows)), replace=False))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("cell", ["s3-fence-gap", "baseline", "door-locked"])
def test_kernel_d_hr_matches_brute_force(cell):
    sim = Simulator(cell)
    h = float(sim.params.scal[L.C_REACH_H])
    near_checked = 0
    for row in sampled_rows(sim, 40, seed=5):
        brute, n_near, pairs = brute_force_d(sim, row)
        near_checked += n_near > 0
        d = float(row[L.M_D])
        step = int(row[L.M_STEP])
        # the closest robot link and body part it names really come that close (a stand-in value that passed
        # for a new best named the wrong pair in session 3, with d still right)
        assert pairs[int(row[L.M_LINK]), int(row[L.M_PART])] <= max(d, 0.0) + SAMPLE, (step, d, pairs)
        if brute <= 0.0:
            assert d == 0.0, (step, brute)
            continue
        # never below the true minimum (the brute force may itself sit up to half a sample above it) ...
        assert d >= brute - SAMPLE, (step, d, brute)
        # ... and never above it by more than the trace's tolerance
        assert d <= brute + h + K.TRACE_REL_TOL * brute + 1e-9, (step, d, brute)
    if cell != "baseline":
        assert near_checked >= 30  # the fence-detour path is what this test is about
