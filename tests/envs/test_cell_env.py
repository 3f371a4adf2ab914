"""Our cells as Gymnasium envs: Gymnasium's checker, the same numbers as the simulator, the vector env."""

from __future__ import annotations

import warnings
from importlib import resources
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import cellstress.envs
from cellstress.envs.cell_env import CellEnv, CellVectorEnv, observe
from cellstress.human.actions import action_index
from cellstress.sim.simulator import Simulator

S3_WITNESS = ["walk+bend-right", "turn-left-45+bend-forward-left", "walk+bend-forward", "walk+bend-forward-left"]


@pytest.mark.parametrize("cell", ["s3-fence-gap", "baseline"])
def test_gymnasium_checker_passes_without_a_warning(cell):
    env = gymnasium.make(cellstress.envs.ENV_ID, cell=cell)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    assert not [str(w.message) for w in caught]


def test_episode_matches_the_simulator():
    env = CellEnv("s3-fence-gap")
    sim = Simulator("s3-fence-gap")
    trace = sim.run(S3_WITNESS)
    env.reset(seed=3)
    reward_of = sim.criterion.reward(sim.actions_per_episode)
    state = sim.reset()
    for name in S3_WITNESS:
        obs, reward, terminated, truncated, info = env.step(action_index(name))
        state, rows = sim.step(state, action_index(name))
        assert env.observation_space.contains(obs)
        assert reward == reward_of(sim.measures(rows), False, sim.is_unsafe(state))[0]
        np.testing.assert_array_equal(obs, observe(rows[-1]))
    assert terminated and not truncated and info["unsafe"]
    np.testing.assert_array_equal(obs, observe(trace.rows[-1]))
    assert obs[8] == info["d_HR"] == 0.0 and obs[9] == info["v_R"] > 0.0


def test_a_safe_episode_is_truncated_at_the_horizon():
    env = CellEnv("baseline")
    env.reset()
    for k in range(env.sim.actions_per_episode):
        obs, reward, terminated, truncated, info = env.step(action_index("turn-left-90+upright"))
        assert not terminated
        assert truncated == (k == env.sim.actions_per_episode - 1)
    assert reward < 0.0  # the paper's terminal penalty -c_S


def test_bad_action_and_start():
    env = CellEnv("all-flaws", start="upper-end")
    env.reset()
    with pytest.raises(ValueError, match="not in Discrete"):
        env.step(30)
    with pytest.raises(ValueError, match="unknown start 'nowhere'"):
        CellEnv("all-flaws", start="nowhere")


def test_vector_env_equals_single_envs_and_autoresets():
    n = 5
    vec = gymnasium.make_vec(cellstress.envs.ENV_ID, num_envs=n, vectorization_mode="vector_entry_point",
                             cell="s3-fence-gap")
    assert isinstance(vec.unwrapped, CellVectorEnv)
    singles = [CellEnv("s3-fence-gap") for _ in range(n)]
    obs, _ = vec.reset(seed=0)
    for i, e in enumerate(singles):
        np.testing.assert_array_equal(obs[i], e.reset()[0])
    rng = np.random.default_rng(1)
    plan = rng.integers(0, 30, size=(12, n))
    plan[:4, 0] = [action_index(a) for a in S3_WITNESS]  # copy 0 reaches the unsafe set at step 4
    done = np.zeros(n, dtype=bool)
    saw_reset = False
    for acts in plan:
        obs, rew, term, trunc, _ = vec.step(acts)
        for i, e in enumerate(singles):
            if done[i]:  # next-step autoreset: the copy only resets
                want = e.reset()[0]
                np.testing.assert_array_equal(obs[i], want)
                assert rew[i] == 0.0 and not term[i] and not trunc[i]
                saw_reset = True
                continue
            o, r, t, tr, _ = e.step(int(acts[i]))
            np.testing.assert_array_equal(obs[i], o)
            assert (rew[i], term[i], trunc[i]) == (r, t, tr)
        done = term | trunc
    assert saw_reset
    assert vec.observation_space.contains(obs)


def test_the_articulated_worker_as_an_env(tmp_path):
    """Its 119 actions, and an observation that holds its stance and arm joints."""
    text = Path(resources.files("cellstress.cell").joinpath("builtin", "s3-fence-gap.yaml")).read_text()
    cell = tmp_path / "s3-articulated.yaml"
    cell.write_text(text.replace("human:\n", "human:\n  model: articulated\n", 1))
    env = CellEnv(str(cell))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env, skip_render_check=True)
    assert env.action_space.n == 119 and env.observation_space.shape == (22,)
    env.reset(seed=0)
    obs, *_ = env.step(env.sim.action_index("stand+reach-up"))
    assert obs[11 + 1] == pytest.approx(np.pi)  # the left shoulder's flexion, after the action
