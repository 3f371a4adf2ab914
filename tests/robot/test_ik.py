"""Inverse kinematics for tool poses: solutions reach the pose within the limits, follow on from the previous
waypoint (a redundant arm does not jump to another configuration), and are the same on every run."""

from __future__ import annotations

import itertools

import numpy as np
import pinocchio as pin
import pytest

from cellstress.robot.ik import Unreachable, solve_poses
from cellstress.robot.joints import joint_map
from cellstress.robot.model import BUILTIN_ROBOTS, load_robot, resolve_urdf


@pytest.fixture(scope="module")
def panda():
    robot = load_robot(resolve_urdf("panda", None))
    jmap = joint_map(robot, {robot.joint_names.index("panda_finger_joint1"): 0.03})
    model = pin.buildModelFromUrdf(str(robot.urdf))
    return robot, jmap, model, model.createData()


def hand_pose(jmap, model, data, x) -> np.ndarray:
    pin.framesForwardKinematics(model, data, jmap.expand(x))
    return data.oMf[model.getFrameId("panda_hand")].homogeneous.copy()


def test_a_path_of_nearby_poses_gives_nearby_joint_values(panda):
    """Poses made by FK along a smooth joint path: from one waypoint to the next the solutions move no more
    than the path itself does (a 7-joint arm has infinitely many solutions per pose; a solver that picked any
    one would jump between them). (They need not stay on the path's own joint values: each is the solution
nearest the one before, and the path was not made that way.)"""
    robot, jmap, model, data = panda
    a = np.array([0.3, -0.4, 0.2, -2.0, 0.1, 1.8, 0.6])
    b = np.array([1.2, 0.1, -0.3, -1.6, 0.4, 2.2, -0.2])
    path = [a + s * (b - a) for s in np.linspace(0.0, 1.0, 11)]
    poses = [hand_pose(jmap, model, data, x) for x in path]
    sol = solve_poses(jmap, "panda_hand", poses, a)
    step = np.abs(np.diff(np.asarray(path), axis=0)).max()
    assert np.abs(np.diff(sol, axis=0)).max() < 1.5 * step
    np.testing.assert_allclose(sol[0], a, atol=1e-9)  # the seed already reaches the first pose
    for x, pose in zip(sol, poses, strict=True):
        got = hand_pose(jmap, model, data, x)
        assert np.linalg.norm(got[:3, 3] - pose[:3, 3]) < 1e-6
    q = jmap.expand(sol)
    assert (q >= robot.lower).all() and (q <= robot.upper).all()
    assert (q[:, 7] == 0.03).all() and (q[:, 8] == 0.03).all()  # held finger, and its mimic
    np.testing.assert_array_equal(sol, solve_poses(jmap, "panda_hand", poses, a))  # deterministic


def test_an_unreachable_pose_reports_how_far(panda):
    _, jmap, model, data = panda
    far = np.eye(4)
    far[:3, 3] = [2.0, 0.0, 0.3]
    with pytest.raises(Unreachable) as err:
        solve_poses(jmap, "panda_hand", [hand_pose(jmap, model, data, np.zeros(7)), far], np.zeros(7))
    assert err.value.index == 1
    assert err.value.residual[0] > 0.9  # m: the Panda reaches about 0.86 m


def test_poses_of_an_arm_with_continuous_joints():
    """IK through pinocchio's (cos, sin) joints of the Kinova: the poses of known joint values are reached."""
    robot = load_robot(resolve_urdf("kinova", None))
    jmap = joint_map(robot, {})
    model = pin.buildModelFromUrdf(str(robot.urdf))
    data = model.createData()
    fid = model.getFrameId("j2s6s200_end_effector")
    path = [np.array([0.3, 2.5, 3.0, 0.2, 2.0, 0.1]), np.array([1.0, 2.8, 2.6, -0.3, 2.4, 0.8])]
    poses = []
    for x in path:
        pin.framesForwardKinematics(model, data, robot.pinocchio_q(x))
        poses.append(data.oMf[fid].homogeneous.copy())
    sol = solve_poses(jmap, "j2s6s200_end_effector", poses, np.array([0.0, 2.6, 2.8, 0.0, 2.2, 0.0]))
    for x, pose in zip(sol, poses, strict=True):
        pin.framesForwardKinematics(model, data, robot.pinocchio_q(x))
        assert np.linalg.norm(data.oMf[fid].translation - pose[:3, 3]) < 1e-4  # (the tolerance is 1 mm)


# ---- issue 28: programs a robot integrator would write ---------------------------------------------------------
HELD = {"panda": "panda_finger_joint1", "z1": "jointGripper", "so100": "gripper", "so101": "gripper"}


def _tool_of(robot, jmap) -> str:
    """The last link (URDF order) that the last driven joint carries: where a tool would sit."""
    return [name for name, j in robot.link_joint.items() if j == jmap.driven[-1]][-1]


