"""The compiled robot kinematics against pinocchio, and the compiled trajectory against its Python reference.

Pinocchio's joint j is the kernel's joint j - 1 (pinocchio's joint 0 is the universe), and the kernel's world
is pinocchio's world placed by the robot base pose P.base.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from cellstress.robot.trajectory import MIN_SEGMENT_TIME, evaluate
from cellstress.sim import kernels as K
from cellstress.sim import layout as L

N_CONFIGS = 300
FK_ATOL = 1e-12  # metres / rotation-matrix entries; both sides are double-precision products of ~6 matrices
V_RTOL = 1e-10


@pytest.fixture(scope="module")
def setup(baseline_sim):
    P = baseline_sim.params
    model = pin.buildModelFromUrdf(str(baseline_sim.layout.robot.urdf))
    return baseline_sim, P, model, model.createData()


def random_base(rng):
    """A general rigid base pose (tilted as well as yawed), so that base rotation errors cannot hide."""
    R = pin.rpy.rpyToMatrix(*rng.uniform(-np.pi, np.pi, 3))
    m = np.eye(4)
    m[:3, :3] = R
    m[:3, 3] = rng.uniform(-2.0, 2.0, 3)
    return m


def random_q(rng, model, n):
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    return rng.uniform(lo, hi, (n, model.nq))


def pin_joint_poses(model, data, base, q):
    pin.forwardKinematics(model, data, q)
    out = []
    for j in range(1, model.njoints):
        m = base @ data.oMi[j].homogeneous
        out.append(m)
    return np.asarray(out)


def test_kernel_chain_matches_pinocchio_model(setup):
    _, P, model, _ = setup
    assert model.nq == model.nv == P.placements.shape[0] == 6
    assert model.njoints == 7
    np.testing.assert_array_equal(P.parents, [model.parents[j] - 1 for j in range(1, model.njoints)])


@pytest.mark.parametrize("general_base", [False, True], ids=["cell-base", "random-base"])
def test_forward_kinematics_matches_pinocchio(setup, general_base):
    _, P, model, data = setup
    rng = np.random.default_rng(20240611 + general_base)
    W = K.make_work(P)
    worst_pos = worst_rot = 0.0
    for q in random_q(rng, model, N_CONFIGS):
        PP = P._replace(base=random_base(rng)) if general_base else P
        K.forward_kinematics(PP, q, W.rot, W.pos)
        ref = pin_joint_poses(model, data, PP.base, q)
        worst_rot = max(worst_rot, np.abs(W.rot - ref[:, :3, :3]).max())
        worst_pos = max(worst_pos, np.abs(W.pos - ref[:, :3, 3]).max())
    assert worst_rot < FK_ATOL
    assert worst_pos < FK_ATOL


def test_forward_kinematics_home_pose_is_not_trivial(setup):
    """At q = 0 the UR10's wrist is about 1.2 m out along the base's x axis: a sanity check that the FK test
    compares real chains (a kernel that ignored placements would also 'agree' at the base)."""
    _, P, _, _ = setup
    W = K.make_work(P)
    K.forward_kinematics(P, np.zeros(6), W.rot, W.pos)
    reach = np.linalg.norm(W.pos[-1, :2] - P.base[:2, 3])
    assert 1.0 < reach < 1.4
    assert W.pos[0, 2] == pytest.approx(P.base[2, 3] + 0.1273, abs=1e-3)  # UR10 shoulder height d1


def pin_fastest_joint_speed(model, data, base, q, qd):
    """max over joints of |linear velocity of the joint origin| (rotation by the base keeps speeds)."""
    pin.forwardKinematics(model, data, q, qd)
    speeds = [np.linalg.norm(pin.getVelocity(model, data, j, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear)
              for j in range(1, model.njoints)]
    return max(speeds), np.asarray(speeds)


@pytest.mark.parametrize("general_base", [False, True], ids=["cell-base", "random-base"])
def test_fastest_joint_speed_matches_pinocchio(setup, general_base):
    sim, P, model, data = setup
    vmax = sim.layout.robot.velocity_limits
    rng = np.random.default_rng(99 + general_base)
    W = K.make_work(P)
    for i, q in enumerate(random_q(rng, model, N_CONFIGS)):
        qd = rng.uniform(-vmax, vmax)
        if i % 5 == 0:  # only one joint moving: each joint's contribution on its own
            keep = rng.integers(6)
            qd = np.where(np.arange(6) == keep, qd, 0.0)
        PP = P._replace(base=random_base(rng)) if general_base else P
        K.forward_kinematics(PP, q, W.rot, W.pos)
        v = K.fastest_joint_speed(PP, qd, W.rot, W.pos)
        ref, _ = pin_fastest_joint_speed(model, data, PP.base, q, qd)
        assert v == pytest.approx(ref, rel=V_RTOL, abs=1e-13), (q, qd)


def test_fastest_joint_speed_of_a_single_joint_is_omega_times_radius(setup):
    """Only the pan joint turning at w: the fastest origin moves at w times its distance from the pan axis."""
    _, P, model, _ = setup
    W = K.make_work(P)
    q = np.array([0.3, -0.7, 1.1, -1.5, -1.57, 0.2])
    K.forward_kinematics(P, q, W.rot, W.pos)
    axis = W.rot[0] @ P.axes[0]
    rel = W.pos - W.pos[0]
    radii = np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1)
    w = 1.7
    v = K.fastest_joint_speed(P, np.array([w, 0, 0, 0, 0, 0.0]), W.rot, W.pos)
    assert v == pytest.approx(w * radii.max(), rel=1e-12)
    assert v > 0.5


def test_robot_live_v_R_matches_pinocchio_along_the_task(setup):
    """End to end: v_R from path time (kernel) against pinocchio at the reference trajectory's q and qd."""
    sim, P, model, data = setup
    traj = sim.layout.trajectory
    W = K.make_work(P)
    ts = np.linspace(0.0, 2 * traj.cycle, 701)
    moving = 0
    for t in ts:
        v, phase, tau = K.robot_live(P, t, np.inf, W)
        assert phase == L.PHASE_RUNNING
        q, qd = evaluate(traj, tau)
        ref, _ = pin_fastest_joint_speed(model, data, P.base, q, qd)
        assert v == pytest.approx(ref, rel=V_RTOL, abs=1e-12)
        moving += ref > 0.01
    assert moving > 100  # the check covered the robot in motion, not only dwells
    # the pre-stop table the simulator uses holds the same numbers
    k = np.arange(0, P.pre_v.shape[0], 7)
    dt = P.scal[L.C_DT]
    for kk in k:
        v, _, tau = K.robot_live(P, kk * dt, np.inf, W)
        assert P.pre_v[kk] == v and P.pre_tau[kk] == tau


