"""The baseline survives adversarial scripted behaviour from every undetected place around the cell, at many
robot phases; the same scripts do find the hazards of the flawed cells (so the scripts have teeth)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml

from cellstress.cell.load import builtin_text, parse_cell
from cellstress.human.actions import action_index
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

BODIES = ["upright", "bend-forward", "bend-left", "bend-right", "bend-forward-left", "bend-forward-right"]
AGGRESSIVE = [f"walk+{b}" for b in BODIES] + [f"{t}+{b}" for t in ("turn-left-45", "turn-right-45")
                                                for b in ("bend-forward", "bend-forward-left", "bend-forward-right")]


def start_points():
    """Places outside every detection zone: the front aisle, the back aisle, outside both side walls."""
    pts = [(x, 3.35) for x in np.linspace(-1.2, 1.2, 7)]
    pts += [(x, -1.85) for x in (-0.4, 0.0, 0.4)]
    pts += [(sx * 1.75, y) for sx in (-1.0, 1.0) for y in np.linspace(-1.4, 3.0, 7)]
    starts = []
    for x, y in pts:
        inward = -90.0 if y > 3.0 else (90.0 if y < -1.6 else (0.0 if x < 0 else 180.0))
        at_robot = math.degrees(math.atan2(-y, -x))
        starts += [(float(x), float(y), inward), (float(x), float(y), at_robot)]
    return starts


def scripts(rng):
    seqs = []
    for k in range(9):  # walk k steps straight ahead, then lean while stepping on the spot
        for b in BODIES:
            lean = [f"turn-left-45+{b}" if i % 2 == 0 else f"turn-right-45+{b}" for i in range(8 - k)]
            seqs.append(["walk+upright"] * k + lean)
    seqs += [[f"walk+{b}"] * 8 for b in BODIES]
    idx = rng.integers(0, len(AGGRESSIVE), (300, 8))
    seqs += [[AGGRESSIVE[i] for i in row] for row in idx]
    return np.asarray([[action_index(a) for a in s] for s in seqs], dtype=np.int64)


def with_phase(name: str, phase: float) -> Simulator:
    data = yaml.safe_load(builtin_text(name))
    data = copy.deepcopy(data)
    data["robot"]["task"]["phase"] = float(phase)
    return Simulator(parse_cell(yaml.safe_dump(data), f"{name}@{phase:.2f}", None))


def attack(name: str, n_phases: int, starts) -> tuple[int, float, int]:
    """(unsafe episodes, smallest d_HR seen, episodes played) over phases x starts x scripts."""
    cycle = Simulator(name).layout.trajectory.cycle
    acts = scripts(np.random.default_rng(42))
    unsafe, lo, played = 0, np.inf, 0
    for phase in np.linspace(0.0, cycle, n_phases, endpoint=False):
        sim = with_phase(name, phase)
        for start in starts:
            s = sim.with_start(start)
            assert s.initial_metrics()[L.M_SEEN] == 0, f"start {start} is inside a detection zone"
            res = s.run_batch(acts)
            unsafe += int(res.unsafe.sum())
            lo = min(lo, float(res.min_d.min()))
            played += len(acts)
    return unsafe, lo, played


@pytest.mark.slow
def test_baseline_survives_scripted_attacks():
    unsafe, lo, played = attack("baseline", 8, start_points())
    assert played > 100_000
    assert unsafe == 0
    assert lo == 0.0  # the scripts do touch the robot, but only once it stands still


@pytest.mark.slow
@pytest.mark.parametrize("cell", ["s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap"])
def test_same_scripts_break_the_flawed_cells(cell):
    flawed = Simulator(cell)
    unsafe, _, _ = attack(cell, 4, [flawed.start] + start_points()[::6])
    assert unsafe > 0
