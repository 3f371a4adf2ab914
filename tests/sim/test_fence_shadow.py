"""``fences.shadow_bound``: how far a hand must go round the panels to reach any point of a robot capsule's axis.

``separation`` skips a (robot capsule, arm) pair whose bound, less the arm and the capsule's radius, is not
below the best distance found so far, so the bound must never exceed the length of the way round to any point
of the axis: checked here against the kernel's own detour (``fence_detour``, an actual path round the panels)
and against its per-point lower bound (``fence_detour_bound``) at 41 points of each axis, on random walls of
one to three runs with random panels beside them. That the skip changes no distance is checked on whole
episodes by ``test_separation`` (door-locked, where it skips most) and bit for bit by
``scripts/kernel_reference.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
from walls import every_panel_near, random_wall, sides

from cellstress.sim.kernels.fences import fence_detour_bound, shadow_bound


def _cell(rng):
    """A wall of one to three collinear runs (heights may differ) and up to two panels anywhere."""
    whole, split = random_wall(rng, int(rng.integers(1, 4)))
    split = split.copy()
    split[:, 5] = rng.choice([split[0, 5], rng.uniform(0.9, 2.4)], size=len(split))
    others = [[*rng.uniform(-2.5, 2.5, 4), 0.0, rng.uniform(0.8, 2.2)] for _ in range(int(rng.integers(0, 3)))]
    return whole, np.vstack([split, *others]) if others else split


@pytest.mark.parametrize("seed", range(4))
def test_the_shadow_is_never_longer_than_the_way_round_to_any_point_of_the_axis(seed):
    rng = np.random.default_rng(seed)
    shadowed = 0
    for _ in range(300):
        whole, fences = _cell(rng)
        s, a = sides(rng, whole)
        b = sides(rng, whole)[1]
        near, n = every_panel_near(fences)
        lb = shadow_bound(fences, near, n, *s, *a, *b)
        if lb <= 0.0:
            continue
        shadowed += 1
        for u in np.linspace(0.0, 1.0, 41):
            q = a + u * (b - a)
            d, around = fence_detour_bound(fences, near, n, *s, *q, np.inf)
            assert lb <= around + 1e-9, (seed, u, lb, around)
            assert lb <= d + 1e-9, (seed, u, lb, d)
    assert shadowed >= 60  # most draws put the whole axis behind the wall


def test_no_shadow_where_the_straight_way_is_open():
    fences = np.array([[0.0, -1.0, 0.0, 1.0, 0.0, 2.0]])
    near, n = every_panel_near(fences)
    # the axis runs past the panel's end: part of it is seen from the shoulder
    assert shadow_bound(fences, near, n, -0.5, 0.0, 1.4, 0.5, 0.5, 1.0, 0.5, 2.5, 1.0) == 0.0
    # the whole axis behind the panel: the hand goes over the top or round an end
    lb = shadow_bound(fences, near, n, -0.5, 0.0, 1.4, 0.5, -0.2, 1.0, 0.5, 0.2, 1.0)
    over_top = np.hypot(0.5, 0.6) + np.hypot(0.5, 1.0)
    round_end = np.hypot(0.5, 1.0) + np.hypot(0.5, 0.8)
    assert lb == pytest.approx(min(over_top, round_end))
