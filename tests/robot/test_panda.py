"""A Panda with its gripper (prismatic fingers, one a URDF <mimic> of the other): the kernel's forward
kinematics and robot speed against pinocchio, as test_kinematics does for the UR10, and the Panda test cell
(tests/robot/cells/panda.yaml: tool poses solved by inverse kinematics, fingers held) end to end."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from cellstress.robot.model import PRISMATIC, REVOLUTE, load_robot, resolve_urdf
from cellstress.robot.trajectory import evaluate
from cellstress.sim import kernels as K
from cellstress.sim import layout as L

CELL = Path(__file__).parent / "cells" / "panda.yaml"
FK_ATOL = 1e-12
V_RTOL = 1e-10


@pytest.fixture(scope="module")
def panda_sim():
    from cellstress.sim.simulator import Simulator

    return Simulator(str(CELL))


@pytest.fixture(scope="module")
def pin_model(panda_sim):
    model = pin.buildModelFromUrdf(str(panda_sim.layout.robot.urdf))
    return model, model.createData()


def random_base(rng):
    m = np.eye(4)
    m[:3, :3] = pin.rpy.rpyToMatrix(*rng.uniform(-np.pi, np.pi, 3))
    m[:3, 3] = rng.uniform(-2.0, 2.0, 3)
    return m


def test_panda_model_has_prismatic_fingers_and_a_mimic():
    robot = load_robot(resolve_urdf("panda", None))
    assert robot.kinds == (REVOLUTE,) * 7 + (PRISMATIC,) * 2
    f1, f2 = robot.joint_names.index("panda_finger_joint1"), robot.joint_names.index("panda_finger_joint2")
    assert robot.mimic_master[f2] == f1 and robot.mimic_multiplier[f2] == 1.0 and robot.mimic_offset[f2] == 0.0
    assert (robot.mimic_master[:f2] == -1).all()
    # the second finger slides along -y of the hand: pinocchio's unaligned prismatic axis survives
    np.testing.assert_allclose(robot.axes[f2], [0.0, -1.0, 0.0])


@pytest.mark.parametrize("general_base", [False, True], ids=["cell-base", "random-base"])
def test_panda_forward_kinematics_matches_pinocchio(panda_sim, pin_model, general_base):
    P, (model, data) = panda_sim.params, pin_model
    assert P.placements.shape[0] == model.nq == 9
    np.testing.assert_array_equal(P.jtype[7:], L.JOINT_PRISMATIC)
    rng = np.random.default_rng(7 + general_base)
    W = K.make_work(P)
    worst = 0.0
    for q in rng.uniform(model.lowerPositionLimit, model.upperPositionLimit, (300, 9)):
        PP = P._replace(base=random_base(rng)) if general_base else P
        K.forward_kinematics(PP, q, W.rot, W.pos)
        pin.forwardKinematics(model, data, q)
        ref = np.asarray([PP.base @ data.oMi[j].homogeneous for j in range(1, model.njoints)])
        worst = max(worst, np.abs(W.rot - ref[:, :3, :3]).max(), np.abs(W.pos - ref[:, :3, 3]).max())
    assert worst < FK_ATOL


def test_panda_fingers_slide_apart(panda_sim):
    """Opening the fingers by d moves each finger's origin by d along its own axis, in opposite directions."""
    P = panda_sim.params
    W = K.make_work(P)
    q = np.array([0.1, -0.3, 0.2, -2.0, 0.1, 1.6, 0.7, 0.0, 0.0])
    K.forward_kinematics(P, q, W.rot, W.pos)
    closed = W.pos[7:].copy()
    q[7:] = 0.03
    K.forward_kinematics(P, q, W.rot, W.pos)
    np.testing.assert_allclose(np.linalg.norm(W.pos[7:] - closed, axis=1), 0.03, atol=1e-12)
    assert np.linalg.norm(W.pos[7] - W.pos[8]) == pytest.approx(0.06, abs=1e-12)


