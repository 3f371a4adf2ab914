"""The last action's bound (verifier.last_action): its key points hold the worker, its posture speed bounds how
far a key point moves, and what it clears is never unsafe and never nearer than it says."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cellstress.sim import layout as L
from cellstress.sim.kernels.body import pose_body
from cellstress.sim.kernels.expand import expand_states
from cellstress.sim.simulator import Simulator
from cellstress.verifier.bounds import Bounds
from cellstress.verifier.last_action import _key_points, applies, key_speed
from cellstress.verifier.tree import decide

FEATURES = Path(__file__).parent / "cells"


def _posed(sim, pose):
    b = sim.params.body
    n = int(b[L.B_N_CAPS])
    ha, hb, hr, sh, tr = np.empty((n, 3)), np.empty((n, 3)), np.empty(n), np.empty((2, 3)), np.empty((3, 3))
    pose_body(b, pose[0], pose[1], pose[2], pose[3], pose[4], np.zeros(16), 0, ha, hb, hr, sh, tr)
    kp, kr = np.empty((64, 3)), np.empty(64)
    n_key = _key_points(b, ha, hb, hr, sh, kp, kr)
    return kp[:n_key], kr[:n_key]


def test_the_key_points_hold_the_worker() -> None:
    sim = Simulator("s3-fence-gap")
    last = Bounds(sim, horizon=2).last
    rng = np.random.default_rng(7)
    poses = sim.worker_paths(rng.integers(0, 30, size=(60, 6))).reshape(-1, L.N_POSE)
    poses = poses[rng.choice(len(poses), 300, replace=False)]
    tight = np.inf
    for pose in poses:
        kp, kr = _posed(sim, pose)
        kr[-2:] = last.r_shoulder
        points = kp[rng.integers(0, len(kp), 64)] + rng.uniform(-1.5, 1.5, size=(64, 3))
        d = sim.worker_distances(pose[None, :], points[None, :, :])[0]
        cover = (np.linalg.norm(points[:, None, :] - kp[None, :, :], axis=2) - kr[None, :]).min(axis=1)
        assert np.all(d >= cover - 1e-9)
        tight = min(tight, float((d - cover).min()))
    assert tight < 0.1  # and the cover is not uselessly loose


def test_a_key_point_moves_no_faster_than_key_speed() -> None:
    sim = Simulator("baseline")
    b = sim.params.body
    rng = np.random.default_rng(8)
    for _ in range(200):
        h0, f0, l0 = rng.uniform(-np.pi, np.pi), rng.uniform(0.0, 1.0), rng.uniform(-0.6, 0.6)
        dh, df, dl = rng.uniform(-1.6, 1.6), rng.uniform(-1.0, 1.0), rng.uniform(-1.2, 1.2)
        s = np.linspace(0.0, 1.0, 401)
        pts = np.stack([_posed(sim, (0.0, 0.0, h0 + dh * t, f0 + df * t, l0 + dl * t))[0] for t in s])
        moved = np.linalg.norm(np.diff(pts, axis=0), axis=2).max()
        assert moved <= key_speed(b, dh, df, dl) * (s[1] - s[0]) * (1 + 1e-9)


# cells of every kind the last layer meets: fences, devices that stop, restart and slow the robot, two robots
CELLS = ["s3-fence-gap", "baseline", "restart-auto", "warning-field-short", "two-robots",
         str(FEATURES / "warning-trunk.yaml"), str(FEATURES / "linear-axis.yaml")]


@pytest.mark.parametrize("cell", CELLS)
def test_what_the_bound_clears_is_safe_and_no_nearer_than_it_says(cell) -> None:
    base = Simulator(cell)
    assert applies(base)
    rng = np.random.default_rng(9)
    cleared = 0
    for phase in rng.choice(np.arange(0.0, base.layout.trajectory.cycle, 0.05), 1, replace=False):
        sim = base.with_start(base.start, float(phase))
        bounds = Bounds(sim, horizon=8)
        # parents after 1..7 actions of episodes that walk in (any posture) half the time
        parents = []
        for n, acts in enumerate(rng.integers(0, 30, size=(30, 7))):
            state = sim.reset()
            for a in (acts % 6 if n % 2 else acts):
                state, _ = sim.step(state, int(a))
                if sim.is_unsafe(state):
                    break
                parents.append(state)
        parents = np.array(parents)
        lb = bounds.last.lower_bound(parents)
        children = np.empty((len(parents) * 30, L.NS))
        last, d_min = np.empty((len(children), L.NM)), np.empty(len(children))
        expand_states(sim.params, parents, 30, children, last, d_min)
        lb = lb.ravel()
        assert np.all(d_min >= lb)  # every step's d_HR, no nearer than the bound
        # as decide asks: where a coarse cover of the body already clears a child, its value is that cover's
        quick = bounds.last.lower_bound(parents, stop=True).ravel()
        clear = bounds.last_safe(parents).ravel()
        assert np.array_equal(clear, quick > bounds.swept.dtol)
        assert np.all(d_min[clear] >= quick[clear])
        assert not (children[clear, L.S_UNSAFE] != 0.0).any()
        cleared += int(clear.sum())
    assert cleared > 0


def test_the_last_layer_counts_the_same_with_and_without_it() -> None:
    # decide's counts with the last action's bound against the same tree with it taken out
    sim = Simulator("s3-fence-gap")
    with_it = decide(sim, 4, Bounds(sim, horizon=4))
    plain = Bounds(sim, horizon=4)
    plain.last = None
    without = decide(sim, 4, plain)
    assert with_it.hazardous == without.hazardous and with_it.safe == without.safe
    assert with_it.pruned_states["distance"] > without.pruned_states.get("distance", 0)
    assert with_it.expanded < without.expanded
    assert [h.actions for h in with_it.hits] == [h.actions for h in without.hits]
