"""Several robots in one cell (issue 17): the second robot's kinematics against pinocchio, a one-robot cell
written as a ``robots`` list giving the same bits, a device that stops only the robots it names, each robot's own
stopping time, and a two-robot hazard that replays bit-exactly."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import yaml

from cellstress.analysis.replay import check_result
from cellstress.cell.load import builtin_text, load_cell, parse_cell, with_criterion
from cellstress.core.errors import CellstressError
from cellstress.robot.model import base_matrix, resolve_urdf
from cellstress.searchers import search
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.determinism import check_determinism
from cellstress.sim.simulator import Simulator

# through the opening, then right towards robot b's end of the table (plan's hazard on two-robots, seed 0)
TO_B = ["turn-right-45+bend-forward", "turn-right-90+bend-forward", "turn-left-90+upright", "turn-left-90+upright",
        "walk+bend-forward", "walk+bend-forward", "turn-right-45+bend-left", "walk+bend-right", "walk+bend-forward",
        "walk+bend-forward", "walk+bend-forward", "walk+bend-forward"]
RUNNING, PENDING, BRAKING, STOPPED = L.PHASE_RUNNING, L.PHASE_PENDING, L.PHASE_BRAKING, L.PHASE_STOPPED


@pytest.fixture(scope="module")
def flawed():
    return Simulator("two-robots")


@pytest.fixture(scope="module")
def fixed():
    return Simulator("two-robots-fixed")


def test_second_robot_forward_kinematics_matches_pinocchio(flawed):
    P = flawed.layout.params
    part = flawed.layout.robots[1]
    model = pin.buildModelFromUrdf(str(resolve_urdf(part.spec.urdf, None)))
    data = model.createData()
    base = base_matrix(part.spec.base.xyz, part.spec.base.yaw_deg)
    live = P._replace(pre_xv=np.zeros((0, 1)))  # no pre-stop table: posed by the kinematics itself
    W = K.make_work(P)
    state = np.full(L.NS, np.inf)
    nj = part.model.n_joints
    for k in (0, 7, 33, 61, 140):
        K.other_robots(live, np.int64(k), state, W)
        pin.forwardKinematics(model, data, W.xq[:nj].copy())
        for j in range(nj):
            want = base[:3, :3] @ data.oMi[j + 1].translation + base[:3, 3]
            np.testing.assert_allclose(W.xpos[j], want, atol=1e-9)
    # and the step posed the same capsules from the pre-stop table
    K.other_robots(P, np.int64(61), state, W)
    a_table = W.ra[part.first_capsule:].copy()
    K.other_robots(live, np.int64(61), state, W)
    np.testing.assert_array_equal(W.ra[part.first_capsule:], a_table)


def test_one_robot_as_a_list_gives_the_same_bits():
    data = yaml.safe_load(builtin_text("baseline"))
    data["robots"] = [{"name": "ur10", **data.pop("robot")}]
    listed = Simulator(parse_cell(yaml.safe_dump(data), "baseline-listed", None))
    plain = Simulator("baseline")
    acts = np.random.default_rng(5).integers(0, 30, size=(200, 8))
    a, b = plain.run_batch(acts), listed.run_batch(acts)
    for name in ("d_end", "v_end", "unsafe_step", "min_d"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(plain.run(acts[3]).rows, listed.run(acts[3]).rows)


def test_curtain_that_names_a_stops_a_and_not_b(flawed):
    rows = flawed.run(TO_B).rows
    curtain = 1 << flawed.layout.device_names.index("bay-curtain")
    seen = next(i for i in range(len(rows)) if int(rows[i, L.M_SEEN]) & curtain)
    after = rows[seen:]
    assert set(after[:, L.M_PHASE].astype(int)) <= {PENDING, BRAKING, STOPPED}
    assert rows[-1, L.M_PHASE] == STOPPED
    # robot b runs on: its phase stays RUNNING and its path time keeps advancing one second per second
    assert np.all(rows[:, L.M_XPHASE] == RUNNING)
    dt = flawed.dt
    np.testing.assert_allclose(np.diff(rows[:, L.M_XTAU]), dt, atol=1e-9)
    assert rows[-1, L.M_UNSAFE] == 1.0 and rows[-1, L.M_ROBOT] == 1
    assert flawed.layout.capsules[int(rows[-1, L.M_LINK])].name.startswith("b:")


def test_each_robot_brakes_over_its_own_stopping_time(fixed):
    rows = fixed.run(TO_B).rows
    assert not np.any(rows[:, L.M_UNSAFE])
    t = rows[:, L.M_T]
    a_stop = t[np.argmax(rows[:, L.M_PHASE] == BRAKING)]
    b_stop = t[np.argmax(rows[:, L.M_XPHASE] == BRAKING)]
    assert a_stop == b_stop  # the same curtain, the same response time
    a_still = t[np.argmax(rows[:, L.M_PHASE] == STOPPED)]
    b_still = t[np.argmax(rows[:, L.M_XPHASE] == STOPPED)]
    dt = fixed.dt
    # braking begins a step after the stop takes effect at the latest; standstill after each one's stopping time
    assert a_still - a_stop == pytest.approx(0.15, abs=dt + 1e-9)
    assert b_still - b_stop == pytest.approx(0.30, abs=dt + 1e-9)
    assert b_still > a_still


def test_two_robot_episodes_are_deterministic(flawed):
    seqs = [TO_B] + np.random.default_rng(1).integers(0, 30, size=(5, 12)).tolist()
    assert check_determinism(flawed, seqs) == len(seqs)


def test_two_robot_hazard_replays_bit_exactly(flawed):
    res = search(flawed, "plan", budget=200, seed=0)
    assert res.found
    hz = res.hazard
    assert hz.robot_link.startswith("b:")  # the hazard names the robot it touched, and the link
    check = check_result(res, search_again=False)
    assert check.reproduced, check


def test_contact_judging_criterion_is_refused_with_two_robots():
    with pytest.raises(CellstressError, match="several robots"):
        Simulator(with_criterion(load_cell("two-robots"), "iso15066"))
