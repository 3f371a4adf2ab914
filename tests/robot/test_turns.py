"""Whole turns of a joint over a cyclic program (robot.turns): the least largest move against every assignment of
turns enumerated by brute force, and the unwound values attaining it."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from cellstress.robot.turns import TURN, candidates, least_largest_move, unwound


def brute_force(values: np.ndarray, lo: float, hi: float) -> float:
    """The least largest cyclic move over every choice of whole turns (within [lo, hi]; without limits, within
    three turns of the first value, which holds an optimum: shifting every value by one turn changes no move)."""
    per = []
    for i, v in enumerate(values):
        if math.isfinite(lo):
            ks = [k for k in range(-4, 5) if lo - 1e-9 <= v + k * TURN <= hi + 1e-9]
        else:
            ks = [k for k in range(-8, 9) if abs(v + k * TURN - values[0]) <= 3 * TURN] if i else [0]
        per.append([v + k * TURN for k in ks])
    best = math.inf
    for combo in itertools.product(*per):
        c = np.asarray(combo)
        best = min(best, float(np.max(np.abs(np.roll(c, -1) - c))))
    return best


def largest_move(values: np.ndarray) -> float:
    return float(np.max(np.abs(np.roll(values, -1) - values)))


def test_three_stations_around_the_base_must_turn_back_once():
    """67, 180 and 293 deg: the cycle turns back 226 deg somewhere whatever the turns (gaps 113, 113, 134)."""
    values = np.deg2rad([67.0, 180.0, 293.0])
    assert math.degrees(least_largest_move(values, -TURN, TURN)) == pytest.approx(226.0)
    assert math.degrees(largest_move(unwound(values, -TURN, TURN, 0.0))) == pytest.approx(226.0)


def test_a_needless_turn_is_taken_back():
    """The issue's shoulder: -90 then 292 deg (382 deg on the way) is -68 deg, 22 deg from -90."""
    values = np.deg2rad([-90.0, 292.0])
    assert math.degrees(least_largest_move(values, -TURN, TURN)) == pytest.approx(22.0)
    out = unwound(values, -TURN, TURN, values[0])
    np.testing.assert_allclose(np.rad2deg(out), [-90.0, -68.0])


def test_a_joint_whose_range_leaves_no_other_way_keeps_its_values():
    values = np.deg2rad([-160.0, 160.0])  # a Panda joint of +-166 deg: 320 deg is the only way
    assert math.degrees(least_largest_move(values, math.radians(-166), math.radians(166))) == pytest.approx(320.0)
    np.testing.assert_array_equal(unwound(values, math.radians(-166), math.radians(166), 0.0), values)


@pytest.mark.parametrize("limits", [(-TURN, TURN), (-1.5 * TURN, 0.8 * TURN), (-math.inf, math.inf)])
def test_least_largest_move_matches_brute_force(limits):
    lo, hi = limits
    rng = np.random.default_rng(11)
    for _ in range(60):
        n = int(rng.integers(2, 6))
        if math.isfinite(lo):
            values = rng.uniform(lo, hi, n)
        else:
            values = rng.uniform(-3 * TURN, 3 * TURN, n)
        want = brute_force(values, lo, hi)
        assert least_largest_move(values, lo, hi) == pytest.approx(want, abs=1e-9)
        out = unwound(values, lo, hi, float(values[0]))
        assert largest_move(out) == pytest.approx(want, abs=1e-9)
        # the same angles, each within the limits
        np.testing.assert_allclose(np.mod(out - values + 0.5, TURN) - 0.5, 0.0, atol=1e-9)
        assert np.all(out >= lo - 1e-9) and np.all(out <= hi + 1e-9)


def test_candidates_stay_within_the_limits():
    for c in candidates(np.deg2rad([0.0, 350.0, -359.0]), -TURN, TURN):
        assert np.all(np.abs(c) <= TURN + 1e-9)
    assert [len(c) for c in candidates(np.deg2rad([10.0, -10.0]), -TURN, TURN)] == [2, 2]
