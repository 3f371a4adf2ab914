"""A wall built of several fence runs that meet end to end in a straight line is the same wall as one run.

The hand's way round a panel bends 1 cm past one of its ends; where another panel continues it in a straight
line, that bend point lies in the other panel (a seam, not an end), and the simulator once let the arm through
there: s3-fence-gap's missing metre put back as a panel of its own was reached through, while the same wall
drawn as one run was not. Cross-checked here two ways: the kernel's detour length against the same wall
unsplit, and a whole episode in the two cells.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cellstress.cell.load import builtin_file, parse_cell
from cellstress.sim.kernels.fences import fence_detour
from cellstress.sim.simulator import Simulator


def _wall(rng, pieces: int) -> tuple[np.ndarray, np.ndarray]:
    """A random straight wall as one panel and as ``pieces`` collinear panels meeting end to end."""
    a = rng.uniform(-2.0, 2.0, 2)
    ang = rng.uniform(0.0, 2 * np.pi)
    length = rng.uniform(0.5, 3.0)
    u = np.array([np.cos(ang), np.sin(ang)])
    bottom, top = rng.choice([0.0, 0.0, 0.3]), rng.uniform(1.0, 2.4)
    cuts = np.sort(rng.uniform(0.1, 0.9, pieces - 1))
    ts = np.concatenate(([0.0], cuts, [1.0]))
    pts = [a + t * length * u for t in ts]
    whole = np.array([[*pts[0], *pts[-1], bottom, top]])
    split = np.array([[*p, *q, bottom, top] for p, q in zip(pts, pts[1:], strict=False)])
    return whole, split


def _detour(fences, s, q):
    near = np.arange(len(fences), dtype=np.int64)
    return fence_detour(fences, near, np.int64(len(fences)), *s, *q, np.inf)


@pytest.mark.parametrize("seed", range(4))
def test_a_split_wall_is_as_long_a_way_round_as_the_whole(seed):
    """From a shoulder on one side to a point on the other: the same way round (over the top or round a true
    end) whether the wall is one panel or two to four collinear ones."""
    rng = np.random.default_rng(seed)
    checked = 0
    for _ in range(300):
        whole, split = _wall(rng, int(rng.integers(2, 5)))
        x0, y0, x1, y1 = whole[0, :4]
        u = np.array([x1 - x0, y1 - y0])
        n = np.array([-u[1], u[0]]) / np.linalg.norm(u)
        along = np.array([x0, y0]) + rng.uniform(-0.2, 1.2) * u
        s = np.array([*(along + rng.uniform(0.05, 0.6) * n), rng.uniform(0.8, 1.7)])
        q = np.array([*(along + rng.uniform(-0.3, 0.3) * u - rng.uniform(0.05, 0.8) * n), rng.uniform(0.3, 1.8)])
        d_whole, d_split = _detour(whole, s, q), _detour(split, s, q)
        assert d_split == pytest.approx(d_whole, rel=1e-9, abs=1e-9), (whole, split, s, q)
        checked += d_whole > np.linalg.norm(s - q) + 1e-9  # the wall was in the way
    assert checked > 50


def test_a_corner_is_still_a_way_round():
    """Two panels meeting at a right angle: the hand still goes round the outside of the corner (the bend 1 cm
    past one panel's end is 1 cm off the other, no seam)."""
    fences = np.array([[0.0, 0.0, 1.0, 0.0, 0.0, 2.0], [1.0, 0.0, 1.0, -1.0, 0.0, 2.0]])
    s, q = np.array([0.5, 0.3, 1.2]), np.array([1.3, -0.5, 1.2])  # outside both, the straight line cuts the corner
    d = _detour(fences, s, q)
    corner = np.array([1.0, 0.0, 1.2])
    assert np.linalg.norm(s - q) < d <= np.linalg.norm(s - corner) + np.linalg.norm(corner - q) + 0.03


def test_the_gap_closed_by_a_panel_of_its_own_is_the_gap_closed_by_the_wall(tmp_path):
    """s3-fence-gap with its missing metre put back as a third run, and with its right wall drawn as one run:
    the same episode (the one the simulator once reached through the seam) gives the same distances."""
    text = Path(builtin_file("s3-fence-gap")).read_text()
    assert text.count("[[1.5, 3.2], [1.5, 0.8]]") == 1
    panel = text.replace("fences:\n", "fences:\n  - {points: [[1.5, 0.8], [1.5, -0.2]], top: 2.0}\n", 1)
    wall = text.replace("[[1.5, 3.2], [1.5, 0.8]]", "[[1.5, 3.2], [1.5, -0.2]]")
    actions = ["walk+upright"] * 3 + ["walk+bend-forward", "turn-left-45+bend-forward-left", "walk+bend-left"]
    rows = []
    for name, body in (("panel", panel), ("wall", wall)):
        path = tmp_path / f"{name}.yaml"
        path.write_text(body)
        trace = Simulator(parse_cell(body, str(path), tmp_path)).run(actions)
        rows.append(trace.records())
    d_panel = np.array([r.d_HR for r in rows[0]])
    d_wall = np.array([r.d_HR for r in rows[1]])
    np.testing.assert_allclose(d_panel, d_wall, atol=1e-9)
    assert d_wall.min() > 0.5  # the wall holds the arm back: no contact through it
