"""The iso15066 criterion: the force formula, the reflected mass, body regions, and the simulator applying it."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

from cellstress.cell.load import load_cell, with_criterion
from cellstress.core.errors import CellstressError
from cellstress.core.records import Measures
from cellstress.criteria.contact import ContactWhileMoving
from cellstress.criteria.iso15066 import (
    REGIONS,
    Iso15066,
    IsoReward,
    peak_force,
    region_force,
    transient_limit,
)
from cellstress.human.actions import action_index
from cellstress.human.regions import body_region
from cellstress.robot.dynamics import point_dynamics, reflected_mass
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.determinism import check_determinism
from cellstress.sim.layout import pose_vector
from cellstress.sim.scene import body_pose
from cellstress.sim.simulator import Simulator

S3_WITNESS = ["walk+bend-right", "turn-left-45+bend-forward-left", "walk+bend-forward", "walk+bend-forward-left"]


def test_force_formula_against_a_hand_computed_example():
    # hand: m_H = 0.6 kg, k = 75 N/mm; robot 5 kg at 1 m/s
    # mu = 1 / (1/0.6 + 1/5) = 0.535714 kg; F = 1 m/s * sqrt(0.535714 kg * 75000 N/m) = 200.446 N
    assert peak_force(1.0, 5.0, 0.6, 75_000.0) == pytest.approx(200.446, abs=1e-3)
    assert region_force("hands", 1.0, 5.0) == pytest.approx(200.446, abs=1e-3)
    # chest: m_H = 40 kg, k = 25 N/mm; robot 20 kg at 0.5 m/s: mu = 13.333 kg, F = 0.5 * sqrt(333333) = 288.68 N,
    # above the transient limit 2 x 140 N = 280 N
    f = region_force("chest", 0.5, 20.0)
    assert f == pytest.approx(288.675, abs=1e-3)
    assert transient_limit("chest") == 280.0
    assert Iso15066().rule("chest", f, moving=True)[0]
    # an immovable robot (infinite mass): mu = m_H
    assert peak_force(2.0, math.inf, 0.6, 75_000.0) == pytest.approx(2.0 * math.sqrt(45_000.0))
    assert peak_force(-1.0, 5.0, 0.6, 75_000.0) == 0.0  # moving apart: no impact


def test_table_values_used():
    assert REGIONS["hands"] == (140.0, 75.0, 0.6)
    assert REGIONS["back-shoulders"] == (210.0, 35.0, 40.0)
    assert {r: transient_limit(r) for r in ("upper-arms", "forearms", "pelvis")} == \
        {"upper-arms": 300.0, "forearms": 320.0, "pelvis": 360.0}


SINGLE_LINK = """<robot name="one">
  <link name="base"/>
  <link name="arm">
    <inertial><origin xyz="0.5 0 0"/><mass value="2.0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
