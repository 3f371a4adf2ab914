"""The capsules swept over a program's cycle (analysis.program_sweep): the speed bound the sampling is spaced by
holds against finite differences of the kernel's poses, the samples are spaced by it, a long fast program is
sampled within the work bound, and the compiled grid poses as the kernel does one pose at a time."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from cellstress.analysis import program_sweep
from cellstress.analysis.program_check import check_program
from cellstress.analysis.program_sweep import (
    DEPTH,
    MAX_POINTS,
    capsule_axes,
    capsule_grid,
    point_speed_bounds,
    sample_grids,
    sample_spacing,
    sample_times,
)
from cellstress.cell.load import builtin_text, load_cell, parse_cell
from cellstress.sim.build import build_layout


def _layout(data: dict, name: str):
    return build_layout(parse_cell(yaml.safe_dump(data), name, None))


def baseline_with(waypoints_deg) -> dict:
    data = yaml.safe_load(builtin_text("baseline"))
    data["robot"]["task"]["waypoints_deg"] = waypoints_deg
    return data


@pytest.fixture(scope="module")
def swing():
    """The baseline's UR10 with its shoulder turned 382 deg: the arm swings down through the table."""
    layout = _layout(baseline_with([[124.8, -44.8, 78.4, -123.6, -90.0, 0.0],
                                    [124.8, 337.2, 78.4, -123.6, -90.0, 0.0]]), "swing")
    return layout, check_program(layout, 0)


@pytest.mark.parametrize("cell", ["baseline", "palletizing", "swing"])
def test_the_speed_bound_holds(cell, swing):
    """No capsule axis end moves faster than the bound the sampling is spaced by: finite differences of the
    kernel's poses every 0.5 ms along every move."""
    layout = swing[0] if cell == "swing" else build_layout(load_cell(cell))
    part = layout.robots[0]
    bounds = point_speed_bounds(part)
    traj = part.trajectory
    for i in range(traj.n_segments)[:40]:  # (a trajectory file: its first 40 rows)
        begin = traj.starts[i] + traj.dwells[i]
        taus = begin + np.arange(0.0, traj.move_times[i], 5e-4)
        a, b = capsule_axes(layout, 0, taus)
        moving = [c for c, cap in enumerate(part.capsules) if cap.joint >= 0]
        speed = max(np.linalg.norm(np.diff(e[:, moving], axis=0), axis=-1).max() / 5e-4 for e in (a, b))
        assert speed <= bounds[i] * (1 + 1e-6)
        assert speed >= 0.2 * bounds[i]  # (a bound, not a wild one)


def test_samples_are_spaced_by_the_bound(swing):
    layout, p = swing
    part = layout.robots[0]
    bounds = point_speed_bounds(part)
    traj = part.trajectory
    grids = sample_grids(traj, bounds)
    assert len(grids) == traj.n_segments and p.spacing == DEPTH
    for i, (t0, dt, n) in enumerate(grids):
        assert t0 == pytest.approx(traj.starts[i] + traj.dwells[i])
        assert t0 + (n - 1) * dt == pytest.approx(t0 + traj.move_times[i])  # the move's end
        assert dt * bounds[i] <= DEPTH * (1 + 1e-9)
    taus, moves = sample_times(traj, bounds)
    assert set(moves.tolist()) == set(range(traj.n_segments))
    # a trajectory file is one even stretch over its cycle
    pallet = build_layout(load_cell("palletizing")).robots[0]
    ((t0, dt, n),) = sample_grids(pallet.trajectory, point_speed_bounds(pallet))
    assert t0 == 0.0 and (n - 1) * dt == pytest.approx(pallet.trajectory.cycle)


def test_a_long_fast_program_is_sampled_within_bounds(monkeypatch):
    """256 full-speed moves (a 391 s cycle, some 30 million axis points at 10 mm): under a cap of 2 million the
    spacing widens until at most that many are measured, and the header says what spacing was used."""
    data = baseline_with([[124.8 - 87.7 * (i % 2), -44.8, 78.4, -123.6, -90.0, 0.0] for i in range(256)])
    data["robot"]["task"]["speed_scale"] = 1.0
    layout = _layout(data, "long")
    part = layout.robots[0]
    bounds = point_speed_bounds(part)
    lengths = np.asarray([np.linalg.norm(np.subtract(c.p1, c.p0)) for c in part.capsules if c.joint >= 0])

    def points(step):
        return sum(n for _, _, n in sample_grids(part.trajectory, bounds, step)) * np.sum(np.ceil(lengths / step) + 1)

    assert sample_spacing(part, bounds) == DEPTH and points(DEPTH) <= MAX_POINTS
    monkeypatch.setattr(program_sweep, "MAX_POINTS", 2_000_000)
    step = sample_spacing(part, bounds)
    assert step > DEPTH and points(step) <= 2_000_000 < points(step / 1.05)
    p = check_program(layout, 0)
    assert p.spacing == step and f"at least every {step * 1000:.0f} mm of capsule travel" in p.lines()[0]


def test_the_compiled_grid_poses_as_the_kernel_does_one_by_one():
    layout = build_layout(load_cell("two-robots"))
    for r in (0, 1):
        a, b = capsule_grid(layout, r, 0.35, 0.01, 7)
        a1, b1 = capsule_axes(layout, r, 0.35 + 0.01 * np.arange(7))
        np.testing.assert_allclose(a, a1, atol=1e-12)
        np.testing.assert_allclose(b, b1, atol=1e-12)