# ---- trajectory --------------------------------------------------------------------------------------------
def test_joint_trajectory_matches_reference(setup):
    sim, P, _, _ = setup
    traj = sim.layout.trajectory
    rng = np.random.default_rng(5)
    q, qd = np.zeros(6), np.zeros(6)
    taus = np.concatenate([
        rng.uniform(-traj.cycle, 3 * traj.cycle, 2000),
        traj.starts, traj.starts + traj.dwells, traj.starts + traj.dwells + traj.move_times,  # the joins
        traj.starts + traj.dwells + 0.5 * traj.move_times,  # peak speed
    ])
    for tau in taus:
        sigma = rng.uniform(0.0, 1.0)
        K.joint_trajectory(P, tau, sigma, q, qd)
        q_ref, qd_ref = evaluate(traj, tau)
        np.testing.assert_allclose(q, q_ref, rtol=0, atol=1e-12)
        np.testing.assert_allclose(qd, sigma * qd_ref, rtol=0, atol=1e-12)


def test_trajectory_visits_the_waypoints(setup):
    sim, P, _, _ = setup
    traj = sim.layout.trajectory
    wp = np.deg2rad(np.asarray(sim.cell.spec.robot.task.waypoints_deg, float))
    q, qd = np.zeros(6), np.zeros(6)
    for i, start in enumerate(traj.starts):
        for tau in (start, start + 0.5 * traj.dwells[i]):  # during the dwell
            K.joint_trajectory(P, tau, 1.0, q, qd)
            np.testing.assert_allclose(q, wp[i], atol=1e-12)
            np.testing.assert_array_equal(qd, 0.0)
        K.joint_trajectory(P, start + traj.dwells[i] + traj.move_times[i] * (1 - 1e-12), 1.0, q, qd)
        np.testing.assert_allclose(q, wp[(i + 1) % len(wp)], atol=1e-9)


def test_trajectory_velocity_is_continuous(setup):
    """Sampled every dt, no joint velocity jumps by more than max|acceleration| * dt (anywhere, joins
    included); a minimum-jerk move of dq in T has max|acceleration| = (10 / sqrt(3)) |dq| / T^2."""
    sim, P, _, _ = setup
    traj = sim.layout.trajectory
    dt = 1e-4
    taus = np.arange(-0.01, traj.cycle + 0.01, dt)
    q, qd = np.zeros(6), np.zeros(6)
    Q, QD = np.empty((len(taus), 6)), np.empty((len(taus), 6))
    for i, tau in enumerate(taus):
        K.joint_trajectory(P, tau, 1.0, q, qd)
        Q[i], QD[i] = q, qd
    n = len(traj.waypoints)
    acc = max(np.max(10 / np.sqrt(3) * np.abs(traj.waypoints[(i + 1) % n] - traj.waypoints[i])
                     / traj.move_times[i] ** 2) for i in range(n))
    assert acc > 0
    assert np.abs(np.diff(QD, axis=0)).max() <= acc * dt * (1 + 1e-6)
    # positions too (bounded by the top speed)
    assert np.abs(np.diff(Q, axis=0)).max() <= np.abs(QD).max() * dt * (1 + 1e-6)
    # and the one-sided limits at every join agree (both zero: moves start and end at rest)
    eps = 1e-7
    for start, dwell, move in zip(traj.starts, traj.dwells, traj.move_times, strict=True):
        for join in (start, start + dwell, start + dwell + move):
            for tau in (join - eps, join + eps):
                K.joint_trajectory(P, tau, 1.0, q, qd)
                assert np.abs(qd).max() < 1e-9


def test_peak_joint_speed_respects_scaled_limits(setup):
    sim, P, _, _ = setup
    traj = sim.layout.trajectory
    scale = sim.cell.spec.robot.task.speed_scale
    vmax = sim.layout.robot.velocity_limits
    limit = scale * vmax
    q, qd = np.zeros(6), np.zeros(6)
    mid = traj.starts + traj.dwells + 0.5 * traj.move_times  # where each move peaks
    taus = np.concatenate([np.linspace(0.0, traj.cycle, 20001), mid])
    peak = np.zeros(6)
    for tau in taus:
        K.joint_trajectory(P, tau, 1.0, q, qd)
        peak = np.maximum(peak, np.abs(qd))
    assert np.all(peak <= limit * (1 + 1e-12)), peak / limit
    # the limiting joint of each move runs at the scaled limit at mid-move (the time is not padded)
    for i, start in enumerate(traj.starts):
        if traj.move_times[i] <= MIN_SEGMENT_TIME:
            continue
        K.joint_trajectory(P, start + traj.dwells[i] + 0.5 * traj.move_times[i], 1.0, q, qd)
        assert np.max(np.abs(qd) / limit) == pytest.approx(1.0, rel=1e-9)
