"""robot.files.referenced_meshes: the collision meshes a URDF pulls in, found as pinocchio finds them (issue 29:
every file a cell reads is listed and hashed)."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin
import pytest

from cellstress.robot.files import package_dirs, referenced_meshes
from cellstress.robot.model import BUILTIN_ROBOTS, load_pinocchio, resolve_urdf


@pytest.mark.parametrize("name", BUILTIN_ROBOTS)
def test_the_same_meshes_pinocchio_loads(name, monkeypatch):
    """Cross-check: pinocchio's own geometry loader records the path of every mesh it read (meshPath)."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    urdf = resolve_urdf(name, None)
    geom = pin.buildGeomFromUrdf(load_pinocchio(urdf), str(urdf), pin.GeometryType.COLLISION,
                                 package_dirs=package_dirs(urdf))
    theirs = {o.meshPath for o in geom.geometryObjects if o.meshPath and Path(o.meshPath).is_file()}
    mine = referenced_meshes(urdf)
    assert mine and {str(p) for p in mine} == theirs
    assert len(mine) == len(set(mine))


ROBOT = """<?xml version="1.0"?>
<robot name="r">
  <link name="base">
    <visual><geometry><mesh filename="visual-only.stl"/></geometry></visual>
    <collision><geometry><mesh filename="{a}"/></geometry></collision>
  </link>
  <link name="l1">
    <collision><geometry><mesh filename="{b}"/></geometry></collision>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    <collision><geometry><mesh filename="{a}"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>
"""


@pytest.mark.parametrize(("a", "b", "expect"), [
    ("meshes/a.stl", "package://pkg/b.stl", ["{cell}/meshes/a.stl", "{cell}/pkg/b.stl"]),
    ("file://{out}/a.stl", "{out}/b.stl", ["{out}/a.stl", "{out}/b.stl"]),
    ("package://../out/a.stl", "../out/b.stl", ["{cell}/../out/a.stl", "{cell}/../out/b.stl"]),
    ("package://nowhere/a.stl", "meshes/a.stl", ["{cell}/meshes/a.stl"]),  # what cannot be found is not read
])
def test_every_way_of_naming_a_mesh(tmp_path, monkeypatch, a, b, expect):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    cell, out = tmp_path / "cell", tmp_path / "out"
    for f in (cell / "meshes" / "a.stl", cell / "pkg" / "b.stl", out / "a.stl", out / "b.stl"):
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_bytes(b"solid x\nendsolid x\n")
    urdf = cell / "r.urdf"
    urdf.write_text(ROBOT.format(a=a.format(out=out), b=b.format(out=out)))
    assert [str(p) for p in referenced_meshes(urdf)] == [e.format(cell=cell, out=out) for e in expect]


def test_ros_package_path_is_searched_after_the_urdfs_folders(tmp_path, monkeypatch):
    ros = tmp_path / "ros"
    (ros / "pkg").mkdir(parents=True)
    (ros / "pkg" / "b.stl").write_bytes(b"x")
    (tmp_path / "cell").mkdir()
    urdf = tmp_path / "cell" / "r.urdf"
    urdf.write_text(ROBOT.format(a="package://pkg/b.stl", b="package://pkg/b.stl"))
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ros))
    assert referenced_meshes(urdf) == [Path(f"{ros}/pkg/b.stl")]
