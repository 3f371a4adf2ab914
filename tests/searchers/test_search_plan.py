"""The model-based searcher ``plan`` (not the paper's): finds the hazards of the flawed cells in few episodes,
is a pure function of its seed, refuses what it cannot search, and its model of the robot holds physically."""

from __future__ import annotations

import json
from typing import Protocol, runtime_checkable

import numpy as np
import pytest
import yaml
from toywalk import ToyWalk

from cellstress.cell.load import builtin_text, safe_load_yaml
from cellstress.cli import main
from cellstress.criteria.contact import ContactWhileMoving
from cellstress.searchers import SearchError, plan, run_search, searcher_class
from cellstress.searchers.plan import Plan, _Model
from cellstress.searchers.result import SearchResult
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

FLAWED = ("s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")


@pytest.fixture(scope="module")
def sims():
    return {name: Simulator(name) for name in FLAWED}


def test_registered() -> None:
    assert searcher_class("plan") is Plan and Plan().name == "plan"


@pytest.mark.parametrize("cell", FLAWED)
def test_finds_every_hazard_in_few_episodes(sims, cell) -> None:
    sim = sims[cell]
    reward = sim.criterion.reward(sim.actions_per_episode)
    episodes = []
    for seed in range(5):
        out = run_search(sim, reward, "plan", 200, seed)
        assert out.found, (cell, seed)
        ep = out.first_hazard
        assert sim.run(list(ep.actions)).unsafe  # the hazard replays from s0 by its actions alone
        episodes.append(ep.index)
    # measured on seeds 0-4: 3.2 / 15.6 / 3.0 on average (random search: about 180 / 170 / 90, docs/results.md)
    assert np.mean(episodes) < 30, episodes


@pytest.mark.parametrize("budget", [1, 2, 3, 17])
def test_budget_is_exact(budget) -> None:
    sim = Simulator("baseline")  # safe: the whole budget is used
    out = run_search(sim, sim.criterion.reward(sim.actions_per_episode), "plan", budget, 0)
    assert out.episodes == budget and len(out.risks) == budget and not out.found


def test_until_budget_never_replays_a_hazard(sims) -> None:
    # a candidate that begins with a sequence cut short by a hazard would replay that episode: never drawn
    sim = sims["s3-fence-gap"]
    out = run_search(sim, sim.criterion.reward(sim.actions_per_episode), "plan", 60, 1, until="budget")
    actions = [h.actions for h in out.hazards]
    assert len(actions) > 30 and len(set(actions)) == len(actions)  # measured: 57 hazards, all distinct
    assert not any(a[: len(b)] == b for a in actions for b in actions if len(b) < len(a))


def test_same_seed_same_search(sims) -> None:
    sim = sims["s2-elbow-intrusion"]
    reward = sim.criterion.reward(sim.actions_per_episode)
    a, b, c = (run_search(sim, reward, "plan", 30, s, until="budget") for s in (3, 3, 4))
    assert a == b and a.episodes == 30
    assert a.risks != c.risks


@pytest.mark.parametrize("cell", ["door-unlocked", "palletizing", "reach-over"])
def test_resuming_played_prefixes_changes_no_episode(cell, monkeypatch) -> None:
    """``plan`` walks a candidate's played prefix once (``ResumableWorker``): the same episodes, risks and
    hazards as walking every candidate from s0 (doors pushed, a searched arrival phase, the articulated worker)."""
    sim = Simulator(cell)
    reward = sim.criterion.reward(sim.actions_per_episode)
    resumed = run_search(sim, reward, "plan", 25, 2, until="budget")

    @runtime_checkable
    class Nothing(Protocol):
        def no_such_ability(self) -> None: ...

    monkeypatch.setattr(plan, "ResumableWorker", Nothing)
    walked = run_search(sim, reward, "plan", 25, 2, until="budget")
    assert resumed == walked and resumed.episodes == 25


def test_result_file_is_byte_identical(tmp_path, capsys) -> None:
    args = ["search", "s3-fence-gap", "--searcher", "plan", "--budget", "30", "--until", "budget", "--no-report"]
    for d in ("a", "b"):
        assert main([*args, "--seed", "1", "--out", str(tmp_path / d)]) == 0
    capsys.readouterr()
    assert (tmp_path / "a" / "result.json").read_bytes() == (tmp_path / "b" / "result.json").read_bytes()


