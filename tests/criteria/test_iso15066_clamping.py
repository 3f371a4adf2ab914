"""iso15066: clamping (quasi-static) against free (transient) contacts, the force a clamping robot exerts until it
stands, and the worker's own speed in v_rel (issue 34, Deliver 4)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cellstress.cell.load import load_cell
from cellstress.core.records import Contact
from cellstress.core.surroundings import Backing, ContactInCell
from cellstress.criteria.iso15066 import (
    CLAMP_TOLERANCE,
    HUMAN_SPEED_CAP,
    Iso15066,
    clamping_force,
    quasi_static_limit,
    transient_limit,
)
from cellstress.sim import layout as L
from cellstress.sim.build import build_layout
from cellstress.sim.clamping import FixedSurfaces, body_thickness
from cellstress.sim.scene import body_pose

HAND_K = 75_000.0  # N/m, ISO/TS 15066 Table A.3
HAND_M = 0.6  # kg


@pytest.fixture(scope="module")
def baseline():
    return build_layout(load_cell("baseline"))


def _contact(region="hands", v_rel=0.3, m=10.0, v_r=0.3, v_human=0.0, backing=None, d=0.0) -> ContactInCell:
    return ContactInCell(d, v_r, "wrist_3_link", "right-hand", region, (0.0, 0.0, 0.9), (0.0, 0.0, 0.88),
                         (0.0, 0.0, -1.0), v_rel, m, v_human, backing)


def _backing(surface: str, distance: float, thickness: float, v_push=0.0, m_push=10.0, travel=0.0) -> Backing:
    return Backing(surface, distance, thickness, (0.0, 0.0, -1.0), v_push, m_push, travel)


def _mu(m_r: float, m_h: float = HAND_M) -> float:
    return 1.0 / (1.0 / m_h + 1.0 / m_r)


def test_a_hand_on_the_table_under_a_descending_tool_is_clamped_and_0_5_m_above_it_is_not(baseline):
    """The table of the baseline cell (0.85 m, its base strip spans x -1..1, y -0.4..0.3) under a tool moving
    straight down onto a hand: the ray from the hand's contact point down finds the table top."""
    surfaces = FixedSurfaces(baseline)
    pose = body_pose(baseline, L.pose_vector(0.0, 0.0, 0.0))
    hand = body_thickness(baseline, L.PART_RIGHT_REACH, pose)
    assert hand == pytest.approx(0.05)  # 2 x the 25 mm hand radius
    down = (0.0, 0.0, -1.0)
    on_table = (0.7, 0.0, 0.85 + hand)  # the hand's top side: the tool touches it there
    name, dist = surfaces.nearest(on_table, down)
    assert name == "table" and dist == pytest.approx(hand)
    b = _backing(name, dist, hand, v_push=0.05, travel=0.004)
    assert b.gap == pytest.approx(0.0) and Iso15066.clamped(b)
    # the same contact 0.5 m higher: the table is 0.55 m below, beyond the search range (0.5 m) and the gap
    above = (0.7, 0.0, 0.85 + hand + 0.5)
    assert surfaces.nearest(above, down) is None
    far = surfaces.nearest(above, down, reach=1.0)
    assert far[0] == "table" and far[1] == pytest.approx(0.55)
    assert not Iso15066.clamped(_backing(*far, hand))
    # the gap rule's edge: thickness + 20 mm clamps, a millimetre more does not
    assert Iso15066.clamped(_backing("table", hand + CLAMP_TOLERANCE - 1e-9, hand))
    assert not Iso15066.clamped(_backing("table", hand + CLAMP_TOLERANCE + 0.001, hand))


def test_fixed_surfaces_against_hand_computed_distances(baseline):
    surfaces = FixedSurfaces(baseline)
    # beside the table (x 1.5 is outside its footprint) straight down: the floor at the point's height
    assert surfaces.nearest((1.5, 0.0, 0.3), (0.0, 0.0, -1.0)) == ("floor", pytest.approx(0.3))
    # inside the table's solid: distance 0
    assert surfaces.nearest((0.0, 0.0, 0.5), (0.0, 0.0, 1.0)) == ("table", 0.0)
    # towards the table's side face x = 1.0 at 45 degrees downwards from (1.2, 0, 0.5): 0.2 m in x, so
    # 0.2 * sqrt(2) along the ray, hitting the face at z 0.3 (within 0 .. 0.85)
    d = np.array([-1.0, 0.0, -1.0]) / math.sqrt(2.0)
    assert surfaces.nearest((1.2, 0.0, 0.5), d) == ("table", pytest.approx(0.2 * math.sqrt(2.0)))
    # a fence panel, horizontally: the kernel's fence rows are the panels
    row = baseline.params.fences[0]
    a, b = row[0:2], row[2:4]
    mid = (a + b) / 2.0
    normal = np.array([-(b - a)[1], (b - a)[0], 0.0]) / np.linalg.norm(b - a)
    z = (row[4] + row[5]) / 2.0
    start = np.array([mid[0], mid[1], z]) - 0.1 * normal
    name, dist = surfaces.nearest(start, normal)
    assert name.startswith("fence panel") and dist == pytest.approx(0.1)


