"""A URDF is checked by us before pinocchio's parser sees it, and that parser's own complaints on file
descriptor 2 never reach the user."""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

import pytest

from cellstress.core.errors import CellstressError
from cellstress.robot.geometry import robot_geometry
from cellstress.robot.model import load_pinocchio, mesh_paths, resolve_urdf
from cellstress.robot.urdf_file import (
    MAX_URDF_JOINTS,
    captured_fd2,
    package_dirs,
    parse_urdf,
    read_urdf,
    resolve_mesh,
)

BOXARM = resources.files("cellstress.cell").joinpath("builtin", "boxarm.urdf").read_text(encoding="utf-8")
FOREARM = ('<collision><origin xyz="0 0 0.286" rpy="0 0 0"/><geometry><cylinder radius="0.05" length="0.572"/>'
           "</geometry></collision>")


def chain(n: int, joint_extra: str = "") -> str:
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
                     f'<axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/>{joint_extra}</joint>'
                     for i in range(n))
    return f'<?xml version="1.0"?><robot name="r">{links}{joints}</robot>'


BAD: list[tuple[str, str | bytes, str]] = [
    ("empty", "", "is empty"),
    ("blank", "  \n ", "is empty"),
    ("utf16", BOXARM.encode("utf-16"), "UTF-16"),
    ("latin1", BOXARM.replace("boxarm", "b\xe9").encode("latin-1"), "not UTF-8"),
    ("not-xml", "<robot", "not well-formed XML"),
    ("entity", '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "x">]><robot name="r"><link name="&a;"/></robot>',
     "entities"),
    ("not-robot", '<?xml version="1.0"?><html/>', "not <robot>"),
    ("no-link", '<?xml version="1.0"?><robot name="r"/>', "defines no <link>"),
    ("too-many-joints", chain(MAX_URDF_JOINTS + 1), f"at most {MAX_URDF_JOINTS}"),
    ("dup-link", BOXARM.replace('<link name="tool0"/>', '<link name="tool0"/><link name="tool0"/>'),
     "link 'tool0': is defined twice"),
    ("dup-joint", chain(2).replace('name="j1"', 'name="j0"'), "joint 'j0': is defined twice"),
    ("cycle", chain(2).replace('<child link="l2"/>', '<child link="l0"/>'), "link 'l0': lies on a cycle"),
    ("pure-cycle", '<?xml version="1.0"?><robot name="r"><link name="a"/><link name="b"/>'
                   '<joint name="x" type="fixed"><parent link="a"/><child link="b"/></joint>'
                   '<joint name="y" type="fixed"><parent link="b"/><child link="a"/></joint></robot>', "cycle"),
    ("two-parents", BOXARM.replace("</robot>", '<joint name="loop" type="fixed"><parent link="gripper"/>'
                                               '<child link="shoulder_link"/></joint></robot>'), "child of two joints"),
    ("disconnected", BOXARM.replace("</robot>", '<link name="loose"/></robot>'), "is not connected"),
    ("missing-link", chain(1).replace('<child link="l1"/>', '<child link="zz"/>'), "'zz', which the URDF does not"),
    ("self-joint", chain(1).replace('<child link="l1"/>', '<child link="l0"/>'), "to itself"),
    ("nan-limit", chain(1).replace('upper="1"', 'upper="nan"'), "<limit upper>: is not finite"),
    ("inf-velocity", chain(1).replace('velocity="1"', 'velocity="inf"'), "<limit velocity>: is not finite"),
    ("no-limit", chain(1).replace('<limit lower="-1" upper="1" velocity="1" effort="1"/>', ""), "has no <limit>"),
    ("axis-zero", chain(1).replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'), "is zero"),
    ("axis-nan", chain(1).replace('<axis xyz="0 0 1"/>', '<axis xyz="0 nan 1"/>'), "not finite"),
    ("origin-far", chain(1, '<origin xyz="1e30 0 0"/>'), "more than 100 m"),
    ("origin-words", chain(1, '<origin xyz="a b c"/>'), "is not 3 numbers"),
    ("origin-two", chain(1, '<origin xyz="1 2"/>'), "has 2 values, not 3"),
    ("unknown-type", chain(1).replace('type="revolute"', 'type="ball"'), "has type 'ball'"),
    ("box-negative", BOXARM.replace('size="0.08 0.08 0.46"', 'size="0.08 -0.08 0.46"'), "sizes must be positive"),
    ("radius-huge", BOXARM.replace('radius="0.095"', 'radius="1e9"'), "at most 100 m"),
    ("mesh-no-file", BOXARM.replace(FOREARM, '<collision><geometry><mesh/></geometry></collision>'), "no filename"),
    ("mesh-scale-zero", BOXARM.replace(FOREARM, '<collision><geometry><mesh filename="a.stl" scale="0 1 1"/>'
                                                "</geometry></collision>"), "scale"),
    ("two-geometries", BOXARM.replace(FOREARM, '<collision><geometry><box size="1 1 1"/><sphere radius="1"/>'
                                               "</geometry></collision>"), "exactly one <geometry>"),
    ("mass-negative", BOXARM.replace('<mass value="3.9"/>', '<mass value="-3.9"/>'), "is negative"),
    ("inertia-nan", BOXARM.replace('ixx="0.1"', 'ixx="nan"'), "<inertia ixx>"),
    ("mimic-unknown", chain(2).replace('effort="1"/></joint></robot>', 'effort="1"/><mimic joint="q"/></joint>'
                                                                       "</robot>"), "<mimic>: names joint 'q'"),
    ("long-name", BOXARM.replace('<child link="gripper"/>', '<child link="' + "g" * 5000 + '"/>'),
     "'" + "g" * 60 + "...', which the URDF does not define"),
]


@pytest.mark.parametrize(("name", "text", "says"), BAD, ids=[b[0] for b in BAD])
def test_bad_urdfs_are_refused_in_our_words(name, text, says, tmp_path):
    data = text.encode("utf-8") if isinstance(text, str) else text
    with pytest.raises(CellstressError) as err:
        parse_urdf(tmp_path / "r.urdf", data)
    msg = str(err.value)
    assert msg.startswith(str(tmp_path / "r.urdf")) and says in msg, msg
    assert len(msg) < 400 and "\n" not in msg


def test_the_built_in_urdfs_pass(tmp_path):
    doc = parse_urdf(tmp_path / "b.urdf", BOXARM.encode())
    assert doc.links[0] == "base_link" and doc.masses["tool0"] is None and doc.masses["forearm_link"] == 3.9
    assert [s.kind for s in doc.collision["gripper"]] == ["cylinder", "box"]


def test_resolve_mesh(tmp_path):
    urdf = tmp_path / "sub" / "r.urdf"
    assert resolve_mesh("m/a.stl", urdf) == tmp_path / "sub" / "m" / "a.stl"
    assert resolve_mesh("/abs/a.stl", urdf) == Path("/abs/a.stl")
    assert resolve_mesh("file:///abs/a.stl", urdf) == Path("/abs/a.stl")
    assert resolve_mesh("package://pkg/a.stl", urdf) == package_dirs(urdf)[0] / "pkg" / "a.stl"
    ur = read_urdf(Path(str(resources.files("cellstress.cell").joinpath("builtin", "boxarm.urdf"))))
    assert ur.mesh_references() == ()


def test_mesh_paths_of_a_short_name_robot():
    paths = mesh_paths(resolve_urdf("ur10", None))
    assert len(paths) == 14 and all(p.is_file() for p in paths)  # 7 collision STL, 7 visual DAE
    assert len(set(paths)) == len(paths)
    read = robot_geometry(resolve_urdf("ur10", None)).mesh_files()
    assert read == paths[:7] and all(p.suffix == ".stl" for p in read)  # only the collision meshes are read


def test_file_descriptor_2_is_captured():
    with captured_fd2() as said:
        os.write(2, b"Error:   Could not parse this\n   at line 3\n")
    assert said == ["Error:   Could not parse this", "   at line 3"]


def test_pinocchio_chatter_stays_quiet(tmp_path, capfd):
    """urdfdom does not know <capsule> and says so on fd 2 for each; we read capsules ourselves, so a URDF with
    one loads, and nothing reaches the terminal."""
    path = tmp_path / "cap.urdf"
    path.write_text(BOXARM.replace(FOREARM, '<collision><geometry><capsule radius="0.05" length="0.4"/></geometry>'
                                            "</collision>"))
    model = load_pinocchio(path)
    assert model.njoints == 7
    assert capfd.readouterr().err == ""
