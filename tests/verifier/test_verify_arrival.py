"""Every arrival moment (verifier.arrival): the capsule margins hold every capsule position of the half step
around a grid phase, and the arrival-window model is unsafe wherever the model is at an arrival moment between
grid points; cells whose devices read the robot's clock are covered at the grid only, and say so."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import cellstress
from cellstress.sim import layout as L
from cellstress.sim.kernels.dense import dense_batch
from cellstress.sim.scene import robot_capsules
from cellstress.sim.simulator import Simulator
from cellstress.sim.starts import parse_phase
from cellstress.verifier.arrival import REACH_LIPSCHITZ, arrival_cover, capsule_margins, clock_dependence, inflated
from cellstress.verifier.phases import start_points
from cellstress.verifier.records import UNSAFE

CELLS = Path(__file__).parent / "cells"


def _cell(name: str) -> str:
    path = CELLS / f"{name}.yaml"
    return str(path) if path.exists() else name


@pytest.mark.parametrize("cell", ["baseline", "two-robots", "linear-axis"])
def test_margins_hold_every_capsule_position_of_the_window(cell) -> None:
    sim = Simulator(_cell(cell))
    lay = sim.layout
    half = 0.5 * sim.dt
    margins = (capsule_margins(lay, half) - float(lay.params.scal[L.C_REACH_H])) / REACH_LIPSCHITZ
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


# (cell, whether random actions find its hazards: the property is checked on every cell, and is not vacuous)
WINDOW_CELLS = [("s1-scanner-width", True), ("s3-fence-gap", True), ("restart-auto", False),
                ("warning-field-short", False), ("door-unlocked", False), ("two-robots", False), ("two-near", True),
                ("restart-fast", True), ("warning-trunk", True), ("linear-axis", True),
                ("reach-near", True)]  # (the articulated worker: its body capsules against the grown capsules)


@pytest.mark.parametrize(("cell", "random_finds"), WINDOW_CELLS)
def test_the_window_model_is_unsafe_wherever_an_arrival_between_grid_points_is(cell, random_finds) -> None:
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
        # (the articulated worker's 119 actions hit reach-near's arm about once in 2,000 episodes)
        acts = rng.integers(0, base.n_actions, size=(300 if base.n_actions == 30 else 3000, base.actions_per_episode))
        flagged = wide_sim.run_batch(acts).unsafe_step
        for sim in real_sims:
            real = sim.run_batch(acts).unsafe_step
            hit = real >= 0
            hazards += int(hit.sum())
            # unsafe in the window model too, and no later than the real step (it is unsafe wherever the real is)
            assert np.all(flagged[hit] >= 0) and np.all(flagged[hit] <= real[hit]), cell
    assert hazards > 0 or not random_finds


def test_clock_reading_cells_are_covered_at_the_grid_only() -> None:
    for cell, words in (("ssm-latency", "separation"), ("muting-long", "muted")):
        sim = Simulator(cell)
        assert words in (clock_dependence(sim.layout) or ""), cell
        assert not arrival_cover(sim, False).covered
    # muting-long's pallet is a timed panel: without the muting it still reads the clock
    lay = Simulator("muting-long").layout
    assert lay.params.panel_fence.shape[0] > 0
    unmuted = dataclasses.replace(lay, params=lay.params._replace(dev_muted=np.full_like(lay.params.dev_muted, np.inf)))
    assert "timed panel" in (clock_dependence(unmuted) or "")
    assert clock_dependence(Simulator("baseline").layout) is None
    assert "criterion" in arrival_cover(Simulator("baseline"), True).reason


def test_a_hazard_only_between_grid_moments_is_not_proved_safe(tmp_path) -> None:
    # pass-by: at the grid arrivals the arm touches the worker only at moments strictly between the 50 ms samples.
    # Sampled, the grid alone proved it safe; with contact in continuous time (kernels.sweep) the grid arrivals
    # already touch it between their samples, and every arrival moment agrees.
    cell = str(CELLS / "pass-by.yaml")
    grid = cellstress.verify(cell, moments="grid")
    assert grid.verdict == UNSAFE and grid.classes
    assert "only" in grid.scope.arrival
    base = Simulator(cell)
    real = 0
    for w in grid.classes:
        trace = base.run(list(w.actions))
        assert trace.unsafe and trace.rows[trace.unsafe_row, L.M_SWEPT] != 0.0  # between the samples
        # a contact of the continuous motion (sampled 200 times per step), not only a conservative flag
        sim = base.with_start(base.start, parse_phase(w.actions[0]))
        acts = np.array([[base.action_index(a) for a in w.actions[1:]]], dtype=np.int64)
        fine = np.empty(1, dtype=np.int64)
        dense_batch(sim.params, sim.reset(), acts, 200, fine)
        real += int(fine[0] >= 0)
    assert real > 0
    res = cellstress.verify(cell, out=tmp_path)
    assert res.verdict == UNSAFE and res.classes
    for w in res.classes:
        assert Simulator(cell).run(list(w.actions)).unsafe
    assert "every arrival moment" in res.scope.arrival and res.scope.margin > 0.0
