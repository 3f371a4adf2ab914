"""robot.files.referenced_meshes: the meshes a URDF pulls in, found before any is read, are exactly those the
robot loader reads (issue 29: every file a cell reads is listed and hashed)."""

from __future__ import annotations

import pytest

from cellstress.robot.files import referenced_meshes
from cellstress.robot.geometry import robot_geometry
from cellstress.robot.model import BUILTIN_ROBOTS, resolve_urdf


@pytest.mark.parametrize("name", BUILTIN_ROBOTS)
def test_the_same_meshes_the_loader_reads(name):
    urdf = resolve_urdf(name, None)
    mine = referenced_meshes(urdf)
    assert set(mine) == set(robot_geometry(urdf).mesh_files())
    assert len(mine) == len(set(mine))


ROBOT = """<?xml version="1.0"?>
<robot name="r">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><mesh filename="visual-only.stl"/></geometry></visual>
    <collision><geometry><mesh filename="{a}"/></geometry></collision>
  </link>
  <link name="l1">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><geometry><mesh filename="{b}"/></geometry></collision>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    <collision><geometry><mesh filename="{a}"/></geometry></collision>
  </link>
  <link name="l2">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><mesh filename="{c}"/></geometry></visual>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>
"""


@pytest.mark.parametrize(("a", "b", "expect"), [
    ("meshes/a.stl", "package://pkg/b.stl", ["{cell}/meshes/a.stl", "{cell}/pkg/b.stl", "{cell}/c.stl"]),
    ("file://{out}/a.stl", "{out}/b.stl", ["{out}/a.stl", "{out}/b.stl", "{cell}/c.stl"]),
    ("package://../out/a.stl", "../out/b.stl", ["{cell}/../out/a.stl", "{cell}/../out/b.stl", "{cell}/c.stl"]),
])
def test_every_way_of_naming_a_mesh(tmp_path, a, b, expect):
    # a link's collision meshes, or its visual ones where it has no collision shape (l2); never a visual mesh of
    # a link that has collision shapes (base's visual-only.stl)
    cell, out = tmp_path / "cell", tmp_path / "out"
    urdf = cell / "r.urdf"
    cell.mkdir()
    urdf.write_text(ROBOT.format(a=a.format(out=out), b=b.format(out=out), c="c.stl"))
    assert [str(p) for p in referenced_meshes(urdf)] == [e.format(cell=cell, out=out) for e in expect]