def test_refuses_what_it_cannot_search(tmp_path, capsys) -> None:
    with pytest.raises(SearchError, match="cell's simulator"):
        run_search(ToyWalk(), ContactWhileMoving().reward(8), "plan", 20, 0)


def test_several_start_points_as_they_are(tmp_path, capsys) -> None:
    """Issue 34.6: `search CELL --searcher plan` on a cell with several start points gives the first hazard (the
    budget shared between the start points in slices), with no --distinct, and the same bytes twice."""
    args = ["search", "all-flaws", "--searcher", "plan", "--budget", "200", "--seed", "0", "--no-report"]
    for d in ("a", "b"):
        assert main([*args, "--out", str(tmp_path / d)]) == 0
    capsys.readouterr()
    res = SearchResult.load(tmp_path / "a" / "result.json")
    assert res.found and res.until == "first" and res.distinct is None
    assert res.episodes == res.hazard.episode < 200  # stopped at the first hazard
    assert res.hazard.actions[0].startswith("start:")
    assert (tmp_path / "a" / "result.json").read_bytes() == (tmp_path / "b" / "result.json").read_bytes()


@pytest.mark.parametrize("options", [{"n_init": 0}, {"candidates": 0}, {"pool": 1.5}, {"explore": 1.5},
                                     {"sticky": -0.1}, {"keep_tail": True}, {"init_sticky": "high"}])
def test_bad_options(options) -> None:
    with pytest.raises(SearchError):
        Plan(**options)


def without_devices(name: str, tmp_path) -> Simulator:
    spec = safe_load_yaml(builtin_text(name))
    spec["devices"] = []
    path = tmp_path / f"{name}-no-devices.yaml"
    path.write_text(yaml.safe_dump(spec), encoding="utf-8")
    return Simulator(path)


@pytest.mark.parametrize("cell", ["s2-deceptive", "s3-fence-gap"])
def test_robot_points_learned_in_one_episode_hold_in_every_other(cell, tmp_path) -> None:
    """The premise of the model: until a stop, the robot's pose is a function of time alone. In a cell without
    devices nothing stops the robot, so a predicted clearance is an upper bound on the real d_HR of any sequence
    (up to the offsets' tolerance): the robot points seen at a step lie on the robot at that step in every
    episode. Checked against 400 sequences played for real (test only: the searcher never does this)."""
    sim = without_devices(cell, tmp_path)
    model = _Model(sim)
    rng = np.random.default_rng(2)
    for actions in rng.integers(0, sim.n_actions, size=(40, sim.actions_per_episode)).tolist():
        model.learn(actions, sim.run(actions).rows[1:])
    fresh = rng.integers(0, sim.n_actions, size=(400, sim.actions_per_episode))
    predicted = model.predict(fresh)
    real = np.empty(len(fresh))
    for i, actions in enumerate(fresh):
        rows = sim.run(actions).rows[1:]
        moving = rows[:, L.M_V] > model.v_tol
        real[i] = rows[moving, L.M_D].min() if moving.any() else np.inf
    known = np.isfinite(predicted)
    assert known.sum() > 300
    bound = np.maximum(predicted[known], 0.0)  # (a penetration is negative; d_HR stops at 0)
    # (the offsets are within the trace's tolerance of one 2 cm grid step plus 5 % of d_HR)
    assert np.all(real[known] <= bound + 0.02 + 0.05 * real[known]), (real[known] - bound).max()
    # and the bound is informative: most predictions are within 10 cm of the truth
    assert np.median(bound - real[known]) < 0.1
    assert np.sum((predicted <= 0) & (real == 0)) > 0  # contacts predicted, and real


def test_distinct_finds_the_three_flaws_of_all_flaws(tmp_path, capsys) -> None:
    # with --distinct each start point gets its own plan searches (search.slices)
    out = tmp_path / "af"
    args = ["search", "all-flaws", "--searcher", "plan", "--distinct", "--until", "budget", "--budget", "40",
            "--seed", "0", "--no-report", "--out", str(out)]
    assert main(args) == 0
    capsys.readouterr()
    doc = json.loads((out / "result.json").read_text())
    devices = {d["class"]["device"] for d in doc["distinct"]}
    assert devices == {"front-scanner", "bay-curtain", "none"}  # measured: all three by episode 7
