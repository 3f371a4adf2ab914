"""The brute-force probe behind S2's curtain that docs/cells.md quotes (scripts/curtain_probe.py)."""

from __future__ import annotations

import pytest

from cellstress.analysis.probe import probe


@pytest.mark.slow
def test_no_worker_standing_behind_the_s2_curtain_is_reached():
    r = probe("s2-elbow-intrusion", 0.05)
    assert (r["poses"], r["unseen"], r["robot_poses"]) == (14400, 4500, 250)
    # the figure docs/cells.md gives: the robot stays 0.262 m outside the reach of every unseen standing pose
    assert r["d"] == pytest.approx(0.262, abs=0.0005)
    assert (r["x"], r["y"], r["heading_deg"], r["link"]) == (0.15, -1.95, 120, "upper_arm_link")
