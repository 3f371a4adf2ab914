"""Loading robots: the built-in short names, URDF joints of every kind the kernel takes (revolute, prismatic,
fixed, <mimic>), and one clear error for what it does not take."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from cellstress.core.errors import CellstressError
from cellstress.robot.joints import joint_map
from cellstress.robot.model import (
    BUILTIN_ROBOTS,
    PRISMATIC,
    load_robot,
    resolve_urdf,
    unknown_urdf_message,
)
from cellstress.sim import layout as L
from cellstress.sim.kernels.robot import _forward_kinematics  # the compiled FK, without a whole cell's SimParams

LINK = '<link name="{0}"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>'
JOINT = ('<joint name="{0}" type="{1}"><parent link="{2}"/><child link="{3}"/><origin xyz="{4}" rpy="{5}"/>'
         '<axis xyz="{6}"/><limit lower="-1" upper="1" velocity="2" effort="1"/>{7}</joint>')


def urdf(tmp_path: Path, joints: list[tuple], extra: str = "") -> Path:
    """A chain base - l1 - l2 - ... with the given (name, type, origin xyz, rpy, axis, inner xml) joints."""
    links = ["base"] + [f"l{i + 1}" for i in range(len(joints))]
    body = "".join(LINK.format(n) for n in links)
    for i, (name, kind, xyz, rpy, axis, inner) in enumerate(joints):
        body += JOINT.format(name, kind, links[i], links[i + 1], xyz, rpy, axis, inner)
    path = tmp_path / "robot.urdf"
    path.write_text(f'<?xml version="1.0"?>{extra}<robot name="r">{body}</robot>', encoding="utf-8")
    return path


@pytest.mark.parametrize("name", BUILTIN_ROBOTS)
def test_every_short_name_loads(name):
    robot = load_robot(resolve_urdf(name, None))
    assert robot.n_joints >= 5
    assert (robot.velocity_limits > 0).all() and (robot.lower <= robot.upper).all()


def test_short_names_cover_ur_and_panda():
    assert {"ur3", "ur5", "ur10", "panda"} <= set(BUILTIN_ROBOTS)


def test_unknown_short_name_message():
    msg = unknown_urdf_message("xyz", Path("/cells/xyz"))
    assert msg.startswith("'xyz' is neither a built-in robot (ur3, ur5, ur10") and msg.endswith("nor a file")
    assert "URDF file not found: /cells/arm.urdf" in unknown_urdf_message("arm.urdf", Path("/cells/arm.urdf"))


def test_continuous_joints_are_unbounded_revolute_joints():
    """The Kinova's continuous joints (pinocchio's nq = 2: cos, sin) are revolute joints without angle limits;
    the kernel's FK at any angles, even past a turn, is pinocchio's at pinocchio_q of them."""
    robot = load_robot(resolve_urdf("kinova", None))
    np.testing.assert_array_equal(robot.continuous, [True, False, False, True, False, True])
    assert np.isinf(robot.lower[robot.continuous]).all() and np.isinf(robot.upper[robot.continuous]).all()
    assert np.isfinite(robot.lower[~robot.continuous]).all()
    model = pin.buildModelFromUrdf(str(robot.urdf))
    data = model.createData()
    jtype = np.full(6, L.JOINT_REVOLUTE)
    rng = np.random.default_rng(2)
    lo, hi = robot.sampling_range()
    rot, pos = np.zeros((6, 3, 3)), np.zeros((6, 3))
    for q in rng.uniform(lo, hi, (200, 6)) + np.where(robot.continuous, rng.integers(-3, 4, 6) * 2 * np.pi, 0.0):
        _forward_kinematics(robot.parents, robot.placements, np.eye(4), robot.axes, jtype, q, rot, pos)
        pin.forwardKinematics(model, data, robot.pinocchio_q(q))
        for j in range(6):
            np.testing.assert_allclose(pos[j], data.oMi[j + 1].translation, atol=1e-12)
            np.testing.assert_allclose(rot[j], data.oMi[j + 1].rotation, atol=1e-12)


def test_pinocchio_q_is_q_without_continuous_joints():
    robot = load_robot(resolve_urdf("ur10", None))
    q = np.arange(6.0)
    assert robot.pinocchio_q(q) is q


def test_mimic_with_multiplier_and_offset(tmp_path):
    path = urdf(tmp_path, [
        ("a", "revolute", "0 0 0.3", "0 0 0", "0 0 1", ""),
        ("fix", "fixed", "0.2 0 0", "0 0.3 0", "0 0 1", ""),
        ("b", "prismatic", "0 0.1 0", "0.2 0 0", "1 0 0", ""),
        ("c", "revolute", "0 0 0.1", "0 0 0", "0 1 0", '<mimic joint="a" multiplier="-0.5" offset="0.1"/>'),
        ("d", "prismatic", "0 0 0.1", "0 0 0", "0 0 1", '<mimic joint="b" multiplier="2"/>'),
    ])
    robot = load_robot(path)
    assert robot.joint_names == ("a", "b", "c", "d")  # the fixed joint is merged into the frames
    np.testing.assert_array_equal(robot.mimic_master, [-1, -1, 0, 1])
    np.testing.assert_array_equal(robot.mimic_multiplier, [1.0, 1.0, -0.5, 2.0])
    np.testing.assert_array_equal(robot.mimic_offset, [0.0, 0.0, 0.1, 0.0])
    assert robot.kinds[1] == robot.kinds[3] == PRISMATIC
    jm = joint_map(robot, {})
    assert jm.driven_names == ("a", "b")
    q = jm.expand(np.array([0.4, 0.3]))
    np.testing.assert_allclose(q, [0.4, 0.3, -0.5 * 0.4 + 0.1, 0.6])
    # the kernel's chain through the fixed joint, at the expanded vector, against pinocchio's
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    jtype = np.asarray([L.JOINT_PRISMATIC if k == PRISMATIC else L.JOINT_REVOLUTE for k in robot.kinds])
    rot, pos = np.zeros((4, 3, 3)), np.zeros((4, 3))
    _forward_kinematics(robot.parents, robot.placements, np.eye(4), robot.axes, jtype, q, rot, pos)
    for j in range(4):
        np.testing.assert_allclose(pos[j], data.oMi[j + 1].translation, atol=1e-12)
        np.testing.assert_allclose(rot[j], data.oMi[j + 1].rotation, atol=1e-12)


def test_mimic_of_an_unknown_joint(tmp_path):
    path = urdf(tmp_path, [("a", "revolute", "0 0 0.3", "0 0 0", "0 0 1", '<mimic joint="zz"/>')])
    with pytest.raises(CellstressError, match="<mimic>: names joint 'zz', which the URDF does not define"):
        load_robot(path)


def test_xml_entities_are_refused(tmp_path):
    bomb = '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>'
    path = urdf(tmp_path, [("a", "revolute", "0 0 0.3", "0 0 0", "0 0 1", "")], extra=bomb)
    with pytest.raises(CellstressError, match="declares XML entities"):
        load_robot(path)


def test_joint_without_velocity_limit(tmp_path):
    path = urdf(tmp_path, [("a", "revolute", "0 0 0.3", "0 0 0", "0 0 1", "")])
    path.write_text(path.read_text().replace('velocity="2"', 'velocity="0"'))
    with pytest.raises(CellstressError, match="no velocity limit"):
        load_robot(path)
