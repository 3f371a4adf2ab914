"""Acceptance (issue 28): the same cell with a robot of box and cylinder collision shapes and with equal-size
STL meshes gives the same check, search and verify verdicts.

The STL meshes are written here from the primitives' dimensions: a box as its 8 corners and 12 triangles, a
cylinder as the prism on the regular 64-gon circumscribing it (the points the primitive fit encloses too). The
cells are the built-in pair long-gripper (flawed) and long-gripper-ok (its fixed twin), whose robot
(boxarm.urdf) is drawn in primitives only. Before issue 28 the primitive robot had no capsule at all: verify
proved the flawed cell safe.
"""

from __future__ import annotations

import re
import struct
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
import yaml

from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.robot_audit import audit_robot
from cellstress.cell.load import builtin_text, load_cell
from cellstress.robot.geometry import ROUND_SIDES, robot_geometry
from cellstress.sim.build import build_layout

ARM = resources.files("cellstress.cell").joinpath("builtin", "boxarm.urdf").read_text(encoding="utf-8")
SHAPE = re.compile(r"<geometry><(box|cylinder) ([^/]*)/></geometry>")


def _stl(vertices: np.ndarray, triangles: list[tuple[int, int, int]]) -> bytes:
    rows = b"".join(struct.pack("<12fH", 0, 0, 0, *vertices[list(t)].ravel(), 0) for t in triangles)
    return b"\0" * 80 + struct.pack("<I", len(triangles)) + rows


def box_stl(size) -> bytes:
    h = 0.5 * np.asarray(size)
    v = np.array([(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float) * h
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6),
             (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return _stl(v, faces)


def cylinder_stl(radius: float, length: float) -> bytes:
    n = ROUND_SIDES
    rc = radius / np.cos(np.pi / n)
    phi = 2 * np.pi * np.arange(n) / n
    ring = np.column_stack([rc * np.cos(phi), rc * np.sin(phi)])
    v = np.concatenate([np.column_stack([ring, np.full(n, z)]) for z in (-0.5 * length, 0.5 * length)])
    tris = [t for i in range(n) for t in ((i, (i + 1) % n, n + i), ((i + 1) % n, n + (i + 1) % n, n + i))]
    tris += [(0, k + 1, k) for k in range(1, n - 1)] + [(n, n + k, n + k + 1) for k in range(1, n - 1)]
    return _stl(v, tris)


def mesh_arm(folder: Path) -> Path:
    """boxarm.urdf with every primitive replaced by an STL mesh of the same size at the same origin."""
    count = 0

    def swap(m: re.Match) -> str:
        nonlocal count
        kind, attrs = m.group(1), dict(re.findall(r'(\w+)="([^"]*)"', m.group(2)))
        data = (box_stl([float(x) for x in attrs["size"].split()]) if kind == "box"
                else cylinder_stl(float(attrs["radius"]), float(attrs["length"])))
        name = f"shape{count}.stl"
        count += 1
        (folder / name).write_bytes(data)
        return f'<geometry><mesh filename="{name}"/></geometry>'

    text = SHAPE.sub(swap, ARM)
    assert count == 11 and "<box" not in text and "<cylinder" not in text
    path = folder / "mesharm.urdf"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def cells(tmp_path_factory) -> dict[tuple[str, str], Path]:
    """The pair with the primitive arm and with the mesh arm, as files."""
    folder = tmp_path_factory.mktemp("arms")
    (folder / "boxarm.urdf").write_text(ARM, encoding="utf-8")
    mesh_arm(folder)
    out = {}
    for name in ("long-gripper", "long-gripper-ok"):
        for arm in ("boxarm", "mesharm"):
            doc = yaml.safe_load(builtin_text(name))
            doc["robot"]["urdf"] = f"{arm}.urdf"
            path = folder / f"{name}-{arm}.yaml"
            path.write_text(yaml.safe_dump(doc), encoding="utf-8")
            out[(name, arm)] = path
    return out


def test_the_mesh_arm_is_the_primitive_arm(cells):
    """Same links, same capsule joints; every link of both inside its capsules (the audit); the mesh arm's
    capsules, fitted by the original (mesh) fit, are never thinner than the primitive arm's."""
    a = build_layout(load_cell(cells[("long-gripper", "boxarm")]))
    b = build_layout(load_cell(cells[("long-gripper", "mesharm")]))
    assert [(c.name, c.joint) for c in a.capsules] == [(c.name, c.joint) for c in b.capsules]
    for layout in (a, b):
        audit = audit_robot(robot_geometry(layout.robot.urdf), layout.capsules)
        assert audit.worst == 0.0 and len(audit.links) == 8
    for ca, cb in zip(a.capsules, b.capsules, strict=True):
        assert cb.radius >= ca.radius - 1e-6, ca.name


@pytest.mark.parametrize("name", ["long-gripper", "long-gripper-ok"])
def test_same_verdicts(name, cells, capsys):
    from cellstress.cli import main

    verdicts = {}
    for arm in ("boxarm", "mesharm"):
        path = str(cells[(name, arm)])
        cell = load_cell(path)
        static = check_cell(cell, build_layout(cell))
        out = f"{path}.out"
        search = main(["search", path, "--searcher", "plan", "--budget", "30", "--seed", "0", "--out", out,
                       "--no-report"])
        found = "FOUND at episode" in capsys.readouterr().out
        verify = main(["verify", path, "--phases", "cell", "--horizon", "4", "--out", f"{out}-verify"])
        capsys.readouterr()
        verdicts[arm] = (static.ok, static.failures(), search, found, verify)
    assert verdicts["boxarm"] == verdicts["mesharm"]
    flawed = name == "long-gripper"
    assert verdicts["boxarm"] == ((False, ["front-scanner"], 0, True, 1) if flawed else (True, [], 0, False, 0))
