"""The exact decision against brute force: for short horizons, the hazardous-sequence count of every built-in
cell (one start point each, at its own phase and at another) equals enumerating all 30^k sequences with
``Simulator.run_batch``; every witness is a real, bit-exact episode; a searcher's hazard lies in the verifier's
hazardous set."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import cellstress
from cellstress.cell.load import BUILTIN_CELLS
from cellstress.sim.simulator import Simulator
from cellstress.verify.bounds import Bounds
from cellstress.verify.phases import start_points
from cellstress.verify.tree import decide, lookup


def _all_sequences(k: int) -> np.ndarray:
    return np.array(list(itertools.product(range(30), repeat=k)), dtype=np.int64)


def _brute_force(sim: Simulator, k: int) -> int:
    return int(sim.run_batch(_all_sequences(k)).unsafe.sum())


def _start_sim(cell: str, phase: float | None = None) -> Simulator:
    sim = Simulator(cell)
    s = start_points(sim.cell)[0]
    own = sim.cell.spec.robot.task.phase if s.phase is None else s.phase
    return sim.with_start(s.pose, own if phase is None else phase)


@pytest.mark.parametrize("cell", BUILTIN_CELLS)
def test_counts_equal_brute_force_three_actions(cell) -> None:
    sim = _start_sim(cell)
    out = decide(sim, 3, Bounds(sim, horizon=3))
    assert out.decided
    assert out.hazardous == _brute_force(sim, 3)
    assert out.hazardous + out.safe == 30 ** 3


@pytest.mark.parametrize(("cell", "phase"), [("s1-scanner-width", None), ("s3-fence-gap", 4.75)])
def test_counts_equal_brute_force_four_actions(cell, phase) -> None:
    sim = _start_sim(cell, phase)
    out = decide(sim, 4, Bounds(sim, horizon=4))
    assert out.hazardous == _brute_force(sim, 4) > 0


def test_witnesses_are_played_bit_exactly() -> None:
    sim = _start_sim("s1-scanner-width")
    out = decide(sim, 5, Bounds(sim, horizon=5))
    assert out.hits
    for hit in out.hits:
        trace = sim.run(list(hit.actions))
        assert trace.unsafe and np.array_equal(trace.rows[-1], hit.row)
    # the hits' sequences add up to the count
    assert sum(h.sequences for h in out.hits) == out.hazardous


@pytest.mark.parametrize("cell", ["s1-scanner-width", "s3-fence-gap"])
def test_searchers_hazard_is_in_the_hazardous_set(cell) -> None:
    found = cellstress.search(cell, "plan", budget=200, seed=0)
    assert found.found
    sim = Simulator(cell)
    bounds = Bounds(sim, horizon=8)
    out = decide(sim, 8, bounds, keep=True)
    assert lookup(sim, out, bounds, list(found.hazard.actions)) == "hazardous"
    assert out.hazardous > 0