</robot>
"""


@pytest.mark.parametrize("q", [0.0, 0.7])
def test_reflected_mass_of_a_single_link(tmp_path, q):
    """A link turning about z: inertia about the axis I = I_c + m c^2 = 0.1 + 2 * 0.5^2 = 0.6 kg m^2. At a point
    at distance r = 0.8 m, the reflected mass along the tangent is I / r^2 = 0.9375 kg, along a direction at
    angle phi to the tangent I / (r cos phi)^2, and infinite along the link (the joint cannot push that way)."""
    path = tmp_path / "one.urdf"
    path.write_text(SINGLE_LINK)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    c, s = math.cos(q), math.sin(q)
    point = np.array([0.8 * c, 0.8 * s, 0.0])
    tangent = np.array([-s, c, 0.0])
    radial = np.array([c, s, 0.0])
    J, M = point_dynamics(model, data, np.array([q]), 1, point)
    assert M[0, 0] == pytest.approx(0.6)
    assert J[:, 0] == pytest.approx(0.8 * tangent)
    assert reflected_mass(J, M, tangent) == pytest.approx(0.9375)
    phi = math.radians(60)
    oblique = math.cos(phi) * tangent + math.sin(phi) * radial
    assert reflected_mass(J, M, oblique) == pytest.approx(0.6 / (0.8 * math.cos(phi)) ** 2)
    assert reflected_mass(J, M, radial) == math.inf


def test_hand_contact_at_low_speed_is_safe_under_iso_but_not_under_the_paper():
    # the predicates alone: a hand touched at 0.3 m/s by a 10 kg robot
    f = region_force("hands", 0.3, 10.0)
    assert f < transient_limit("hands")
    assert not Iso15066().rule("hands", f, moving=True)[0]
    assert ContactWhileMoving().is_unsafe(0.0, 0.3)
    # and in the simulator: the S3 witness reaches the robot's forearm, the robot's point at about 0.6 m/s
    paper = Simulator("s3-fence-gap").run(S3_WITNESS)
    assert paper.unsafe and paper.record(paper.unsafe_row).body_part == "left-reach"
    iso = Simulator(with_criterion(load_cell("s3-fence-gap"), "iso15066"))
    trace = iso.run(S3_WITNESS)
    touching = [i for i, r in enumerate(trace.rows) if r[L.M_D] <= 0.0]
    assert touching == [trace.unsafe_row]  # the same contact happens at the same step
    c = iso.contacts.contact(trace.rows[touching[0]])  # without the step before: the robot's speed alone
    alone = iso.criterion.judge(c)
    assert alone.touching and alone.moving and alone.region == "hands" and alone.case == "transient"
    assert 0.0 < alone.force < alone.limit == 280.0 and not alone.unsafe
    # with the worker's own speed (the hand swung towards the robot as the trunk bends, 1.3 m/s) it is unsafe
    v = iso.verdict_at(trace, touching[0])
    assert v.unsafe and v.v_human > 1.0 and v.force > 280.0 and v.case == "transient"
    assert v.reason.startswith(f"{v.force:.0f} N > 280 N transient limit (hands): no fixed surface behind the body")
    assert v.reason.endswith(f"v_rel {v.v_rel:.2f} m/s with the worker's {v.v_human:.2f} m/s towards the robot")


def test_head_contact_while_moving_is_unsafe_at_any_force():
    crit = Iso15066()
    assert crit.rule("face", 1.0, moving=True) == (True, "face contact while the robot moves")
    assert crit.rule("skull-forehead", 0.0, moving=True)[0]
    assert not crit.rule("skull-forehead", 0.0, moving=False)[0]
    assert not crit.rule("neck", 10.0, moving=True)[0]


def test_body_regions():
    sim = Simulator("baseline")
    b = sim.layout.body
    pose = body_pose(sim.layout, pose_vector(0.0, 0.0, 0.0))  # upright at the origin, facing +x

    def region(part, p):
        return body_region(part, p, pose, b.height, b.upper_arm, b.forearm)

    H = b.height
    assert region(0, (0.0, 0.1, 0.2)) == "lower-legs"
    assert region(1, (0.0, -0.1, 0.7)) == "thighs"
    assert region(2, (0.15, 0.0, 0.55 * H)) == "pelvis"
    assert region(2, (0.15, 0.0, 0.66 * H)) == "abdomen"
    assert region(2, (0.15, 0.0, 0.76 * H)) == "chest"
    assert region(2, (-0.15, 0.0, 0.66 * H)) == "back-shoulders"
    assert region(2, (0.0, 0.0, 0.85 * H)) == "neck"
    centre = pose.a[3]
    assert region(3, centre + (0.1, 0.0, -0.01)) == "face"
    assert region(3, centre + (0.0, 0.0, 0.1)) == "skull-forehead"
    assert region(3, centre + (-0.1, 0.0, 0.0)) == "skull-forehead"
    sh = pose.shoulders[0]
    assert region(4, sh + (0.0, 0.0, -0.2)) == "upper-arms"
    assert region(4, sh + (0.0, 0.0, -0.5)) == "forearms"
    assert region(4, sh + (0.0, 0.0, -0.7)) == "hands"
    assert region(6, sh + (0.7, 0.0, 0.0)) == "hands"
    assert region(7, pose.shoulders[1] + (0.4, 0.0, 0.0)) == "forearms"


def test_criterion_choice_and_errors():
    cell = load_cell("s3-fence-gap")
    iso = with_criterion(cell, "iso15066")
    assert iso.spec.criterion == Iso15066(distance_tolerance=0.0, speed_tolerance=0.001, payload=2.0)
    assert with_criterion(cell, None) is cell and with_criterion(cell, "contact-while-moving") is cell
    with pytest.raises(CellstressError, match="unknown criterion 'force'"):
        with_criterion(cell, "force")


def test_reward_guards():
    r = IsoReward(8)
    # a stopped robot is worth nothing, however close (no stalling to farm reward)
    assert r(Measures(0.0, 0.0, 0.0), False, False) == (0.0, 0.0)
    # risk grows with the force ratio, and is capped at 2 while safe
    lo, hi = r.risk(0.5, 0.5, 0.2, False), r.risk(0.5, 0.5, 0.8, False)
    assert 0.0 < lo < hi < 2.0 and r.risk(0.0, 100.0, 5.0, False) < 2.0
    # an unsafe end beats any safe episode: 2 n > 2 (n - 1)
    assert r(Measures(0.0, 0.5, 1.2), False, True) == (16.0, 2.2)
    assert 7 * 2.0 < 16.0
    ret_last, _ = r(Measures(3.0, 0.2, 0.0), True, False)
    assert ret_last < 0.0


class _Strict(Iso15066):
    """A test criterion with a 50 N limit everywhere, so that the S3 cell has iso15066 hazards."""

    def rule(self, region, force, moving, clamped=False):
        return (force > 50.0, "test") if force > 50.0 else (False, None)


def _strict_s3() -> Simulator:
    cell = load_cell("s3-fence-gap")
    return Simulator(replace(cell, spec=cell.spec.model_copy(update={"criterion": _Strict()})))


def test_simulator_applies_the_criterion_the_same_way_everywhere():
    sim = _strict_s3()
    trace = sim.run(S3_WITNESS)
    assert trace.unsafe and trace.rows[-1, L.M_UNSAFE] == 1.0 and trace.unsafe_row == len(trace.rows) - 1
    rng = np.random.default_rng(5)
    seqs = [S3_WITNESS + ["walk+upright"] * 4, *rng.integers(0, 30, (40, 8)).tolist()]
    assert check_determinism(sim, seqs) == len(seqs)
    b = sim.run_batch(np.asarray([[action_index("turn-left-90+upright")] * 8,
                                  [action_index(a) for a in seqs[0]]]))
    assert b.unsafe.tolist() == [False, True]


def test_contact_point_velocity_matches_the_kernel_kinematics():
    """J q_dot at a contact (pinocchio) equals the finite-difference velocity of the same point carried by the
    kernel's forward kinematics along the path: the two robot models agree, and so do q, q_dot of the step."""
    from cellstress.sim import scene

    sim = Simulator(with_criterion(load_cell("s3-fence-gap"), "iso15066"))
    P, fm = sim.params, sim.contacts
    rows = [r for r in sim.run(S3_WITNESS).rows if r[L.M_D] <= 0.0]
    assert rows
    W = K.make_work(P)

    def joint_frame(j, tau):
        K.robot_live(P, tau - P.scal[L.C_PHASE0], np.inf, W)
        return W.rot[j].copy(), W.pos[j].copy()

    for r in rows:
        assert int(r[L.M_PHASE]) == L.PHASE_RUNNING  # sigma = 1: path velocity = time velocity
        j = int(P.cap_joint[int(r[L.M_LINK])])
        rp = np.array(r[L.M_RX:L.M_RZ + 1])
        q, qd = scene.joint_state(sim.layout, r)
        (R0, o0), (R1, o1) = joint_frame(j, r[L.M_TAU] - 1e-6), joint_frame(j, r[L.M_TAU] + 1e-6)
        Rm, om = joint_frame(j, r[L.M_TAU])
        local = Rm.T @ (rp - om)
        v_fd = ((R1 @ local + o1) - (R0 @ local + o0)) / 2e-6
        Jp, _ = point_dynamics(fm.model, fm.data, q, j + 1, fm.R_base.T @ (rp - fm.t_base))
        assert fm.R_base @ (Jp @ qd) == pytest.approx(v_fd, abs=1e-5)


