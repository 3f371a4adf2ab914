from __future__ import annotations

import math

import numpy as np
import pytest

from cellstress.core.records import Measures
from cellstress.criteria.contact import ContactWhileMoving
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator


def test_predicate_and_tolerances():
    c = ContactWhileMoving()
    assert c.is_unsafe(0.0, 0.5)
    assert not c.is_unsafe(0.0, 0.0005)  # a standstill within the tolerance
    assert not c.is_unsafe(0.001, 2.0)  # not touching
    assert ContactWhileMoving(distance_tolerance=0.01).is_unsafe(0.005, 0.5)


def test_reward_matches_the_paper():
    c = ContactWhileMoving()
    assert c.safety_index(0.0, 0.0) == 1.0
    assert c.safety_index(1.0, 0.0) == 2.0
    assert c.safety_index(2.0, 1.0) == pytest.approx(5.0 / math.e)
    r = c.reward(8)
    assert r(Measures(2.0, 1.0), last_action=False, unsafe=False) == pytest.approx((math.e / 5.0, math.e / 5.0))
    assert r(Measures(2.0, 1.0), last_action=True, unsafe=False)[0] == pytest.approx(-5.0 / math.e)
    assert r(Measures(0.0, 1.0), last_action=True, unsafe=True)[0] == pytest.approx(math.e)


def test_simulator_flags_exactly_the_criterion():
    """Every row of random episodes: the kernel's unsafe flag equals the criterion on its d_HR and v_R."""
    sim = Simulator("s3-fence-gap")
    crit = sim.criterion
    rng = np.random.default_rng(3)
    flagged = 0
    for seq in rng.integers(0, 30, (300, 8)):
        rows = sim.run(seq).rows
        for r in rows:
            # the kernel compares the signed distance; a reported 0.0 may be an overlap, so check one way
            if r[L.M_UNSAFE]:
                flagged += 1
                assert crit.is_unsafe(r[L.M_D], r[L.M_V])
            elif r[L.M_D] > 0.0:
                assert not crit.is_unsafe(r[L.M_D], r[L.M_V])
            else:  # touching but not flagged: the robot must be standing still
                assert r[L.M_V] <= crit.speed_tolerance
    assert flagged > 0
