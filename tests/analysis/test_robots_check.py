"""The static check of a cell with several robots: one ISO 13855 row per device and robot it stops, each with
that robot's stopping time and measured to that robot's hazard zone; a robot the curtain does not stop is open to
a worker who walks through it."""

from __future__ import annotations

import pytest

from cellstress.analysis.hazard_zone import hazard_zone
from cellstress.analysis.iso13855 import check_cell
from cellstress.cell.load import load_cell
from cellstress.sim.build import build_layout


@pytest.fixture(scope="module")
def fixed():
    return check_cell("two-robots-fixed")


@pytest.fixture(scope="module")
def flawed():
    return check_cell("two-robots")


def test_per_robot_rows(fixed):
    rows = {(d.device, d.robot): d for d in fixed.devices}
    assert set(rows) == {("bay-curtain", "a"), ("bay-curtain", "b")}
    a, b = rows["bay-curtain", "a"], rows["bay-curtain", "b"]
    assert (a.stopping_time, b.stopping_time) == (0.15, 0.30)
    # ISO 13855 body detection: S = 1600 T + 850 mm, T = 0.05 s + the robot's stopping time
    assert a.required == pytest.approx(1.170) and b.required == pytest.approx(1.410)
    assert a.where.robot_part.startswith("a:") and b.where.robot_part.startswith("b:")
    assert fixed.ok and fixed.failures() == []
    lines = "\n".join(fixed.lines())
    assert "bay-curtain (light-curtain, stopping robot b): T = 0.05 + 0.30 s" in lines
    assert "undetected reach to robot b's hazard zone (devices that stop it: bay-curtain)" in lines


def test_robot_the_curtain_does_not_stop_fails(flawed):
    assert [(d.device, d.robot) for d in flawed.devices] == [("bay-curtain", "a")]
    assert flawed.failures() == ["undetected-reach:b"]
    b = flawed.robot_approaches[0]
    assert b.robot == "b" and b.guards == () and b.distance < 0.85
    assert "undetected reach to robot b's hazard zone (devices that stop it: none)" in "\n".join(flawed.lines())


def test_zone_of_each_robot_is_part_of_the_whole():
    layout = build_layout(load_cell("two-robots-fixed"))
    whole = hazard_zone(layout)
    za, zb = hazard_zone(layout, robot=0), hazard_zone(layout, robot=1)
    assert {whole.part_names[p].split(":")[0] for p in za.part} == {"a"}
    assert {whole.part_names[p].split(":")[0] for p in zb.part} == {"b"}
    assert len(whole.a) == len(za.a) + len(zb.a)
    assert whole.extent()[0] == pytest.approx(min(za.extent()[0], zb.extent()[0]))
