"""The exact decision against brute force: at 3 and 4 actions the hazardous-sequence count of every built-in
cell (one start point each, at its own phase and at another) and of test cells made to have hazards there
for each feature (automatic restart, warning field, speed and separation monitoring, guard door, muting,
several robots, a prismatic joint, the articulated worker: tests/verifier/cells) equals playing every sequence:
all 30^3 with ``Simulator.run_batch``, all 30^4 prefix by prefix without merging or bounds (``verify_brute``;
the articulated worker's 119^2 and 119^3 too); every witness
is a real, bit-exact episode; a searcher's hazard lies in the verifier's hazardous set."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from verify_brute import brute_force

import cellstress
from cellstress.cell.load import BUILTIN_CELLS, load_cell
from cellstress.sim.simulator import Simulator
from cellstress.verifier.bounds import Bounds
from cellstress.verifier.phases import arrival_phases, start_points
from cellstress.verifier.tree import decide, lookup


def _all_sequences(k: int) -> np.ndarray:
    return np.array(list(itertools.product(range(30), repeat=k)), dtype=np.int64)


def _brute_force(sim: Simulator, k: int) -> int:
    return int(sim.run_batch(_all_sequences(k)).unsafe.sum())


def _start_sim(cell: str, phase: float | None = None) -> Simulator:
    sim = Simulator(cell)
    s = start_points(sim.cell)[0]
    return sim.with_start(s.pose, arrival_phases(sim, s, "cell")[0] if phase is None else phase)


# the paper worker's 30 actions; the articulated worker's 119 (its cells: below)
PAPER_CELLS = tuple(c for c in BUILTIN_CELLS if load_cell(c).spec.human.model == "paper")
ARTICULATED_CELLS = tuple(c for c in BUILTIN_CELLS if c not in PAPER_CELLS)


@pytest.mark.parametrize(("cell", "phase"), [(c, None) for c in PAPER_CELLS] + [("s1-scanner-width", 3.0)])
def test_counts_equal_brute_force_three_actions(cell, phase) -> None:
    sim = _start_sim(cell, phase)
    out = decide(sim, 3, Bounds(sim, horizon=3))
    assert out.decided
    assert out.hazardous == _brute_force(sim, 3)
    assert out.hazardous + out.safe == 30 ** 3


CELLS = Path(__file__).parent / "cells"
# (test cell, arrival phases where its feature decides hazards within 3-4 actions)
FEATURE_CELLS = [
    ("restart-fast", (0.0, 2.5)),  # automatic restart after 0.1 s
    ("warning-trunk", (4.35, 0.55)),  # a trunk-height warning field that releases after 0.1 s
    ("warning-hold", (4.35, 0.55)),  # the same with the stop held: at rest behind a warning field
    ("ssm-near", (1.0, 2.0)),  # speed and separation monitoring
    ("door-near", (0.0,)),  # a guard door without guard locking
    ("muting-near", (4.0,)),  # a muted curtain
    ("two-near", (0.0,)),  # two robots, the curtain stopping one
    ("two-stop", (0.0, 1.0)),  # two robots, the curtain stopping both (at rest once both stand)
    ("linear-axis", (0.0, 1.0)),  # a prismatic joint, a long stop
]


def _feature_sim(name: str, phase: float) -> Simulator:
    sim = Simulator(str(CELLS / f"{name}.yaml"))
    return sim.with_start(start_points(sim.cell)[0].pose, phase)


@pytest.mark.parametrize(("cell", "phase"), [(c, p) for c, ps in FEATURE_CELLS for p in ps])
def test_feature_cells_equal_brute_force_three_actions(cell, phase) -> None:
    sim = _feature_sim(cell, phase)
    out = decide(sim, 3, Bounds(sim, horizon=3))
    assert out.decided
    assert out.hazardous == _brute_force(sim, 3) > 0


@pytest.mark.slow
@pytest.mark.parametrize(("cell", "phase"), [(c, ps[0]) for c, ps in FEATURE_CELLS])
def test_feature_cells_equal_brute_force_four_actions(cell, phase) -> None:
    sim = _feature_sim(cell, phase)
    out = decide(sim, 4, Bounds(sim, horizon=4))
    assert out.decided
    assert out.hazardous == brute_force(sim, 4) > 0


@pytest.mark.slow
@pytest.mark.parametrize("cell", PAPER_CELLS)
def test_counts_equal_brute_force_four_actions(cell) -> None:
    sim = _start_sim(cell)
    out = decide(sim, 4, Bounds(sim, horizon=4))
    assert out.decided
    assert out.hazardous == brute_force(sim, 4)


@pytest.mark.parametrize("cell", ["s1-scanner-width", "restart-auto"])
def test_the_brute_force_tree_plays_what_run_batch_plays(cell) -> None:
    # the prefix-by-prefix brute force of the four-action checks, against every episode played whole
    sim = _start_sim(cell, 3.0)
    assert brute_force(sim, 3) == _brute_force(sim, 3)


def test_witnesses_are_played_bit_exactly() -> None:
    sim = _start_sim("s1-scanner-width")
    out = decide(sim, 5, Bounds(sim, horizon=5))
    assert out.hits
    for hit in out.hits:
        trace = sim.run(list(hit.actions))
        assert trace.unsafe and np.array_equal(trace.rows[-1], hit.row)
    # the hits' sequences add up to the count
    assert sum(h.sequences for h in out.hits) == out.hazardous


def test_searchers_hazards_are_in_the_hazardous_set() -> None:
    # every hazardous episode of a whole search budget, at the cell's horizon of 8 actions
    found = cellstress.search("s1-scanner-width", "plan", budget=100, seed=0, until="budget")
    assert len(found.hazards) > 10
    sim = Simulator("s1-scanner-width")
    bounds = Bounds(sim, horizon=8)
    out = decide(sim, 8, bounds, keep=True)
    for h in found.hazards:
        assert lookup(sim, out, bounds, list(h.actions)) == "hazardous", h.actions


def test_searchers_hazard_on_s3_is_in_the_hazardous_set() -> None:
    # s3's tree at 8 actions takes minutes (docs/verify.md); its first hazard is decided at its own length, which
    # counts the same prefix (the horizon only adds completions after it)
    found = cellstress.search("s3-fence-gap", "plan", budget=200, seed=0)
    actions = list(found.hazard.actions)
    assert len(actions) <= 5
    sim = Simulator("s3-fence-gap")
    bounds = Bounds(sim, horizon=len(actions))
    out = decide(sim, len(actions), bounds, keep=True)
    assert lookup(sim, out, bounds, actions) == "hazardous"


# The articulated worker: 119^2 = 14,161 sequences at 2 actions, 119^3 = 1,685,159 at 3 (prefix by prefix: about
# a minute), so every built-in cell at 2 and a test cell made to have hazards there (reach-near: a hand over a low
# panel into the arm's path, a curtain behind the panel that stops the robot) at 2 and 3.
@pytest.mark.parametrize(("cell", "phase"), [(c, None) for c in ARTICULATED_CELLS]
                         + [(str(CELLS / "reach-near.yaml"), p) for p in (1.0, 1.5, 4.0)])
def test_articulated_counts_equal_brute_force_two_actions(cell, phase) -> None:
    sim = _start_sim(cell, phase)
    assert sim.n_actions == 119
    out = decide(sim, 2, Bounds(sim, horizon=2))
    assert out.decided
    assert out.hazardous == brute_force(sim, 2)
    if phase is not None:
        assert out.hazardous > 0


@pytest.mark.slow
def test_articulated_counts_equal_brute_force_three_actions() -> None:
    sim = _feature_sim("reach-near", 1.5)
    out = decide(sim, 3, Bounds(sim, horizon=3))
    assert out.decided and out.pruned_states.get("at-rest", 0) > 0
    assert out.states[2] < 84 * 119  # states merged that differ in no slot the future reads (stance, arms too)
    assert out.hazardous == brute_force(sim, 3) > 0
