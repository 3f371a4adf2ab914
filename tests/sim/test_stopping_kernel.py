"""How the simulated robot stops (issue 28): a controller's delay before braking, category 0's hold, the same
bits as before for the paper's stop, and the same delay for a warning field and speed and separation monitoring.

Each test plays the same worker (whose motion never depends on the robot) in two versions of a cell and compares
the latched times and the robot's path time on the rows with the model's closed form, computed here."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest
import yaml

from cellstress.cell.load import parse_cell
from cellstress.robot.stopping import hold_radii
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

INTO_BAY = ["walk+upright"] * 7 + ["walk+bend-forward"]  # from the baseline's start, through the bay curtain


def builtin(name: str) -> dict:
    return yaml.safe_load(resources.files("cellstress.cell").joinpath("builtin", f"{name}.yaml").read_text())


def sim_with(name: str, tmp_path, stopping: dict | None = None, robot: int | None = None, **robot_fields):
    data = builtin(name)
    rs = data["robot"] if robot is None else data["robots"][robot]
    if stopping is not None:
        rs.pop("stopping_time", None)
        rs["stopping"] = stopping
    rs.update(robot_fields)
    return Simulator(parse_cell(yaml.safe_dump(data), str(tmp_path / f"{name}.yaml"), tmp_path))


def play(sim: Simulator, actions) -> tuple[np.ndarray, np.ndarray]:
    """(the state after each action, every row) of an episode played action by action."""
    state, states, rows = sim.reset(), [], [sim.run([]).rows]
    for a in actions:
        state, r = sim.step(state, a)
        states.append(state)
        rows.append(r)
        if sim.is_unsafe(state):
            break
    return np.array(states), np.concatenate(rows)


@pytest.fixture(scope="module")
def plain():
    return Simulator("baseline")


def test_the_papers_stop_as_a_block_gives_the_same_bits(plain, tmp_path):
    same = sim_with("baseline", tmp_path, {"category": 1, "controller_delay": 0.0, "time": 0.15})
    a, b = play(plain, INTO_BAY), play(same, INTO_BAY)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert np.array_equal(plain.params.scal[:L.C_STOP_DELAY], same.params.scal[:L.C_STOP_DELAY])


def test_a_controller_delay_moves_the_start_of_braking(plain, tmp_path):
    delay = 0.1
    late = sim_with("baseline", tmp_path, {"category": 1, "controller_delay": delay, "time": 0.15})
    (s0, r0), (s1, r1) = play(plain, INTO_BAY), play(late, INTO_BAY)
    t0, t1 = s0[-1, L.S_TSTOP], s1[-1, L.S_TSTOP]
    assert np.isfinite(t0) and t1 == pytest.approx(t0 + delay, abs=1e-12)
    assert s1[-1, L.S_TRIG_T] == s0[-1, L.S_TRIG_T]  # the same detection: the worker does not depend on the robot
    tau0, T = float(late.params.scal[L.C_PHASE0]), 0.15
    n = min(len(r0), len(r1))
    for row in r1[:n]:
        t = row[L.M_T]
        if t < t1:  # full path speed until braking begins
            assert row[L.M_TAU] == pytest.approx(tau0 + t, abs=1e-12)
        elif t - t1 < T:
            d = t - t1
            assert row[L.M_TAU] == pytest.approx(tau0 + t1 + d - d * d / (2 * T), abs=1e-12)
            assert row[L.M_PHASE] == L.PHASE_BRAKING
        else:
            assert row[L.M_TAU] == pytest.approx(tau0 + t1 + T / 2, abs=1e-12) and row[L.M_V] == 0.0
    # the robot travels v (delay + T / 2) of path time from the signal instead of v T / 2
    assert late.run(INTO_BAY).rows[-1, L.M_TAU] - plain.run(INTO_BAY).rows[-1, L.M_TAU] == pytest.approx(delay)


def test_category_0_holds_the_pose_and_grows_the_capsules(plain, tmp_path):
    held = sim_with("baseline", tmp_path, {"category": 0, "controller_delay": 0.02, "time": 0.2})
    part = held.layout.robots[0]
    stop = part.stop
    assert stop.hold and stop.delay == 0.0 and stop.braking == pytest.approx(0.22)
    # every capsule grown by the bound for the joints' travel (each its top speed over 0.22 s)
    base = plain.layout.capsules
    grow = hold_radii(part.model, np.array([c.joint for c in base]), np.array([c.p0 for c in base]),
                      np.array([c.p1 for c in base]), np.asarray(stop.travel))
    np.testing.assert_allclose(held.params.cap_r, plain.params.cap_r + grow)
    assert grow.max() > 0.05
    states, rows = play(held, INTO_BAY)
    t_s = states[-1, L.S_TSTOP]
    assert np.isfinite(t_s) and t_s == play(plain, INTO_BAY)[0][-1, L.S_TSTOP]  # no delay before the hold
    after = rows[rows[:, L.M_T] >= t_s]
    tau0 = float(held.params.scal[L.C_PHASE0])
    assert len(after) and np.all(after[:, L.M_TAU] == tau0 + t_s)  # held where the stop took effect
    v = after[:, L.M_V]
    assert np.all(np.diff(v) <= 1e-12) and v[after[:, L.M_T] - t_s >= 0.22 - 1e-9].max(initial=0.0) == 0.0


def test_category_0_refuses_devices_that_need_a_controlled_stop(tmp_path):
    from cellstress.core.errors import CellError

    with pytest.raises(CellError) as exc:
        sim_with("restart-auto", tmp_path, {"category": 0, "time": 0.15})
    assert exc.value.field == "robot.stopping.category" and "automatic restart" in exc.value.problem


def test_each_robot_adds_its_own_delay(tmp_path):
    base = Simulator("two-robots-fixed")
    slow = sim_with("two-robots-fixed", tmp_path, {"category": 1, "controller_delay": 0.08, "time": 0.3}, robot=1)
    rng = np.random.default_rng(3)
    for _ in range(20):
        acts = [base.action_names[i] for i in rng.integers(0, base.n_actions, 8)]
        (s0, _), (s1, _) = play(base, acts), play(slow, acts)
        n = min(len(s0), len(s1))
        assert np.array_equal(s0[:n, L.S_TSTOP], s1[:n, L.S_TSTOP])  # robot a as before
        x0, x1 = s0[:n, L.S_XTSTOP], s1[:n, L.S_XTSTOP]
        fin = np.isfinite(x0)
        assert np.array_equal(np.isfinite(x1), fin) and np.allclose(x1[fin], x0[fin] + 0.08, atol=1e-12)


def test_a_warning_field_waits_for_the_delay(tmp_path):
    base = Simulator("warning-field-ok")
    late = sim_with("warning-field-ok", tmp_path, {"category": 1, "controller_delay": 0.05, "time": 0.15})
    rng = np.random.default_rng(5)
    latched = 0
    for _ in range(30):
        acts = [base.action_names[i] for i in rng.integers(0, base.n_actions, 8)]
        (s0, _), (s1, _) = play(base, acts), play(late, acts)
        n = min(len(s0), len(s1))
        a, b = s0[:n, L.S_TSLOW], s1[:n, L.S_TSLOW]
        fin = np.isfinite(a)
        latched += int(fin.any())
        assert np.allclose(b[fin], a[fin] + 0.05, atol=1e-12)
    assert latched > 0


def test_a_speed_command_waits_for_the_delay(tmp_path):
    """The separation monitor's command measured at step j takes effect at j dt + response + delay."""
    from cellstress.sim.kernels.scaling import commands_due

    sim = sim_with("ssm-ok", tmp_path, {"category": 1, "controller_delay": 0.05, "time": 0.15})
    P = sim.params
    dt, resp = sim.dt, float(P.dev_resp[int(P.dev_sep[0, 5])])
    state = sim.reset().copy()
    j = 3
    state[L.S_SEP_Q0 + j] = 0.5
    due = j * dt + resp + 0.05
    k = int(np.ceil(due / dt - 1e-9))
    before = state.copy()
    commands_due(P, before, k - 1)
    assert before[L.S_SEP_ON] == 1.0  # not yet
    commands_due(P, state, k)
    assert state[L.S_SEP_ON] == 0.5 and state[L.S_A_T] == pytest.approx(due, abs=1e-12)