@pytest.mark.parametrize("general_base", [False, True], ids=["cell-base", "random-base"])
def test_panda_fastest_joint_speed_matches_pinocchio(panda_sim, pin_model, general_base):
    P, (model, data) = panda_sim.params, pin_model
    vmax = model.velocityLimit
    rng = np.random.default_rng(11 + general_base)
    W = K.make_work(P)
    for i, q in enumerate(rng.uniform(model.lowerPositionLimit, model.upperPositionLimit, (300, 9))):
        qd = rng.uniform(-vmax, vmax)
        if i % 3 == 0:  # only a finger sliding: its own origin moves at |qd|
            qd = np.where(np.arange(9) == 7 + i % 2, qd, 0.0)
        PP = P._replace(base=random_base(rng)) if general_base else P
        K.forward_kinematics(PP, q, W.rot, W.pos)
        v = K.fastest_joint_speed(PP, qd, W.rot, W.pos)
        pin.forwardKinematics(model, data, q, qd)
        ref = max(np.linalg.norm(pin.getVelocity(model, data, j, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear)
                  for j in range(1, model.njoints))
        assert v == pytest.approx(ref, rel=V_RTOL, abs=1e-13), (q, qd)


def test_panda_cell_reaches_its_poses(panda_sim, pin_model):
    """The waypoints the cell's IK found put panda_hand on the poses of the cell file (to 1 mm, 1 deg) within
    the joint limits, with the fingers held 4 cm apart (finger 2 mimicking finger 1) all along the path."""
    (model, data), spec = pin_model, panda_sim.cell.spec
    traj, robot = panda_sim.layout.trajectory, panda_sim.layout.robot
    fid = model.getFrameId(spec.robot.task.tool_frame)
    base = panda_sim.params.base
    for q, pose in zip(traj.waypoints, spec.robot.task.poses, strict=True):
        assert (q >= robot.lower).all() and (q <= robot.upper).all()
        pin.framesForwardKinematics(model, data, q)
        got = base @ data.oMf[fid].homogeneous
        want = pin.SE3(pin.rpy.rpyToMatrix(*np.deg2rad(pose.rpy_deg)), np.asarray(pose.xyz))
        assert np.linalg.norm(got[:3, 3] - want.translation) < 1e-3
        assert np.linalg.norm(pin.log3(got[:3, :3].T @ want.rotation)) < np.deg2rad(1.0)
    q, qd = np.zeros(9), np.zeros(9)
    for tau in np.linspace(0.0, traj.cycle, 501):
        K.joint_trajectory(panda_sim.params, tau, 1.0, q, qd)
        assert q[7] == q[8] == 0.02 and qd[7] == qd[8] == 0.0


def test_panda_v_R_along_the_task_matches_pinocchio(panda_sim, pin_model):
    P, (model, data) = panda_sim.params, pin_model
    traj = panda_sim.layout.trajectory
    W = K.make_work(P)
    moving = 0
    for t in np.linspace(0.0, traj.cycle, 401):
        v, _, tau = K.robot_live(P, t, np.inf, W)
        q, qd = evaluate(traj, tau)
        np.testing.assert_allclose(W.q, q, atol=1e-12)
        pin.forwardKinematics(model, data, q, qd)
        ref = max(np.linalg.norm(pin.getVelocity(model, data, j, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear)
                  for j in range(1, model.njoints))
        assert v == pytest.approx(ref, rel=V_RTOL, abs=1e-12)
        moving += ref > 0.01
    assert moving > 100


def test_panda_cell_runs_episodes(panda_sim):
    """The simulator plays episodes in the Panda cell: the arm moves, and the worker's distance to it is real."""
    rng = np.random.default_rng(0)
    acts = rng.integers(0, 30, size=(64, panda_sim.actions_per_episode))
    r = panda_sim.run_batch(acts)
    assert np.isfinite(r.min_d).all() and (r.min_d > 0.0).any()
    assert panda_sim.params.pre_v.max() > 0.3  # m/s: the arm does move


def test_search_runs_on_the_panda_cell(tmp_path, capsys):
    from cellstress.cli import main

    code = main(["search", str(CELL), "--searcher", "mcts", "--budget", "64", "--seed", "0", "--no-report",
                 "--out", str(tmp_path)])
    assert code in (0, 1), capsys.readouterr().err  # 1: a hazard found; either way the search ran
    assert (tmp_path / "result.json").is_file()


def test_reflected_mass_locks_the_held_fingers(panda_sim):
    """The ISO/TS 15066 reflected mass at a contact on the Panda is that of its 7 driven joints, the held finger
    (and its mimic) locked: the same as pinocchio's own reduced model with the finger joints locked."""
    from cellstress.robot.dynamics import point_dynamics, reflected_mass
    from cellstress.sim import scene
    from cellstress.sim.contacts import ContactModel

    layout = panda_sim.layout
    cm = ContactModel(layout)
    assert cm.reduce.shape == (9, 7)
    rng = np.random.default_rng(4)
    rows = panda_sim.run(rng.integers(0, 30, panda_sim.actions_per_episode)).rows
    full = pin.buildModelFromUrdf(str(layout.robot.urdf))
    checked = 0
    for row in rows[1:]:
        link = int(row[L.M_LINK])
        j = int(panda_sim.params.cap_joint[link])
        if j < 0:
            continue
        contact = cm.contact(row)
        q, _ = scene.joint_state(layout, row)
        reduced = pin.buildReducedModel(full, [8, 9], q)  # pinocchio's finger joints (1-based) locked at q
        data = reduced.createData()
        base = panda_sim.params.base
        pb = base[:3, :3].T @ (np.asarray(contact.robot_point) - base[:3, 3])
        jac, mass = point_dynamics(reduced, data, q[:7], j + 1, pb)
        want = reflected_mass(jac, mass, base[:3, :3].T @ np.asarray(contact.normal))
        assert contact.reflected_mass == pytest.approx(want, rel=1e-9)
        checked += 1
    assert checked > 5