def _least_cyclic_largest_move(values: np.ndarray, lo: float, hi: float) -> float:
    """Brute force, independent of robot.turns: every whole-turn choice of every waypoint within the limits (a
    joint without limits: within three turns of the first value, which holds an optimum)."""
    per = []
    for i, v in enumerate(values):
        ks = range(-8, 9)
        if np.isfinite(lo):
            per.append([v + k * 2 * np.pi for k in ks if lo - 1e-9 <= v + k * 2 * np.pi <= hi + 1e-9])
        else:
            per.append([v + k * 2 * np.pi for k in ks if abs(v + k * 2 * np.pi - values[0]) <= 6 * np.pi] if i
                       else [v])
    return min(float(np.max(np.abs(np.roll(c, -1) - np.asarray(c)))) for c in itertools.product(*per))


@pytest.mark.parametrize("name", BUILTIN_ROBOTS)
def test_random_reachable_poses_never_turn_a_joint_more_than_needed(name):
    """The acceptance test of issue 28: on every short-name robot, programs of tool poses made by forward
    kinematics of random joint vectors within the limits (so every pose is reachable) are solved into waypoints
    that reach each pose, stay within the limits, and turn no joint further on any move than needed: at most
    180 deg, or, where the cycle has to turn back, no further than the least largest move that whole turns of
    the waypoints within the joint's limits allow (checked by brute force, not by robot.turns). A program of
    two poses has no such excuse: each move is at most 180 deg wherever the target's other turn is within
    the limits."""
    robot = load_robot(resolve_urdf(name, None))
    held = {}
    if name in HELD:
        j = robot.joint_names.index(HELD[name])
        held[j] = float(0.5 * (robot.lower[j] + robot.upper[j]))
    jmap = joint_map(robot, held)
    frame = _tool_of(robot, jmap)
    model = pin.buildModelFromUrdf(str(robot.urdf))
    data = model.createData()
    fid = model.getFrameId(frame, pin.FrameType.BODY)
    driven = list(jmap.driven)
    lo, hi = (r[driven] for r in robot.sampling_range())
    rng = np.random.default_rng(28)
    for n_poses in (2, 3):
        xs = rng.uniform(lo, hi, (n_poses, len(driven)))
        poses = []
        for x in xs:
            pin.framesForwardKinematics(model, data, robot.pinocchio_q(jmap.expand(x)))
            poses.append(data.oMf[fid].homogeneous.copy())
        home = rng.uniform(lo, hi)
        sol = solve_poses(jmap, frame, poses, home)
        q = jmap.expand(sol)
        assert (q >= robot.lower - 1e-9).all() and (q <= robot.upper + 1e-9).all()
        for x, pose in zip(sol, poses, strict=True):
            pin.framesForwardKinematics(model, data, robot.pinocchio_q(jmap.expand(x)))
            assert np.linalg.norm(data.oMf[fid].translation - pose[:3, 3]) < 1e-3
        moves = np.abs(np.roll(sol, -1, axis=0) - sol)
        for c, j in enumerate(driven):
            if robot.kinds[j] != "revolute":
                continue
            needed = _least_cyclic_largest_move(sol[:, c], float(robot.lower[j]), float(robot.upper[j]))
            assert moves[:, c].max() <= max(np.pi, needed) + 1e-6, (name, robot.joint_names[j], np.rad2deg(sol[:, c]))
            if n_poses == 2:
                for i in range(2):
                    a, b = sol[i, c], sol[1 - i, c]
                    other = b - np.sign(b - a) * 2 * np.pi
                    if robot.lower[j] - 1e-9 <= other <= robot.upper[j] + 1e-9:
                        assert abs(b - a) <= np.pi + 1e-6


def test_each_pose_takes_the_turn_nearest_the_one_before():
    """A UR5 whose home has the base turned a whole turn (pan 300 deg): the first pose, reachable at pan -50
    deg, is solved at 310 deg, 10 deg from home, not at -50 deg, 350 deg away (the range allows both)."""
    robot = load_robot(resolve_urdf("ur5", None))
    jmap = joint_map(robot, {})
    model = pin.buildModelFromUrdf(str(robot.urdf))
    data = model.createData()
    fid = model.getFrameId("tool0")
    qs = np.deg2rad([[-50.0, -80.0, 90.0, -100.0, -90.0, 0.0], [-20.0, -70.0, 80.0, -100.0, -90.0, 30.0]])
    poses = []
    for x in qs:
        pin.framesForwardKinematics(model, data, x)
        poses.append(data.oMf[fid].homogeneous.copy())
    home = np.deg2rad([300.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    sol = np.rad2deg(solve_poses(jmap, "tool0", poses, home))
    np.testing.assert_allclose(sol, np.rad2deg(qs) + [[360.0, 0, 0, 0, 0, 0]] * 2, atol=1e-3)
