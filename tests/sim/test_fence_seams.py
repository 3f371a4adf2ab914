"""A wall built of several fence runs that meet end to end in a straight line is the same wall as one run.

The hand's way round a panel bends 1 cm past one of its ends; where another panel continues it in a straight
line, that bend point lies in the other panel (a seam, not an end), and the simulator once let the arm through
there: s3-fence-gap's missing metre put back as a panel of its own was reached through, while the same wall
drawn as one run was not. Cross-checked here three ways: the kernel's detour length and its lower bound
against the same wall unsplit, the bound against the length where the runs differ in height, and a whole
episode in the two cells.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from walls import every_panel_near, random_wall, sides

from cellstress.cell.load import builtin_file, parse_cell
from cellstress.sim.kernels.fences import fence_detour, fence_detour_bound
from cellstress.sim.simulator import Simulator


def _detour(fences, s, q):
    return fence_detour(fences, *every_panel_near(fences), *s, *q, np.inf)


def _detour_bound(fences, s, q):
    return fence_detour_bound(fences, *every_panel_near(fences), *s, *q, np.inf)


@pytest.mark.parametrize("seed", range(4))
def test_a_split_wall_is_as_long_a_way_round_as_the_whole(seed):
    """From a shoulder on one side to a point on the other: the same way round (over the top or round a true
    end) whether the wall is one panel or two to four collinear ones."""
    rng = np.random.default_rng(seed)
    checked = 0
    for _ in range(300):
        whole, split = random_wall(rng, int(rng.integers(2, 5)))
        s, q = sides(rng, whole)
        d_whole, d_split = _detour(whole, s, q), _detour(split, s, q)
        assert d_split == pytest.approx(d_whole, rel=1e-9, abs=1e-9), (whole, split, s, q)
        # the lower bound sees one wall too (a bound that went round the seam would be far below the length,
        # and the simulator's strides near the wall would shrink to the grid step)
        b_whole, b_split = _detour_bound(whole, s, q)[1], _detour_bound(split, s, q)[1]
        assert b_split == pytest.approx(b_whole, rel=1e-9, abs=1e-9), (whole, split, s, q)
        checked += d_whole > np.linalg.norm(s - q) + 1e-9  # the wall was in the way
    assert checked > 50


@pytest.mark.parametrize("seed", range(3))
def test_a_panel_lying_in_a_wall_changes_nothing(seed):
    """A second panel inside a wall's run (a closed door leaf drawn over its wall, a run drawn twice in part):
    the bends 1 cm past its ends lie in the wall, and the way round is the wall's alone."""
    rng = np.random.default_rng(200 + seed)
    checked = 0
    for _ in range(300):
        whole, _ = random_wall(rng, 2)
        x0, y0, x1, y1 = whole[0, :4]
        a, b = np.sort(rng.uniform(0.05, 0.95, 2))
        inner = [x0 + a * (x1 - x0), y0 + a * (y1 - y0), x0 + b * (x1 - x0), y0 + b * (y1 - y0)]
        if rng.random() < 0.5:
            inner = inner[2:] + inner[:2]
        both = np.array([whole[0], [*inner, whole[0, 4], whole[0, 5]]])
        s, q = sides(rng, whole)
        d_whole, d_both = _detour_bound(whole, s, q), _detour_bound(both, s, q)
        assert d_both[0] == pytest.approx(d_whole[0], rel=1e-9, abs=1e-9), (both, s, q)
        assert d_both[1] <= d_both[0] + 1e-9
        checked += d_whole[0] > np.linalg.norm(s - q) + 1e-9
    assert checked > 50


