"""``Simulator.worker_paths``: the worker's open-loop motion, without robot or devices, is the motion the
simulator plays (bit for bit, up to the step where an episode ends), walls and table included."""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

POSE = list(L.POSE_ROW)


@pytest.mark.parametrize("cell", ["baseline", "s2-elbow-intrusion", "s3-fence-gap"])
def test_paths_are_the_simulated_poses(cell) -> None:
    sim = Simulator(cell)
    rng = np.random.default_rng(4)
    acts = rng.integers(0, sim.n_actions, size=(300, sim.actions_per_episode))
    acts[:100] = rng.integers(0, 6, size=(100, sim.actions_per_episode))  # straight walks: into walls and table
    paths = sim.worker_paths(acts)
    assert paths.shape == (300, sim.actions_per_episode * sim.steps_per_action, L.N_POSE)
    blocked = 0
    for e in range(len(acts)):
        trace = sim.run(acts[e])
        rows = trace.rows[1:]  # (the first row is s0)
        own = rows[:, L.M_SWEPT] == 0.0
        assert np.array_equal(paths[e, : len(rows)][own], rows[own][:, POSE]), e
        for i in np.flatnonzero(~own):  # a contact within a step: the pose of its moment, on the line between
            before = paths[e, i - 1] if i > 0 else trace.rows[0][POSE]  # the step's two poses
            s = (rows[i, L.M_TC] - (rows[i, L.M_T] - sim.dt)) / sim.dt
            assert 0.0 < s <= 1.0
            np.testing.assert_allclose(rows[i, POSE], before + s * (paths[e, i] - before), rtol=0.0, atol=1e-12)
        walked = np.hypot(*np.diff(paths[e, :, :2], axis=0).T)
        blocked += int(np.sum((acts[e].repeat(sim.steps_per_action)[1:] < 6) & (walked == 0.0)))
    assert blocked > 0  # some walks ran into a wall, the table or a fence and were stopped there


def test_bad_actions_are_refused() -> None:
    sim = Simulator("baseline")
    with pytest.raises(ValueError):
        sim.worker_paths(np.array([[0, 30]]))


@pytest.mark.parametrize("cell", ["s2-elbow-intrusion", "s3-fence-gap"])
def test_distance_to_the_robot_point_of_a_row_is_its_d_hr(cell) -> None:
    """The robot point a row names lies on the robot, so the worker is at least d_HR from it; and it is the
    closest point, so not much more (the reach volumes are met at the capsule axis, then moved to its surface)."""
    sim = Simulator(cell)
    acts = np.random.default_rng(9).integers(0, sim.n_actions, size=(60, sim.actions_per_episode))
    rows = np.concatenate([sim.run(a).rows[1:] for a in acts])
    # within reach, and not touching (a row reports a penetration as d_HR = 0)
    rows = rows[(rows[:, L.M_D] < 0.8) & (rows[:, L.M_D] > 0.0)]
    points = rows[:, None, [L.M_RX, L.M_RY, L.M_RZ]]
    dist = sim.worker_distances(rows[:, POSE], points)[:, 0]
    d = rows[:, L.M_D]
    gap = dist - d
    assert len(rows) > 300
    # d_HR itself may be long by the reach trace's tolerance far from contact: one 2 cm grid step plus 5 %
    assert np.all(gap > -(0.02 + 0.05 * d)), gap.min()
    assert np.median(gap) < 0.01 and np.quantile(gap, 0.95) < 0.05, np.quantile(gap, [0.5, 0.95])
    far = sim.worker_distances(rows[:3, POSE], np.full((3, 2, 3), np.nan))
    assert np.all(far == np.inf)


@pytest.mark.parametrize("cell", ["door-unlocked", "reach-over", "muting-long", "s3-fence-gap"])
def test_a_path_resumed_from_its_states_is_the_same_path(cell) -> None:
    """``worker_paths_from``: resumed at any action from the state an earlier call gave there, the poses and the
    later states are bit for bit those of the whole path (doors pushed, the articulated worker's held arms,
    walls), and the steps before are NaN."""
    sim = Simulator(cell)
    rng = np.random.default_rng(11)
    h, spa = sim.actions_per_episode, sim.steps_per_action
    acts = rng.integers(0, sim.n_actions, size=(40, h))
    acts[:10] = rng.integers(0, 6, size=(10, h))  # straight walks: into walls and doors
    whole = sim.worker_paths_from(acts)
    assert np.array_equal(whole.poses, sim.worker_paths(acts))
    assert whole.states.shape == (40, h + 1, L.NS) and np.array_equal(whole.states[:, 0], np.tile(sim.reset(), (40, 1)))
    first = rng.integers(0, h + 1, size=40)
    again = sim.worker_paths_from(acts, whole.states[np.arange(40), first], first)
    for e in range(40):
        k = first[e] * spa
        assert np.isnan(again.poses[e, :k]).all() and np.isnan(again.states[e, : first[e]]).all()
        assert np.array_equal(again.poses[e, k:], whole.poses[e, k:]), e
        assert np.array_equal(again.states[e, first[e]:], whole.states[e, first[e]:]), e
    # a different sequence after a shared prefix: resumed from the prefix's state, as if walked from s0
    other = acts.copy()
    other[:, h // 2:] = rng.integers(0, sim.n_actions, size=(40, h - h // 2))
    mid = np.full(40, h // 2)
    assert np.array_equal(sim.worker_paths_from(other, whole.states[:, h // 2], mid).poses[:, h // 2 * spa:],
                          sim.worker_paths(other)[:, h // 2 * spa:])


def test_bad_resume_is_refused() -> None:
    sim = Simulator("baseline")
    acts = np.zeros((2, sim.actions_per_episode), dtype=np.int64)
    states = np.tile(sim.reset(), (2, 1))
    for first, st in [(np.array([0, sim.actions_per_episode + 1]), states), (np.array([0, -1]), states),
                      (np.array([0]), states), (np.array([0, 0]), states[:, :5])]:
        with pytest.raises(ValueError):
            sim.worker_paths_from(acts, st, first)
