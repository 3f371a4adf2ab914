"""Every link's shape: primitives, meshes and visual shapes placed where pinocchio places them, capsules that
enclose each kind (checked on the exact shapes, not on the points the fit used), frames and unseen links."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from cellstress.core.errors import CellstressError
from cellstress.robot.capsule_fit import fit_capsule_to, fit_tight
from cellstress.robot.capsules import base_footprint, fitted_capsules
from cellstress.robot.geometry import robot_geometry
from cellstress.robot.model import BUILTIN_ROBOTS, example_robot_data_share, load_robot, resolve_urdf

BOXARM = Path(str(resources.files("cellstress.cell").joinpath("builtin", "boxarm.urdf")))
BAXTER = "robots/baxter_description/urdf/baxter.urdf"


def seg_dist(points, a, b):
    """Distance of each point to segment ab (plain numpy, independent of cellstress)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    den = d @ d
    t = np.zeros(len(points)) if den == 0 else np.clip((points - a) @ d / den, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * d), axis=1)


def volume(a, b, r):
    return np.pi * r * r * np.linalg.norm(np.subtract(b, a)) + 4.0 / 3.0 * np.pi * r**3


@pytest.mark.parametrize("name", [*BUILTIN_ROBOTS, "baxter"])
def test_shapes_are_placed_as_pinocchio_places_them(name):
    """Each collision shape's pose in its joint frame is pinocchio's geometry placement, bit for bit."""
    urdf = example_robot_data_share() / BAXTER if name == "baxter" else resolve_urdf(name, None)
    model = pin.buildModelFromUrdf(str(urdf))
    share = example_robot_data_share()
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION,
                                 package_dirs=[str(urdf.parent), str(share), str(share.parent)])
    placed = {o.name: np.asarray(o.placement.homogeneous) for o in geom.geometryObjects}
    ours = {f"{s.link}_{i}": s.pose for g in robot_geometry(urdf).links if g.source == "collision"
            for i, s in enumerate(g.shapes)}
    assert set(ours) == set(placed)
    for key, pose in ours.items():
        assert np.array_equal(pose, placed[key]), key