def test_a_criterion_step_inside_an_action_leaves_the_state_of_that_step():
    """When the criterion ends the episode before an action's last 50 ms step, Simulator.step returns the state
    of that step: its clock and pose are the unsafe row's (a contact within the step: its moment lies in it),
    and measuring it again (the kernel's own sense_and_measure, which also latches stops) reproduces that row
    and latches nothing new."""
    sim = _strict_s3()
    P = sim.params
    rng = np.random.default_rng(11)
    mid_action = 0
    for _ in range(6000):
        s = sim.reset()
        for a in rng.integers(0, 30, 8).tolist():
            s, rows = sim.step(s, a)
            if not sim.is_unsafe(s):
                continue
            row = rows[-1]
            assert s[L.S_K] == row[L.M_STEP] and sim.time(s) == row[L.M_STEP]
            between = row[L.M_SWEPT] != 0.0  # a contact within the step: the row holds its own moment's poses
            if between:
                assert (row[L.M_STEP] - 1) * sim.dt < row[L.M_TC] <= row[L.M_STEP] * sim.dt + 1e-12
            else:
                assert (s[L.S_X], s[L.S_Y], s[L.S_HEADING], s[L.S_FWD], s[L.S_LAT]) == \
                    (row[L.M_X], row[L.M_Y], row[L.M_HEADING], row[L.M_FWD], row[L.M_LAT])
            if len(rows) < P.spa:
                mid_action += 1
                again, again_row = s.copy(), np.zeros(L.NM)
                K.sense_and_measure(P, again, K.make_work(P), again_row, a)
                np.testing.assert_array_equal(again[:L.S_UNSAFE], s[:L.S_UNSAFE])
                for col in () if between else (L.M_D, L.M_V, L.M_SEEN, L.M_PHASE, L.M_TAU, L.M_LINK, L.M_PART):
                    assert again_row[col] == row[col], col
            break
    assert mid_action >= 5  # the case this test is about happened (11 times in these 6,000 episodes)
