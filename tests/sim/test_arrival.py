"""The arrival phase: the phases a search may choose (``human.arrival``), and the ``phase:SECONDS`` decision that
replays an episode at its phase."""

from __future__ import annotations

import math
from importlib import resources

import numpy as np
import pytest
import yaml

from cellstress.cell.load import parse_cell
from cellstress.core.errors import ActionError, CellError
from cellstress.sim.simulator import Simulator
from cellstress.sim.starts import arrival_phases, parse_phase, phase_grid, phase_token


@pytest.fixture(scope="module")
def baseline() -> dict:
    text = resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)


def _sim(data: dict, tmp_path, arrival) -> Simulator:
    data = dict(data, human=dict(data["human"], arrival=arrival))
    return Simulator(parse_cell(yaml.safe_dump(data), str(tmp_path / "cell.yaml"), tmp_path))


def test_phase_grid_is_the_step_grid_with_exact_names():
    grid = phase_grid(0.05, 0.0, 1.0)
    assert len(grid) == 21 and grid[3] == 0.15 and grid[-1] == 1.0
    assert all(parse_phase(phase_token(p)) == p for p in grid)
    assert phase_grid(0.05, 0.12, 0.3) == (0.15, 0.2, 0.25, 0.3)


def test_arrival_phases_per_mode(baseline, tmp_path):
    fixed = _sim(baseline, tmp_path, "fixed")
    assert arrival_phases(fixed) == (baseline["robot"]["task"]["phase"],)
    cycle = _sim(baseline, tmp_path, "cycle")
    phases = arrival_phases(cycle)
    c, dt = cycle.layout.trajectory.cycle, cycle.dt
    assert phases[0] == 0.0 and phases[-1] < c and len(phases) == math.ceil(c / dt - 1e-9)
    window = _sim(baseline, tmp_path, {"start": 1.0, "end": 1.5})
    assert arrival_phases(window) == (1.0, 1.05, 1.1, 1.15, 1.2, 1.25, 1.3, 1.35, 1.4, 1.45, 1.5)


def test_window_end_before_start_is_a_clear_error(baseline, tmp_path):
    with pytest.raises(CellError) as err:
        _sim(baseline, tmp_path, {"start": 2.0, "end": 1.0})
    assert "human.arrival" in str(err.value)


def test_a_phase_decision_replays_the_episode_at_that_phase(baseline, tmp_path):
    sim = _sim(baseline, tmp_path, "cycle")
    acts = ["walk+upright", "walk+bend-forward", "turn-left-45+upright"]
    by_token = sim.run([phase_token(2.35), *acts])
    direct = sim.with_start(sim.start, 2.35).run(acts)
    assert np.array_equal(by_token.rows, direct.rows)
    assert by_token.rows[0, 19] != sim.run(acts).rows[0, 19] or sim.phase == 2.35  # the robot's path time differs


@pytest.mark.parametrize("token", ["phase:x", "phase:nan", "phase:-1", "phase:1e9"])
def test_bad_phase_decisions_are_refused(token):
    with pytest.raises(ActionError):
        parse_phase(token)
