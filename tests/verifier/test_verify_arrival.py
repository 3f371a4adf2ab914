"""Every arrival moment (verifier.arrival): the capsule margins hold every capsule position of the half step
around a grid phase, and the arrival-window model is unsafe wherever the model is at an arrival moment between
grid points; cells whose devices read the robot's clock are covered at the grid only, and say so."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cellstress.sim import layout as L
from cellstress.sim.scene import robot_capsules
from cellstress.sim.simulator import Simulator
from cellstress.verifier.arrival import arrival_cover, capsule_margins, clock_dependence, inflated
from cellstress.verifier.phases import start_points

CELLS = Path(__file__).parent / "cells"


def _cell(name: str) -> str:
    path = CELLS / f"{name}.yaml"
    return str(path) if path.exists() else name


@pytest.mark.parametrize("cell", ["baseline", "two-robots", "linear-axis"])
def test_margins_hold_every_capsule_position_of_the_window(cell) -> None:
    sim = Simulator(_cell(cell))
    lay = sim.layout
    half = 0.5 * sim.dt
    margins = capsule_margins(lay, half) - float(lay.params.scal[L.C_REACH_H])
    rng = np.random.default_rng(5)
    tau0 = float(lay.params.scal[L.C_PHASE0])
    worst = np.zeros(len(lay.capsules))
    for tau in rng.uniform(0.0, float(lay.trajectory.cycle), 300):
        a0, b0 = robot_capsules(lay, tau0 + tau)
        for delta in rng.uniform(-half, half, 4):  # off the sampling grid, both directions
            a1, b1 = robot_capsules(lay, tau0 + tau + delta)
            moved = np.maximum(np.linalg.norm(a1 - a0, axis=1), np.linalg.norm(b1 - b0, axis=1))
            worst = np.maximum(worst, moved)
    assert np.all(worst <= margins + 1e-12)
    moving = worst > 0.01
    assert moving.any() and np.all(margins[moving] < 3.0 * worst[moving] + 0.01)  # and not uselessly loose


@pytest.mark.parametrize("cell", ["s1-scanner-width", "s3-fence-gap", "restart-auto", "warning-field-short",
                                  "door-unlocked", "two-robots", "restart-fast", "warning-trunk", "linear-axis"])
def test_the_window_model_is_unsafe_wherever_an_arrival_between_grid_points_is(cell) -> None:
    base = Simulator(_cell(cell))
    cover = arrival_cover(base, base.contacts is not None)
    assert cover.covered, cover.reason
    wide = Simulator(inflated(base.layout, cover))
    start = start_points(base.cell)[0].pose
    rng = np.random.default_rng(3)
    dt = base.dt
    cycle = float(base.layout.trajectory.cycle)
    hazards = 0
    for _ in range(12):
        grid = float(rng.integers(0, int(cycle / dt))) * dt
        real_sims = [base.with_start(start, grid + d) for d in rng.uniform(-0.5 * dt, 0.5 * dt, 3)]
        wide_sim = wide.with_start(start, grid)
        acts = rng.integers(0, 30, size=(300, base.actions_per_episode))
        flagged = wide_sim.run_batch(acts).unsafe_step
        for sim in real_sims:
            real = sim.run_batch(acts).unsafe_step
            hit = real >= 0
            hazards += int(hit.sum())
            # unsafe in the window model too, and no later than the real step (it is unsafe wherever the real is)
            assert np.all(flagged[hit] >= 0) and np.all(flagged[hit] <= real[hit]), cell
    if cell not in ("door-unlocked", "restart-auto"):  # (their hazards need more than random actions find)
        assert hazards > 0


def test_clock_reading_cells_are_covered_at_the_grid_only() -> None:
    for cell, words in (("ssm-latency", "separation"), ("muting-long", "muted"), ("palletizing", "timed panel")):
        sim = Simulator(cell)
        assert words in (clock_dependence(sim.layout) or ""), cell
        assert not arrival_cover(sim, False).covered
    assert clock_dependence(Simulator("baseline").layout) is None
