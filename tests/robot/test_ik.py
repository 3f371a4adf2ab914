"""Inverse kinematics for tool poses: solutions reach the pose within the limits, follow on from the previous
waypoint (a redundant arm does not jump to another configuration), and are the same on every run."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from cellstress.robot.ik import Unreachable, solve_poses
from cellstress.robot.joints import joint_map
from cellstress.robot.model import load_robot, resolve_urdf


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
