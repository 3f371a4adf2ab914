"""The baseline survives adversarial scripted behaviour from every undetected place around the cell, at many
robot phases; the same scripts do find the hazards of the flawed cells (so the scripts have teeth)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml

from cellstress.cell.load import builtin_text, parse_cell
from cellstress.criteria.iso15066 import CREEP_SPEED
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


def attack(name: str, n_phases: int, starts) -> tuple[int, float, int, list[np.ndarray]]:
    """(unsafe episodes, smallest d_HR seen, episodes played, the unsafe rows) over phases x starts x scripts."""
    cycle = Simulator(name).layout.trajectory.cycle
    acts = scripts(np.random.default_rng(42))
    unsafe, lo, played, rows = 0, np.inf, 0, []
    for phase in np.linspace(0.0, cycle, n_phases, endpoint=False):
        sim = with_phase(name, phase)
        for start in starts:
            s = sim.with_start(start)
            assert s.initial_metrics()[L.M_SEEN] == 0, f"start {start} is inside a detection zone"
            res = s.run_batch(acts)
            unsafe += int(res.unsafe.sum())
            lo = min(lo, float(res.min_d.min()))
            played += len(acts)
            for e in np.flatnonzero(res.unsafe):
                trace = s.run(acts[e].tolist())
                rows.append(trace.rows[trace.unsafe_row])
    return unsafe, lo, played, rows


@pytest.mark.slow
def test_baseline_survives_scripted_attacks():
    """In continuous time (the swept test) a script does touch the baseline's robot while it moves, but only in
    the last moments of its braking, creeping (under ISO/TS 15066's 0.1226 m/s) where the 50 ms samples saw it
    stand: the stop comes in time for every approach, to within the last millimetres of the robot's travel."""
    unsafe, lo, played, rows = attack("baseline", 8, start_points())
    assert played > 100_000
    assert lo == 0.0  # the scripts do touch the robot
    assert len(rows) == unsafe < 100  # (24 of 114,000 when written)
    for row in rows:
        assert row[L.M_PHASE] == L.PHASE_BRAKING and 0.0 < row[L.M_V] < CREEP_SPEED, row
        assert row[L.M_SWEPT] != 0.0  # between the samples: no 50 ms sample sees it


@pytest.mark.slow
@pytest.mark.parametrize("cell", ["s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap"])
def test_same_scripts_break_the_flawed_cells(cell):
    flawed = Simulator(cell)
    unsafe, _, _, _ = attack(cell, 4, [flawed.start] + start_points()[::6])
    assert unsafe > 0
