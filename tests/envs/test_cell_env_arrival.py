"""The env and ``human.arrival``: ``cycle`` draws the arrival moment from the reset's seed (deterministic), the
moment is in ``info``, and an episode played in the env is the search's episode at that moment
(``phase:SECONDS`` then the actions, replayed by ``Simulator.run``); ``gymnasium.make`` by the ``module:id`` form
in a fresh interpreter."""

from __future__ import annotations

import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest
import yaml
from gymnasium.utils.env_checker import check_env

from cellstress.envs import MAKE_ID, CellEnv
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator
from cellstress.sim.starts import arrival_phases, phase_token


@pytest.fixture(scope="module")
def cycle_cell(tmp_path_factory) -> Path:
    doc = yaml.safe_load(resources.files("cellstress.cell").joinpath("builtin", "s1-scanner-width.yaml")
                         .read_text(encoding="utf-8"))
    doc["human"]["arrival"] = "cycle"
    path = tmp_path_factory.mktemp("arrival") / "s1-cycle.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path


def test_the_seed_draws_the_arrival(cycle_cell):
    env = CellEnv(cycle_cell)
    phases = set(arrival_phases(Simulator(cycle_cell)))
    seen = {}
    for seed in range(12):
        obs, info = env.reset(seed=seed)
        assert info["arrival"] in phases
        assert obs[10] == pytest.approx(info["arrival"])  # the robot's path time at t = 0 is the arrival moment
        seen[seed] = info["arrival"]
    assert len(set(seen.values())) > 3  # the moments differ between seeds
    again = CellEnv(cycle_cell)
    assert [again.reset(seed=s)[1]["arrival"] for s in range(12)] == list(seen.values())


def test_an_episode_is_the_searchs_episode_at_that_moment(cycle_cell):
    env = CellEnv(cycle_cell)
    sim = Simulator(cycle_cell)
    actions = [sim.action_index(a) for a in ("walk+bend-left", "walk+bend-left", "walk+bend-forward",
                                             "walk+bend-forward-right")]
    for seed in (1, 5):
        _, info = env.reset(seed=seed)
        for a in actions:
            obs, _, terminated, _, info = env.step(a)
            if terminated:
                break
        trace = sim.run([phase_token(info["arrival"]), *(sim.action_names[a] for a in actions)])
        last = trace.rows[-1]
        assert obs[8] == last[L.M_D] and obs[10] == last[L.M_TAU]  # bit for bit


def test_fixed_arrival_ignores_the_seed():
    env = CellEnv("s1-scanner-width")
    assert {env.reset(seed=s)[1]["arrival"] for s in range(5)} == {1.4}


def test_check_env_with_a_drawn_arrival(cycle_cell):
    check_env(CellEnv(cycle_cell), skip_render_check=True)


def test_make_in_a_fresh_interpreter(cycle_cell):
    code = f"""
import sys, gymnasium
assert "cellstress" not in sys.modules
env = gymnasium.make({MAKE_ID!r}, cell={str(cycle_cell)!r})
obs, info = env.reset(seed=3)
print(type(env.unwrapped).__name__, info["arrival"])
"""
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    name, arrival = p.stdout.split()
    assert name == "CellEnv" and float(arrival) == CellEnv(cycle_cell).reset(seed=3)[1]["arrival"]
