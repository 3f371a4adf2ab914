"""The pure helpers of benchmarks/iso13857.py: the exact reach of a capsule at a height, and the agreement rule."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

_PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "iso13857.py"
_SPEC = importlib.util.spec_from_file_location("iso13857_bench", _PATH)
bench = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(bench)


def brute_section(a, b, r, h, n=20001):
    """max -y over the capsule's section at z = h, from a fine sampling of the axis (disc radius per point)."""
    t = np.linspace(0.0, 1.0, n)
    s = a + t[:, None] * (b - a)
    u = s[:, 2] - h
    ok = np.abs(u) <= r
    if not ok.any():
        return -np.inf
    return float((-s[ok, 1] + np.sqrt(r * r - u[ok] ** 2)).max())


def test_section_reach_matches_fine_sampling():
    rng = np.random.default_rng(7)
    a = rng.uniform(-1.0, 1.0, (300, 3))
    b = rng.uniform(-1.0, 1.0, (300, 3))
    r = rng.uniform(0.02, 0.2, 300)
    heights = np.array([-0.5, 0.0, 0.3, 0.9])
    got = bench.section_reach(a, b, r, heights)
    assert got.shape == (300, 4)
    for i in range(300):
        for k, h in enumerate(heights):
            want = brute_section(a[i], b[i], r[i], h)
            spans = min(a[i, 2], b[i, 2]) - r[i] <= h <= max(a[i, 2], b[i, 2]) + r[i]
            assert np.isfinite(got[i, k]) == spans
            if np.isfinite(want):
                assert got[i, k] == pytest.approx(want, abs=2e-4)
                assert got[i, k] >= want - 1e-12  # exact: never below a sampled point


def test_section_reach_special_cases():
    # a level capsule at the height: its far end plus the radius
    v = bench.section_reach(np.array([0.0, 0.0, 1.0]), np.array([0.0, -0.5, 1.0]), np.array(0.05), np.array([1.0]))
    assert v[0] == pytest.approx(0.55)
    # a vertical capsule: the radius beyond its axis wherever it spans the height, nothing above its end cap
    v = bench.section_reach(np.array([0.0, -0.3, 0.0]), np.array([0.0, -0.3, 1.0]), np.array(0.1),
                            np.array([0.5, 1.05, 1.2]))
    assert v[0] == pytest.approx(0.4)
    assert v[1] == pytest.approx(0.3 + np.sqrt(0.1 ** 2 - 0.05 ** 2))
    assert v[2] == -np.inf


def test_depth_reach_is_the_deepest_surface_point():
    d = bench.depth_reach(np.array([[0.0, 0.2, 1.0]]), np.array([[0.0, -0.4, 1.5]]), np.array([0.03]))
    assert d[0] == pytest.approx(0.43)


def test_guide_equals_exact_for_a_level_capsule_at_the_height():
    a, b, r = np.array([[0.0, 0.1, 1.2]]), np.array([[0.0, -0.6, 1.2]]), np.array([0.04])
    g = bench.guide_reach(a, b, r, np.array([1.2, 1.5]))
    assert g[0, 0] == pytest.approx(0.64)
    assert g[0, 1] == pytest.approx(0.6 - (0.3 - 0.04))  # a height miss costs LAMBDA = 1 m per m


@pytest.mark.parametrize(("c_iso", "c_sim", "verdict"), [
    (0, 0, "agree"), (0, 100, "agree"), (0, 101, "beyond"), (800, 700, "agree"), (800, 699, "short"),
    (800, 900, "agree"), (800, 901, "beyond"), (1500, 0, "short")])
def test_agreement_is_within_one_step(c_iso, c_sim, verdict):
    assert bench.agreement(c_iso, c_sim) == verdict


def test_crossings_free_over_the_top_only():
    free = bench.Objective(np.array([1.0]), top=1.4).free
    # a point going from in front (y > 0) to behind at z 1.5 crosses above the top (1.4 + r)
    assert bench.crossings_free(0.1, 1.5, 0.0, -0.1, 1.5, 0.0, 0.05, free)
    # the same at z 1.2 goes through the panel; at 1.43 it grazes the edge within the radius
    assert not bench.crossings_free(0.1, 1.2, 0.0, -0.1, 1.2, 0.0, 0.05, free)
    assert not bench.crossings_free(0.1, 1.43, 0.0, -0.1, 1.43, 0.0, 0.05, free)
    # the crossing height is interpolated: from (0.3, 1.0) to (-0.1, 1.8) it crosses at 1.6
    assert bench.crossings_free(0.3, 1.0, 0.0, -0.1, 1.8, 0.0, 0.05, free)
    # no crossing: always fine
    assert bench.crossings_free(0.3, 0.2, 0.0, 0.1, 0.2, 0.0, 0.05, free)


def test_crossings_free_through_an_opening():
    square = bench.Objective(None, centre=(0.0, 1.5), e=0.12)
    slot = bench.Objective(None, centre=(0.0, 1.5), slot=True, e=0.12)
    assert square.free(np.array(0.0), np.array(1.5), 0.05)
    assert not square.free(np.array(0.02), np.array(1.5), 0.05)  # 0.01 m to spare only
    assert slot.free(np.array(2.0), np.array(1.5), 0.05)  # a slot runs the whole width
    assert not slot.free(np.array(0.0), np.array(1.52), 0.05)


@pytest.mark.parametrize(("e", "limb"), [(0.04, "none"), (0.05, "none"), (0.06, "hand"), (0.09, "forearm"),
                                         (0.12, "upper arm")])
def test_fits_names_the_thickest_limb_through(e, limb):
    assert bench.fits(e) == limb


def test_reach_over_cell_walks_up_to_the_fence_and_a_witness_replays():
    """The benchmark's cell: five walking actions end exactly at the closest the feet get (0.2 m); a reach over
    the 1.4 m panel (arms up, bend over it) gets the hand beyond the face, and the search's exact value is the
    one the witness gives again."""
    sim = bench.reach_over_sim(1.4, "p95-male", 55.0, 4)
    walk = np.array([[sim.action_index("walk+upright")] * 5])
    assert sim.worker_paths(walk)[0, -1, 1] == pytest.approx(0.2, abs=1e-5)
    obj = bench.Objective(np.array([1.4]), top=1.4)
    seq = ("walk+reach-high", "walk+upright", "walk+tiptoe", "walk+bend-forward", "stand+reach-forward")
    c = bench.replay_value(sim, obj, seq, 0)
    assert 0.5 < c < 0.95  # 0.68 m when written: the panel stops the bend at about 14 degrees
    acts = np.array([[sim.action_index(s) for s in seq]])
    a, b, r = sim.worker_capsules(sim.worker_paths(acts)[0])
    assert obj.exact(a[None], b[None], r[None])[0, 0] == c
    assert obj.swept_ok(a[None], b[None], r[None])[0]  # a motion a body can make: nothing through the panel
