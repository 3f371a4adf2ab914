from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from cellstress.sim.determinism import DeterminismError, check_determinism
from cellstress.sim.simulator import Simulator

CELLS = ["baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap"]


@pytest.mark.parametrize("cell", CELLS)
def test_every_way_of_playing_agrees(cell):
    sim = Simulator(cell)
    rng = np.random.default_rng(5)
    seqs = rng.integers(0, 30, (40, 8)).tolist()
    assert check_determinism(sim, seqs) == 40


def test_checker_catches_a_difference(monkeypatch):
    sim = Simulator("s2-elbow-intrusion")
    real_step = sim.step

    def drifting_step(state, action):
        nxt, rows = real_step(state, action)
        rows[:, 6] += 1e-15  # a tiny disagreement in d_HR
        return nxt, rows

    monkeypatch.setattr(sim, "step", drifting_step)
    with pytest.raises(DeterminismError, match="step-by-step"):
        check_determinism(sim, [[0, 1, 2]])


def test_same_bits_in_a_fresh_process():
    seq = "walk+upright,walk+bend-left,walk+bend-forward"
    code = (
        "import sys; from cellstress.sim.simulator import Simulator;"
        f"sys.stdout.write(Simulator('s2-elbow-intrusion').run({seq.split(',')!r}).rows.tobytes().hex())"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    here = Simulator("s2-elbow-intrusion").run(seq.split(",")).rows.tobytes().hex()
    assert out == here


def test_step_does_not_change_its_input():
    sim = Simulator("baseline")
    s0 = sim.reset()
    before = s0.copy()
    s1, rows = sim.step(s0, "walk+bend-forward")
    assert np.array_equal(s0, before)
    assert not np.array_equal(s1, s0)
    assert rows.shape == (4, rows.shape[1])
    assert np.array_equal(sim.restore(sim.snapshot(s1)), s1)
