"""Speed and separation monitoring in the simulator (ssm-latency and its twin ssm-ok): the commanded speed
follows the ISO/TS 15066 formula from the measured separation, a worker far away leaves full speed, a command
takes effect after the real response time and the robot's own stopping time governs the ramp, and every way of
playing gives the same bits."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest

from cellstress.cell.load import load_cell
from cellstress.core.errors import CellError
from cellstress.sim import layout as L
from cellstress.sim.build import build_layout
from cellstress.sim.determinism import check_determinism
from cellstress.sim.simulator import Simulator

WALK_IN = ["walk+upright"] * 4 + ["walk+bend-forward"] * 4  # straight in from the start, then leaning


@pytest.fixture(scope="module")
def flawed():
    return Simulator("ssm-latency")


@pytest.fixture(scope="module")
def fixed():
    return Simulator("ssm-ok")


def _states(sim, actions):
    """(state, rows) after each action, up to the first unsafe one."""
    s, out = sim.reset(), []
    for a in actions:
        s, rows = sim.step(s, a)
        out.append((s.copy(), rows))
        if s[L.S_UNSAFE]:
            break
    return out


def test_not_a_latching_cell(flawed):
    assert not flawed.layout.stops_latch
    assert flawed.layout.params.dev_sep.shape == (1, 6)
    assert not Simulator("baseline").layout.params.dev_sep.shape[0]


def test_far_away_leaves_full_speed(flawed):
    # from a start 0.4 m in front of the sensing area, turning and bending on the spot: never seen, every command
    # full speed, and the robot follows its path exactly as in a cell without the device (warning-field-short:
    # the same robot, path and phase)
    start = (0.0, 4.0, -90.0)
    sim, base = flawed.with_start(start), Simulator("warning-field-short").with_start(start)
    seq = ["turn-right-90+upright", "turn-right-90+bend-forward"] + ["turn-left-45+bend-left"] * 6
    rows = sim.run(seq).rows
    assert not np.any(rows[:, L.M_SEEN])
    assert np.all(rows[:, L.M_PHASE] == L.PHASE_RUNNING)
    assert np.array_equal(rows[:, L.M_TAU], base.run(seq).rows[:, L.M_TAU])
    s = _states(sim, seq)[-1][0]
    assert s[L.S_SEP_LOW] == 1.0 and s[L.S_LIVE] == 0.0


def test_commanded_fraction_follows_the_formula(flawed):
    dev = flawed.layout.cell.spec.devices[0]
    s = _states(flawed, WALK_IN)[-1][0]
    assert s[L.S_SEP_LOW] < 1.0
    # the lowest command so far is the device's fraction of the separation measured then
    assert s[L.S_SEP_LOW] == pytest.approx(dev.fraction(s[L.S_SEP_LOW_S]), abs=1e-12)
    # every queued command is that of a separation >= 0 at the configured times: within [0, 1]
    q = s[L.S_SEP_Q0:L.S_SEP_Q0 + L.SEP_QUEUE]
    assert np.all((q == -1.0) | ((q >= 0.0) & (q <= 1.0)))
    assert not np.any(np.isnan(s))  # (states are compared with array_equal)


def test_command_takes_effect_after_the_real_response_and_ramps_at_the_robots_stopping_time(fixed):
    rows = fixed.run(WALK_IN).rows
    dev = fixed.layout.cell.spec.devices[0]
    T = fixed.layout.cell.spec.robot.stopping_time
    dt = fixed.dt
    lag = round(dev.response_time / dt)  # 6 steps: the command measured at step j takes effect at step j + 6
    # full speed (tau advances dt per step) until the first command below full speed takes effect
    i = next(i for i in range(len(rows)) if rows[i, L.M_PHASE] == L.PHASE_REDUCED)
    assert np.allclose(np.diff(rows[:i, L.M_TAU]), dt, atol=1e-12)
    assert int(rows[i - lag, L.M_SEEN]) & 1  # it was measured response_time earlier, with the worker seen
    # from then the time scaling changes at most at the robot's braking rate 1/T: the path time's increments
    # per step differ by at most dt^2 / T
    inc = np.diff(rows[i - 1:, L.M_TAU])
    assert np.all(np.abs(np.diff(inc)) <= dt * dt / T + 1e-12)
    assert np.any(np.abs(np.diff(inc)) > 0.5 * dt * dt / T)  # and it does brake at about that rate
    # the twin's robot comes to rest before the worker reaches it: no contact with the moving robot
    assert np.any(rows[:, L.M_V] == 0.0)
    assert not fixed.run(WALK_IN).unsafe


def test_flawed_configuration_is_unsafe_on_the_walk_in(flawed):
    tr = flawed.run(WALK_IN)
    assert tr.unsafe
    row = tr.rows[tr.unsafe_row]
    assert row[L.M_V] > 0.0 and row[L.M_PHASE] == L.PHASE_REDUCED


def test_replay_is_bit_exact(flawed, fixed):
    rng = np.random.default_rng(5)
    seqs = [WALK_IN] + [[int(a) for a in rng.integers(0, 30, 8)] for _ in range(6)]
    assert check_determinism(flawed, seqs) == len(seqs)
    assert check_determinism(fixed, seqs[:3]) == 3


def test_batch_matches_single_runs(flawed):
    rng = np.random.default_rng(9)
    acts = rng.integers(0, 30, size=(40, flawed.actions_per_episode))
    acts[0] = 0  # walk+upright all the way: straight in
    b = flawed.run_batch(acts)
    for e in range(acts.shape[0]):
        assert bool(b.unsafe[e]) == flawed.run(acts[e]).unsafe


def test_response_longer_than_the_queue_is_refused(tmp_path):
    text = resources.files("cellstress.cell").joinpath("builtin", "ssm-ok.yaml").read_text(encoding="utf-8")
    bad = tmp_path / "slow.yaml"
    bad.write_text(text.replace("response_time: 0.3 ", "response_time: 0.9 "), encoding="utf-8")
    with pytest.raises(CellError, match=r"devices\[0\]\.response_time.*at most 0.75 s"):
        build_layout(load_cell(bad))
