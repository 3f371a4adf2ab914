"""The predictive gap (sim/lookahead.py) against a brute force: the simulator's own sense-and-measure on a
state that keeps the worker's pose and moves the clock on, and the gap of a zero-length window."""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.core.protocols import Lookahead as LookaheadAbility
from cellstress.human.actions import action_index
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.lookahead import Lookahead, default_horizon
from cellstress.sim.simulator import Simulator

# an S2 hazard (s2-deceptive: curtain crossed, elbow touched while braking) and an S1 walk into the scanner field
EPISODES = {
    "s2-deceptive": ["walk+upright", "walk+upright", "turn-right-45+bend-right", "walk+bend-left"],
    "s1-scanner-width": ["walk+upright", "walk+bend-forward", "walk+upright", "turn-left-45+upright",
                         "walk+bend-forward", "walk+upright"],
}


def brute_gaps(sim, rows, t_stop, horizon, speed):
    """For each row: the worker's pose at step k, the clock at k + j (j = 0 .. horizon / dt), measured by
    kernels.sense_and_measure (the simulator's step, minus the walking); min of d_HR - speed * j * dt."""
    P, dt = sim.params, sim.dt
    W = K.make_work(P)
    vtol = P.scal[L.C_VTOL]
    out = []
    for r in rows:
        best = np.inf
        for j in range(int(round(horizon / dt)) + 1):
            s = sim.reset()  # (the safeguard slots at their neutral values: nothing latched to release)
            s[L.S_K] = r[L.M_STEP] + j
            s[L.S_X], s[L.S_Y], s[L.S_HEADING], s[L.S_FWD], s[L.S_LAT] = (
                r[L.M_X], r[L.M_Y], r[L.M_HEADING], r[L.M_FWD], r[L.M_LAT])
            s[L.S_TSTOP] = np.inf if r[L.M_PHASE] == L.PHASE_RUNNING else t_stop
            s[L.S_TRIG_DEV] = s[L.S_TRIG_T] = -1.0
            row = np.zeros(L.NM)
            K.sense_and_measure(P, s, W, row, -1)
            if row[L.M_V] > vtol:
                best = min(best, row[L.M_D] - speed * j * dt)
        out.append(best)
    return np.array(out)


@pytest.mark.parametrize("cell", sorted(EPISODES))
def test_gaps_match_brute_force(cell) -> None:
    sim = Simulator(cell)
    la = Lookahead(sim.params)
    assert la.horizon == pytest.approx(default_horizon(sim.params))
    state, phases = sim.reset(), set()
    for a in EPISODES[cell]:
        state, rows = sim.step(state, action_index(a))
        got = la.gaps(rows, state[L.S_TSTOP])
        want = brute_gaps(sim, rows, state[L.S_TSTOP], la.horizon, la.speed)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
        phases |= set(rows[:, L.M_PHASE].astype(int).tolist())
        if sim.is_unsafe(state):
            break
    # the episodes cover the running robot and a requested stop
    assert L.PHASE_RUNNING in phases and phases - {L.PHASE_RUNNING}
    if cell == "s2-deceptive":
        assert sim.is_unsafe(state)


def test_zero_window_is_d_hr_of_the_moving_robot() -> None:
    sim = Simulator("s2-deceptive")  # these actions touch the rebuilt S2's elbow
    la = Lookahead(sim.params, horizon=0.0, speed=1.6)
    state = sim.reset()
    rows_all, gaps = [], []
    for a in ["walk+upright"] * 2 + ["turn-left-45+upright", "turn-right-45+upright"] * 3:
        state, rows = sim.step(state, action_index(a))
        rows_all.append(rows)
        gaps.append(la.gaps(rows, state[L.S_TSTOP]))
    rows, gaps = np.concatenate(rows_all), np.concatenate(gaps)
    moving = rows[:, L.M_V] > sim.params.scal[L.C_VTOL]
    assert moving.any() and not moving.all()  # the S2 robot dwells in its fold for 0.2 s (t = 0.37-0.57 s)
    np.testing.assert_allclose(gaps[moving], rows[moving, L.M_D], rtol=0, atol=1e-12)
    assert np.isinf(gaps[~moving]).all()


def test_lookahead_leaves_the_simulator_alone() -> None:
    sim = Simulator("s1-scanner-width")
    la = Lookahead(sim.params, horizon=0.3, speed=0.0)
    s0 = sim.reset()
    s1, rows1 = sim.step(s0, 0)
    la.gaps(rows1, s1[L.S_TSTOP])
    s2, rows2 = sim.step(s0, 0)
    assert np.array_equal(s1, s2) and np.array_equal(rows1, rows2)
    # the gap never exceeds d_HR now (tau = 0 is in the window) while the robot moves
    g = la.gaps(rows1, s1[L.S_TSTOP])
    assert (g <= rows1[:, L.M_D] + 1e-12).all()


def test_the_simulator_exposes_it() -> None:
    sim = Simulator("s2-elbow-intrusion")
    state, rows = sim.step(sim.reset(), action_index("walk+upright"))
    direct = Lookahead(sim.params, 0.3, 1.0).gaps(rows, state[L.S_TSTOP])
    np.testing.assert_array_equal(sim.lookahead_model(0.3, 1.0).gaps(rows, state[L.S_TSTOP]), direct)
    np.testing.assert_array_equal(sim.lookahead(state, rows, 0.3, 1.0), direct)
    assert isinstance(sim, LookaheadAbility)
    assert sim.lookahead_model().horizon == pytest.approx(0.05 + 0.15)  # the curtain's response + stopping time


def test_bad_window() -> None:
    sim = Simulator("s1-scanner-width")
    with pytest.raises(ValueError):
        Lookahead(sim.params, horizon=-0.1)