def _exact_far(shape, a, b) -> float:
    """The farthest point of a primitive from segment ab, from its exact description: a box's corners, a
    cylinder's rims at 20,000 angles (plus the sampling's bound), a sphere's and capsule's end balls."""
    R, t = shape.pose[:3, :3], shape.pose[:3, 3]
    if shape.kind == "box":
        h = 0.5 * np.asarray(shape.size)
        corners = np.array([(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * h
        return float(seg_dist(corners @ R.T + t, a, b).max())
    r, length = shape.size if shape.kind != "sphere" else (shape.size[0], 0.0)
    if shape.kind == "cylinder":
        phi = np.linspace(0.0, 2 * np.pi, 20_000, endpoint=False)
        rim = np.column_stack([r * np.cos(phi), r * np.sin(phi), np.zeros_like(phi)])
        pts = np.concatenate([rim + [0, 0, z] for z in (-0.5 * length, 0.5 * length)]) @ R.T + t
        return float(seg_dist(pts, a, b).max()) + r * np.pi / 20_000  # a rim point lies within r pi / n of one
    ends = np.array([[0, 0, -0.5 * length], [0, 0, 0.5 * length]]) @ R.T + t
    return float(seg_dist(ends, a, b).max()) + r


@pytest.mark.parametrize("name", ["boxarm", "baxter", "z1", "panda", "ur5-gripper", "random"])
def test_capsules_enclose_primitives_exactly(name, tmp_path):
    if name == "boxarm":
        urdf = BOXARM
    elif name == "baxter":
        urdf = example_robot_data_share() / BAXTER
    elif name == "random":
        urdf = random_primitive_robot(tmp_path, np.random.default_rng(5))
    else:
        urdf = resolve_urdf(name, None)
    robot = load_robot(urdf)
    caps = fitted_capsules(robot)
    n = 0
    for g in robot_geometry(urdf).links:
        mine = [c for c in caps if c.joint == g.joint]
        for s in g.shapes:
            if s.kind == "mesh":
                continue
            n += 1
            # inside one capsule of its joint (a convex shape inside a union would need more care)
            assert min(_exact_far(s, c.p0, c.p1) - c.radius for c in mine) <= 1e-9, (g.link, s.kind)
    assert n >= 3


def random_primitive_robot(folder: Path, rng) -> Path:
    """A 4-joint chain whose links carry random boxes, cylinders, spheres and capsules at random origins."""
    kinds = ["box", "cylinder", "sphere", "capsule"]
    links, joints = [], []
    for i in range(5):
        shapes = ""
        for _ in range(int(rng.integers(1, 4))):
            kind = kinds[int(rng.integers(4))]
            size = {"box": f'<box size="{" ".join(f"{v:.3f}" for v in rng.uniform(0.02, 0.4, 3))}"/>',
                    "cylinder": f'<cylinder radius="{rng.uniform(0.01, 0.1):.3f}" '
                                f'length="{rng.uniform(0.02, 0.5):.3f}"/>',
                    "sphere": f'<sphere radius="{rng.uniform(0.01, 0.15):.3f}"/>',
                    "capsule": f'<capsule radius="{rng.uniform(0.01, 0.1):.3f}" length="{rng.uniform(0.0, 0.4):.3f}"/>'}
            xyz, rpy = rng.uniform(-0.2, 0.2, 3), rng.uniform(-3, 3, 3)
            shapes += (f'<collision><origin xyz="{" ".join(map(str, xyz))}" rpy="{" ".join(map(str, rpy))}"/>'
                       f"<geometry>{size[kind]}</geometry></collision>")
        links.append(f'<link name="l{i}"><inertial><mass value="1"/></inertial>{shapes}</link>')
        if i:
            joints.append(f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
                          f'<origin xyz="0 0 0.3" rpy="{rng.uniform(-1, 1):.3f} 0 0"/><axis xyz="0 1 0"/>'
                          '<limit lower="-2" upper="2" velocity="1" effort="1"/></joint>')
    path = folder / "random.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="r">{"".join(links)}{"".join(joints)}</robot>')
    return path


def test_tight_fit_is_never_worse_and_fits_a_cylinder():
    """``fit_tight`` keeps the original fit as a candidate (never a larger volume) and fits a lone cylinder of
    radius r and length L with radius r (to the 64-gon's 0.12 %) and segment length L."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        pts = rng.normal(size=(40, 3)) * rng.uniform(0.02, 0.3, 3)
        balls = np.column_stack([rng.normal(size=(3, 3)) * 0.1, rng.uniform(0.01, 0.05, 3)])
        a0, b0, r0 = fit_capsule_to(pts, balls)
        a, b, r = fit_tight(pts, balls, rng.normal(size=(2, 3)))
        assert volume(a, b, r) <= volume(a0, b0, r0) * (1 + 1e-12)
        assert seg_dist(pts, a, b).max() <= r + 1e-12
        assert (seg_dist(balls[:, :3], a, b) + balls[:, 3]).max() <= r + 1e-12
    phi = 2 * np.pi * np.arange(64) / 64
    rc = 0.05 / np.cos(np.pi / 64)
    prism = np.concatenate([np.column_stack([rc * np.cos(phi), rc * np.sin(phi), np.full(64, z)]) for z in (0.0, 0.4)])
    a, b, r = fit_tight(prism, np.zeros((0, 4)), np.array([[0.0, 0.0, 1.0]]))
    assert r == pytest.approx(rc, rel=1e-9) and np.linalg.norm(b - a) == pytest.approx(0.4, abs=1e-9)


def test_visual_shapes_stand_in_and_frames_are_frames():
    so100 = robot_geometry(resolve_urdf("so100", None))
    by = {g.link: g for g in so100.links}
    assert by["gripper"].source == by["jaw"].source == "visual" and by["jaw"].shapes
    assert {c.name for c in fitted_capsules(load_robot(resolve_urdf("so100", None)))} >= {"gripper", "jaw"}
    ur10 = robot_geometry(resolve_urdf("ur10", None))
    assert {g.link for g in ur10.links if g.is_frame} == {"world", "base", "tool0"}
    assert not ur10.unseen_links()
    # the UR arm's 1 cm cube on ee_link lies in the wrist's capsule: no capsule of its own, the others unchanged
    assert "ee_link" not in {c.name for c in fitted_capsules(load_robot(resolve_urdf("ur10", None)))}


def test_a_moving_link_with_mass_and_no_shape_is_unseen(tmp_path):
    text = BOXARM.read_text().replace(
        '<collision><origin xyz="0 0 0.286" rpy="0 0 0"/><geometry><cylinder radius="0.05" length="0.572"/>'
        "</geometry></collision>", "")
    path = tmp_path / "r.urdf"
    path.write_text(text)
    unseen = robot_geometry(path).unseen_links()
    assert [g.link for g in unseen] == ["forearm_link"] and unseen[0].mass == pytest.approx(3.9)
    none = tmp_path / "none.urdf"
    none.write_text('<?xml version="1.0"?><robot name="r"><link name="a"/><link name="b"/><joint name="j" '
                    'type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" '
                    'upper="1" velocity="1" effort="1"/></joint></robot>')
    with pytest.raises(CellstressError, match="no link has a <collision> or <visual> shape"):
        fitted_capsules(load_robot(none))


def test_base_footprint_of_primitives_stays_inside_the_real_one():
    """The boxarm's base is a cylinder of radius 0.095 m up to 0.127 m: the obstacle's corners lie on its rim
    (never outside: a larger obstacle would keep the worker away) and its top is the cylinder's."""
    hull, top = base_footprint(load_robot(BOXARM))
    assert len(hull) == 64
    # (the hull rounds its points to 1e-9 m)
    assert np.linalg.norm(hull, axis=1) == pytest.approx(np.full(64, 0.095), abs=1e-9)
    assert top == pytest.approx(0.127)