def test_the_quasi_static_limit_applies_only_when_clamped():
    crit = Iso15066()
    clamped = _backing("table", 0.05, 0.05)
    free = _backing("table", 0.4, 0.05)
    # a 10 kg robot at 0.4 m/s on a hand: transient F = 0.4 sqrt(mu k) = 0.4 sqrt(0.566 * 75000) = 82.4 N
    f = 0.4 * math.sqrt(_mu(10.0 + 2.0) * HAND_K)
    vc, vt = crit.judge(_contact(v_rel=0.4, backing=clamped)), crit.judge(_contact(v_rel=0.4, backing=free))
    assert vt.case == "transient" and vt.limit == transient_limit("hands") == 280.0 and vt.force == pytest.approx(f)
    assert vc.case == "clamping" and vc.limit == quasi_static_limit("hands") == 140.0
    assert vc.force == pytest.approx(f)  # the robot pushes no further (v_push 0, travel 0): the impact is all
    assert "clamped against the table 50 mm behind the contact" in vc.summary()
    assert "free: the table 400 mm behind" in vt.summary()
    # a plain Contact (no surroundings) is transient, as before
    plain = Contact(0.0, 0.3, "l", "right-hand", "hands", (0, 0, 0), (0, 0, 0), (0, 0, 1), 0.4, 10.0)
    assert crit.judge(plain).case == "transient" and crit.judge(plain).force == pytest.approx(f)


def test_under_the_transient_limit_but_over_the_quasi_static_one_is_unsafe_only_when_clamped():
    crit = Iso15066()
    v = 200.0 / math.sqrt(_mu(12.0) * HAND_K)  # a 200 N transient force: 140 < 200 < 280
    free = crit.judge(_contact(v_rel=v, backing=None))
    clamped = crit.judge(_contact(v_rel=v, backing=_backing("table", 0.03, 0.05)))
    assert free.force == pytest.approx(200.0) and clamped.force == pytest.approx(200.0)
    assert not free.unsafe and free.reason is None
    assert clamped.unsafe
    assert clamped.reason.startswith("200 N > 140 N quasi-static limit (hands): clamped against the table 30 mm")


def test_the_force_of_a_robot_that_keeps_pushing_until_it_stands():
    # energy: 1/2 m_R v^2 = F^2 / (2 k) -> F = v sqrt(m_R k); 12 kg at 0.1 m/s on a hand: 0.1 sqrt(900000) = 94.9 N
    assert clamping_force(0.1, 12.0, HAND_K, 0.0) == pytest.approx(0.1 * math.sqrt(12.0 * HAND_K))
    # travel: 4 mm further towards the table compresses the hand by 4 mm: 75 N/mm x 4 mm = 300 N
    assert clamping_force(0.1, 12.0, HAND_K, 0.004) == pytest.approx(300.0)
    assert clamping_force(0.0, math.inf, HAND_K, 0.0) == 0.0
    assert clamping_force(0.1, math.inf, HAND_K, 0.002) == pytest.approx(150.0)  # the travel alone, finite
    crit = Iso15066()
    # the same slow robot (0.1 m/s along the normal, transient 19 N) clamping a hand with 4 mm still to go
    b = _backing("table", 0.05, 0.05, v_push=0.1, m_push=10.0, travel=0.004)
    v = crit.judge(_contact(v_rel=0.1, backing=b))
    assert v.force == pytest.approx(300.0) and v.unsafe and v.case == "clamping"
    free = crit.judge(_contact(v_rel=0.1, backing=None))
    assert free.force == pytest.approx(0.1 * math.sqrt(_mu(12.0) * HAND_K)) and not free.unsafe


def test_the_workers_own_speed_counts_in_v_rel():
    crit = Iso15066()
    # robot 0.3 m/s along the normal, the hand 1.0 m/s towards the robot: v_rel = 1.3 m/s; hand computation:
    # mu = 1 / (1/0.6 + 1/12) = 0.571429 kg; F = 1.3 sqrt(0.571429 * 75000) = 269.1 N
    v = crit.judge(_contact(v_rel=0.3, v_human=1.0))
    assert v.v_rel == pytest.approx(1.3) and v.v_human == 1.0
    assert v.force == pytest.approx(1.3 * math.sqrt(0.571429 * 75_000.0), rel=1e-6)
    assert v.force == pytest.approx(269.1, abs=0.1) and not v.unsafe
    # capped at ISO 13855's 2 m/s hand speed
    fast = crit.judge(_contact(v_rel=0.3, v_human=5.0))
    assert fast.v_human == HUMAN_SPEED_CAP == 2.0 and fast.v_rel == pytest.approx(2.3) and fast.unsafe
    # a robot at a standstill (v_R at the speed tolerance): the worker's speed does not count
    still = crit.judge(_contact(v_rel=0.0, v_r=0.001, v_human=1.5))
    assert still.v_human == 0.0 and still.force == 0.0 and not still.unsafe


def test_verdict_numbers_in_result_files_and_determinism():
    crit = Iso15066()
    b = _backing("table", 0.03, 0.05, v_push=0.1, m_push=10.0, travel=0.004)
    one = json.dumps(crit.judge(_contact(v_rel=0.1, v_human=0.2, backing=b)).as_dict(), sort_keys=True)
    two = json.dumps(crit.judge(_contact(v_rel=0.1, v_human=0.2, backing=b)).as_dict(), sort_keys=True)
    assert one == two
    doc = json.loads(one)
    assert doc["case"] == "clamping" and doc["surface"] == "table" and doc["limit_N"] == 140.0
    assert doc["gap_m"] == pytest.approx(-0.02) and doc["travel_m"] == 0.004 and doc["v_human"] == 0.2
    assert doc["why_case"].startswith("clamped against the table 30 mm behind the contact")
    free = crit.judge(_contact()).as_dict()
    assert free["case"] == "transient" and free["surface"] is None and free["why_case"].startswith("no fixed")
