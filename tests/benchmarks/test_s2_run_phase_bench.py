"""benchmarks/s2_run_phase.py and s2_paper_random_odds.py: the per-run phase draw, the cell edits, and the exact
odds of the paper's S2 random row against a simulation of ten-run experiments."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

_BENCH = Path(__file__).resolve().parents[2] / "benchmarks"


def _load(name):
    spec = importlib.util.spec_from_file_location(f"{name}_bench", _BENCH / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


run_phase = _load("s2_run_phase")
odds = _load("s2_paper_random_odds")


def test_a_seed_draws_one_phase_for_all_its_searchers():
    grid = tuple(round(0.05 * k, 9) for k in range(250))
    draws = [run_phase.draw_phase(s, grid) for s in range(40)]
    assert draws == [run_phase.draw_phase(s, grid) for s in range(40)]
    assert all(p in grid for p in draws)
    assert len(set(draws)) > 20  # the seeds spread over the cycle


def test_edits_reach_into_lists_and_maps():
    data = {"fences": [{"points": [[0, 0], [1, 1]]}], "robot": {"base": {"xyz": [0, 0, 0]}}}
    run_phase.apply_edit(data, "fences.0.points=[[-1.5, 3.2], [-1.5, -1.4]]")
    run_phase.apply_edit(data, "robot.base.xyz=[0.0, -0.2, 0.85]")
    assert data == {"fences": [{"points": [[-1.5, 3.2], [-1.5, -1.4]]}], "robot": {"base": {"xyz": [0.0, -0.2, 0.85]}}}
    with pytest.raises(SystemExit):
        run_phase.apply_edit(data, "robot.base.xyz")


def _simulated(p, runs, rng):
    """Share of ten-run random searches (budget 200, a miss counted as 200) with 3 found and mean <= 150.4."""
    first = rng.geometric(p, size=(runs, 10))
    found = first <= 200
    eps = np.where(found, first, 200)
    return float(np.mean((found.sum(axis=1) == 3) & (eps.mean(axis=1) <= 150.4)))


@pytest.mark.parametrize("p", [0.002, 0.004])
def test_the_exact_odds_match_a_simulation(p):
    want = odds.fixed(p)
    got = _simulated(p, 400_000, np.random.default_rng(1))
    sigma = np.sqrt(want * (1 - want) / 400_000)
    assert abs(got - want) < 4 * sigma + 1e-6