@pytest.mark.parametrize("seed", range(3))
def test_the_bound_stays_below_the_length_where_runs_differ_in_height(seed):
    """Collinear runs of different tops and bottoms (steps at the seams, raised panels): the detour's lower
    bound never exceeds its length, and a straight path through a step above the lower run is no detour."""
    rng = np.random.default_rng(100 + seed)
    stepped = 0
    for _ in range(400):
        whole, split = random_wall(rng, int(rng.integers(2, 5)))
        split[:, 4] = rng.choice([0.0, 0.0, 0.2, 0.4], len(split))
        split[:, 5] = rng.uniform(0.9, 2.2, len(split))
        s, q = sides(rng, whole)
        d, lb = _detour_bound(split, s, q)
        assert lb <= d + 1e-9, (split, s, q)
        assert lb >= np.linalg.norm(s - q) - 1e-9
        stepped += d > np.linalg.norm(s - q) + 1e-9
    assert stepped > 50


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


def _with_midpoints(text: str) -> str:
    """The cell's YAML with a point added in the middle of every fence panel (each wall as collinear runs)."""
    data = yaml.safe_load(text)
    for fence in data["fences"]:
        pts = fence["points"]
        fence["points"] = [pts[0]] + [
            p for a, b in zip(pts, pts[1:], strict=False) for p in ([(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0], b)
        ]
    return yaml.safe_dump(data, sort_keys=False)


@pytest.mark.parametrize("cell", ["s3-fence-gap", "door-locked"])
def test_walls_drawn_as_collinear_runs_change_no_episode(cell):
    """Every fence panel split in two at its middle: 300 random episodes end at the same step with the same
    distances (benchmarks/fence_seams.py measures the speed of the same pair)."""
    text = Path(builtin_file(cell)).read_text()
    where = Path(builtin_file(cell)).parent
    one, split = (Simulator(parse_cell(t, cell, where)) for t in (text, _with_midpoints(text)))
    assert len(split.params.fences) > len(one.params.fences)
    acts = np.random.default_rng(3).integers(0, one.n_actions, size=(300, one.actions_per_episode))
    a, b = one.run_batch(acts), split.run_batch(acts)
    np.testing.assert_array_equal(a.unsafe_step, b.unsafe_step)
    np.testing.assert_allclose(a.d_end, b.d_end, atol=1e-9)
    np.testing.assert_allclose(a.min_d, b.min_d, atol=1e-9)


def test_a_wall_drawn_three_ways_is_one_wall():
    """door-locked's back wall without its door device: the bay closed by a panel between the two runs (two
    seams), the wall as one run with that panel lying in it, and the wall as one run alone give the same 300
    random episodes (the old rule let the arm through the first two in nearly every episode)."""
    text = Path(builtin_file("door-locked")).read_text()
    door = text[text.index("  - type: guard-door") : text.index("human:")]
    left, right = (
        "  - {points: [[-1.5, 3.2], [-1.5, -1.6], [-0.6, -1.6]], top: 2.0}",
        "  - {points: [[1.5, 3.2], [1.5, -1.6], [0.6, -1.6]], top: 2.0}",
    )
    panel = "  - {points: [[-0.6, -1.6], [0.6, -1.6]], top: 2.0}\n"
    seams = text.replace(door, "").replace("devices:\n", "devices: []\n").replace("fences:\n", "fences:\n" + panel, 1)
    overlap = seams.replace(left, left.replace("[-0.6, -1.6]", "[1.5, -1.6]")).replace(
        right, "  - {points: [[1.5, 3.2], [1.5, -1.6]], top: 2.0}"
    )
    single = overlap.replace(panel, "", 1)
    assert len({seams, overlap, single}) == 3
    sims = [Simulator(parse_cell(t, "door-locked (walls)", None)) for t in (seams, overlap, single)]
    acts = np.random.default_rng(5).integers(0, sims[0].n_actions, size=(300, sims[0].actions_per_episode))
    runs = [s.run_batch(acts) for s in sims]
    for r in runs[:2]:
        np.testing.assert_allclose(r.min_d, runs[2].min_d, atol=1e-9)
        np.testing.assert_allclose(r.d_end, runs[2].d_end, atol=1e-9)
