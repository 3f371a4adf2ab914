"""The robot audit: on every short-name robot and on primitive-shaped ones, no sampled point of any link's
surface lies outside the capsules on its joint; and the audit does see a capsule that is too small."""

from __future__ import annotations

import dataclasses
import re
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from cellstress.analysis.robot_audit import OUTSIDE_TOL, audit_robot, surface_samples
from cellstress.robot.capsules import fitted_capsules
from cellstress.robot.geometry import robot_geometry
from cellstress.robot.model import BUILTIN_ROBOTS, example_robot_data_share, load_robot, resolve_urdf

BOXARM = Path(str(resources.files("cellstress.cell").joinpath("builtin", "boxarm.urdf")))
PRIMITIVE_ROBOTS = {"boxarm": BOXARM,
                    "baxter": example_robot_data_share() / "robots/baxter_description/urdf/baxter.urdf"}


@pytest.mark.parametrize("name", [*BUILTIN_ROBOTS, *PRIMITIVE_ROBOTS])
def test_every_link_lies_inside_its_capsules(name):
    urdf = PRIMITIVE_ROBOTS.get(name) or resolve_urdf(name, None)
    robot = load_robot(urdf)
    audit = audit_robot(robot_geometry(urdf), fitted_capsules(robot))
    assert audit.links and audit.worst == 0.0, [(a.link, a.outside) for a in audit.links if a.outside]
    assert all(a.capsules for a in audit.links)
    moving = [a for a in audit.links if a.joint >= 0]
    assert len(moving) >= 5 and sum(a.samples for a in audit.links) > 10_000


def test_the_audit_sees_a_capsule_that_is_too_small():
    """Shrink one capsule's radius by 5 mm: the audit reports about 5 mm outside on that link only (the
    largest outside distance of a surface that touched the capsule is the shrinkage)."""
    robot = load_robot(BOXARM)
    caps = fitted_capsules(robot)
    i = next(k for k, c in enumerate(caps) if c.name == "forearm_link")
    caps[i] = dataclasses.replace(caps[i], radius=caps[i].radius - 0.005)
    audit = audit_robot(robot_geometry(BOXARM), caps)
    outside = {a.link: a.outside for a in audit.links if a.outside > 0}
    assert set(outside) == {"forearm_link"}
    assert outside["forearm_link"] == pytest.approx(0.005, abs=1e-4)


def test_samples_lie_on_the_true_surfaces():
    """Independent of the fit: a cylinder's samples are at its radius or on its end discs, a sphere's at its
    radius, a box's on its faces, a capsule's at its radius from its axis segment."""
    g = {x.link: x for x in robot_geometry(BOXARM).links}
    cyl = g["forearm_link"].shapes[0]
    p = surface_samples(cyl)
    rho, z = np.hypot(p[:, 0], p[:, 1]), p[:, 2]
    on_side = np.isclose(rho, 0.05, atol=1e-12)
    on_end = np.isclose(np.abs(z), 0.286, atol=1e-12) & (rho <= 0.05 + 1e-12)
    assert np.all(on_side | on_end) and on_side.sum() > 1000 and on_end.sum() > 100
    box = g["gripper"].shapes[1]
    q = surface_samples(box)
    h = np.array([0.04, 0.04, 0.23])
    assert np.all(np.abs(q) <= h + 1e-12) and np.all(np.isclose(np.abs(q), h, atol=1e-12).any(axis=1))


def test_check_prints_the_audit(capsys):
    from cellstress.cli import main

    assert main(["check", "baseline"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^robot audit 8 links with shapes; .*outside the capsules on their joint: 0\.000 mm$", out,
                     re.M)
    assert re.search(r"^\s+ee_link\s+wrist_3_joint\s+1 box\s+in wrist_3_link, tool0#extra0: outside by 0\.000 mm",
                     out, re.M)
    assert "frames (no shape, no mass): world, base, tool0" in out


def test_declared_capsules_show_what_they_leave_out(tmp_path, capsys):
    """A cell that declares one capsule for the UR10's forearm: check passes (declared capsules are the user's
    model), and the audit shows every other moving link with no capsule."""
    import yaml

    from cellstress.cli import main

    text = resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text(encoding="utf-8")
    cell = yaml.safe_load(text)
    cell["robot"]["capsules"] = [{"link": "forearm_link", "p0": [0, 0, 0], "p1": [0, 0, 0.5], "radius": 0.08}]
    cell["robot"]["extra_capsules"] = []
    path = tmp_path / "declared.yaml"
    path.write_text(yaml.safe_dump(cell), encoding="utf-8")
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"upper_arm_link\s+shoulder_lift_joint\s+1 mesh\s+in NO CAPSULE: outside by all of it", out)
    m = re.search(r"forearm_link\s+elbow_joint\s+1 mesh\s+in forearm_link: outside by (\d+\.\d+) mm", out)
    assert m and float(m.group(1)) > 10.0
    assert OUTSIDE_TOL < 1e-6
