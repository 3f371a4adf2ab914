"""human/reach_bound.py: the generous reach bound against hand cases and an independent sampling."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cellstress.human import reach_bound as bound

BODY = bound.body_bound("p95-male", 180.0, 0.08)


def test_the_body_is_the_worker_s():
    assert BODY.trunk == pytest.approx(math.hypot((0.818 - 0.530) * 1.855, 0.259 * 1.855 / 2 - 0.05))
    assert BODY.arm == pytest.approx(0.395 + 0.146 * 1.855 + 0.108 * 1.855 + 0.025)
    assert BODY.hip_high == pytest.approx(0.530 * 1.855 + 0.08)
    assert BODY.top == pytest.approx(BODY.hip_high + BODY.trunk + BODY.arm)


def test_above_the_top_nothing_is_reached_exactly():
    assert BODY.top < 2.6
    assert bound.c_bound(BODY, 2.6, 1.0) == (0.0, True)
    c, exact = bound.c_bound(BODY, BODY.top - 0.01, 2.7)
    assert not exact and c == 0.0  # straight up, but a 2.7 m wall stands in front


def test_over_an_edge_below_the_hip_the_body_lies_flat():
    # hip put at the rail's height, trunk and arm horizontal beyond it: the whole length
    c, exact = bound.c_bound(BODY, 1.0, 1.0)
    assert not exact
    assert c == pytest.approx(BODY.trunk + BODY.arm, abs=0.002)


def _blocked(p, q, b):
    """Does the segment p-q pass through the panel x = 0, 0 <= z <= b?"""
    if (p[0] > 0.0) == (q[0] > 0.0) or p[0] == q[0]:
        return False
    t = -p[0] / (q[0] - p[0])
    return p[1] + t * (q[1] - p[1]) < b


def _sampled_reach(a, b, n, rng):
    """The same body, posed at random, the arm taken straight or over the edge, checked segment by segment."""
    best = 0.0
    for _ in range(n):
        hip = rng.uniform(BODY.hip_low, BODY.hip_high)
        xh = -rng.uniform(0.0, 0.6) * rng.choice([0.0, 1.0], p=[0.3, 0.7])
        f = rng.uniform(0.0, math.pi) * rng.choice([0.0, 1.0], p=[0.2, 0.8])  # upright is often best
        s = (xh + BODY.trunk * math.sin(f), hip + BODY.trunk * math.cos(f))
        if _blocked((xh, hip), s, b) or (xh == 0.0 and s[0] > 0.0 and hip < b):
            continue
        dz = a - s[1]
        if abs(dz) <= BODY.arm:
            p = (s[0] + math.sqrt(BODY.arm ** 2 - dz ** 2), a)
            if p[0] > best and not _blocked(s, p, b):
                best = p[0]
        if s[0] <= 0.0:
            rest = BODY.arm - math.hypot(s[0], s[1] - b)
            if rest >= abs(a - b):
                best = max(best, math.sqrt(rest ** 2 - (a - b) ** 2))
    return best


@pytest.mark.parametrize("a,b", [(1.4, 1.0), (2.0, 1.4), (1.0, 1.6), (2.2, 2.0), (0.4, 1.2)])
def test_an_independent_sampling_never_beats_the_bound_and_nearly_meets_it(a, b):
    c, _ = bound.c_bound(BODY, a, b)
    sampled = _sampled_reach(a, b, 40000, np.random.default_rng(3))
    assert sampled <= c + 0.002  # the refined grid approaches the model's supremum from below, within mm
    assert sampled >= c - 0.03
