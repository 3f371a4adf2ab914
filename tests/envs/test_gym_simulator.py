"""Any Gymnasium env stress-tested by our searchers: the protocol, pure steps by replay, searches that find a
failure the same way every time, and clear errors for envs it cannot search."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

from cellstress.api import make_simulator
from cellstress.core.protocols import Simulator
from cellstress.envs.gym_simulator import GymSimulator
from cellstress.searchers import run_search

LEFT, DOWN, RIGHT, UP = range(4)


class HoleDistance(gymnasium.Wrapper):
    """FrozenLake with the Manhattan distance to the nearest hole in info (0 in a hole)."""

    def __init__(self, env):
        super().__init__(env)
        desc = env.unwrapped.desc
        self.cols = desc.shape[1]
        self.holes = [(r, c) for r in range(desc.shape[0]) for c in range(self.cols) if desc[r, c] == b"H"]

    def _info(self, s, info):
        r, c = divmod(int(s), self.cols)
        return {**info, "hole_distance": min(abs(r - hr) + abs(c - hc) for hr, hc in self.holes)}

    def reset(self, **kwargs):
        s, info = self.env.reset(**kwargs)
        return s, self._info(s, info)

    def step(self, action):
        s, r, terminated, truncated, info = self.env.step(action)
        return s, r, terminated, truncated, self._info(s, info)


def lake(horizon: int = 6) -> GymSimulator:
    return GymSimulator(lambda: HoleDistance(gymnasium.make("FrozenLake-v1", is_slippery=False)),
                        measure="hole_distance", horizon=horizon)


def test_it_is_a_simulator_and_registered():
    sim = lake()
    assert isinstance(sim, Simulator)
    assert sim.n_actions == 4 and sim.actions_per_episode == 6
    assert isinstance(make_simulator("gym", env=lambda: HoleDistance(gymnasium.make("FrozenLake-v1")),
                                     measure="hole_distance"), GymSimulator)


def test_steps_are_pure_and_branching_replays():
    sim = lake()
    s0 = sim.reset()
    right, _ = sim.step(s0, RIGHT)  # (0, 1): one from the hole at (1, 1)
    down, rows = sim.step(right, DOWN)  # into the hole
    assert sim.is_unsafe(down) and rows[-1, 0] == 0.0
    assert right.measure == 1 and not sim.is_unsafe(right)
    # branch from the earlier state: the env is replayed from the seed, the result is the same as fresh
    again, _ = sim.step(right, RIGHT)
    fresh = lake()
    f1, _ = fresh.step(fresh.reset(), RIGHT)
    f2, _ = fresh.step(f1, RIGHT)
    assert again == f2 and again.actions == (RIGHT, RIGHT)
    assert sim.measures(rows).d_hr == 0.0


def test_an_ended_env_stays_put():
    sim = lake(horizon=8)
    state = sim.reset()
    for a in (RIGHT, RIGHT, DOWN, DOWN, DOWN, RIGHT):  # to the goal (3, 3): ends without a failure
        state, _ = sim.step(state, a)
    assert state.ended and not state.unsafe
    after, rows = sim.step(state, LEFT)
    assert after == state and rows[-1, 0] == state.measure
    trace = sim.run([RIGHT, DOWN, LEFT])
    assert trace.unsafe and trace.unsafe_row == 1 and len(trace.rows) == 2


@pytest.mark.parametrize("searcher", ["random", "mcts", "mcts-commit", "evolve"])
def test_searchers_find_a_hole_the_same_way_every_time(searcher):
    sim = lake()
    a = run_search(sim, sim.reward(), searcher, 60, 2)
    b = run_search(lake(), sim.reward(), searcher, 60, 2)
    assert a == b and a.found
    assert lake().run(a.first_hazard.actions).unsafe


def test_envs_it_cannot_search():
    with pytest.raises(ValueError, match="must be Discrete"):
        GymSimulator("Pendulum-v1", measure="x")
    sim = GymSimulator("FrozenLake-v1", measure="distance", env_kwargs={"is_slippery": False})
    with pytest.raises(KeyError, match="no safety measure 'distance'"):
        sim.step(sim.reset(), RIGHT)
    with pytest.raises(ValueError, match="horizon"):
        GymSimulator("FrozenLake-v1", measure="distance", horizon=0)
    assert np.isinf(sim.reset().measure)  # FrozenLake's reset info has no distance: no failure at the start
