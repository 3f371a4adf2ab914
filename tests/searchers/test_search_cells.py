"""The searchers on the built-in flawed cells: they find the hazards, the results are reproducible files."""

from __future__ import annotations

import json

import numpy as np
import pytest

import cellstress
from cellstress.cli import main
from cellstress.core.protocols import BatchSimulator
from cellstress.searchers import SearchResult, run_search, search

FLAWED = ("s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")


@pytest.fixture(scope="module")
def sims():
    from cellstress.sim.simulator import Simulator

    return {name: Simulator(name) for name in FLAWED}


# The seed of each run: 0, except where seed 0 finds nothing in 200 episodes (the recalibrated S2 is harder: the
# paper's MCTS variants find it in 6/10 and 3/10 runs, evolve in 9/10, docs/results.md); then the first seed of
# 0..9 that does.
SEEDS = {("s2-elbow-intrusion", "mcts"): 2, ("s2-elbow-intrusion", "mcts-commit"): 6,
         ("s2-elbow-intrusion", "evolve"): 1}


@pytest.mark.parametrize("cell", FLAWED)
@pytest.mark.parametrize("searcher", ["mcts", "mcts-commit", "evolve"])
def test_searchers_find_the_hazard(sims, cell, searcher, tmp_path, capsys) -> None:
    sim = sims[cell]
    res = search(sim, searcher, budget=200, seed=SEEDS.get((cell, searcher), 0))
    assert res.found, f"{searcher} found no hazard in {cell} within 200 episodes"
    h = res.hazard
    assert 1 <= h.episode == res.episodes <= 200
    assert len(res.risk_per_episode) == res.episodes
    assert [(e.episode, e.actions) for e in res.hazards] == [(h.episode, h.actions)]
    assert 1 <= len(h.actions) <= sim.actions_per_episode
    last = h.trace[-1]
    assert last.unsafe and not any(r.unsafe for r in h.trace[:-1])
    # a contact at the step, or one the swept test found (or could not rule out) between the steps, at its moment
    assert h.d_HR == last.d_HR and (last.d_HR <= 0.0 or last.between == "not-ruled-out")
    assert h.v_R == last.v_R > 0.001
    assert h.step == last.step and h.time_s == (last.t if last.between is None else last.contact_t)
    assert last.between is None or last.t - 0.05 < last.contact_t <= last.t
    assert (h.robot_link, h.body_part, h.point) == (last.robot_link, last.body_part,
                                                            last.robot_point)
    # the episode's risk (max 1/c_S over its action ends) is at least that of the contact, e^{v_R}
    assert res.risk_per_episode[-1] >= np.exp(h.v_R) * (1 - 1e-12)
    # the hazard is played from s0 by its actions alone (and the last action is the unsafe one)
    trace = sim.run(h.actions)
    assert trace.unsafe and trace.unsafe_row == len(trace.rows) - 1
    assert (len(trace.rows) - 2) // sim.steps_per_action == len(h.actions) - 1
    path = res.write(tmp_path)
    assert main(["replay", str(path)]) == 0
    out = capsys.readouterr().out
    assert "REPRODUCED bit-exactly" in out and h.robot_link in out.splitlines()[-1]


def test_result_file_contents(sims, tmp_path) -> None:
    sim = sims["s3-fence-gap"]
    res = search(sim, "mcts", budget=200, seed=0, top_k=5)
    doc = json.loads(res.write(tmp_path).read_text())
    assert set(doc) == {"cell", "searcher", "params", "seed", "budget", "until", "found", "episodes", "hazard",
                        "hazards", "top", "risk_per_episode", "distinct_sequences", "version", "format"}
    files = doc["cell"].pop("files")
    assert doc["cell"] == {"name": "s3-fence-gap", "sha256": sim.cell.sha256, "source": "s3-fence-gap",
                           "criterion": "contact-while-moving"}
    assert files == [f.model_dump() for f in sim.cell.files] and files[0]["sha256"] == sim.cell.sha256
    assert 1 <= doc["distinct_sequences"] <= doc["episodes"]
    assert doc["searcher"] == "mcts" and doc["params"] == {"ec": 0.5, "k": 1.0, "alpha": 0.85}
    assert doc["version"] == cellstress.__version__
    assert len(doc["top"]) == min(5, doc["episodes"])
    assert {"episode", "actions", "return", "risk", "unsafe"} == set(doc["top"][0])
    rets = [t["return"] for t in doc["top"]]
    assert rets == sorted(rets, reverse=True)
    assert SearchResult.load(tmp_path) == res


def test_same_inputs_give_byte_identical_files_other_seed_other_search(tmp_path, capsys) -> None:
    args = ["search", "s1-scanner-width", "--searcher", "mcts", "--budget", "60", "--until", "budget"]
    for d in ("a", "b"):
        assert main([*args, "--seed", "3", "--out", str(tmp_path / d)]) == 0
    assert main([*args, "--seed", "4", "--out", str(tmp_path / "c")]) == 0
    capsys.readouterr()
    a, b, c = ((tmp_path / d / "result.json").read_bytes() for d in "abc")
    assert a == b
    ra, rc = json.loads(a), json.loads(c)
    assert ra["episodes"] == rc["episodes"] == 60
    assert ra["risk_per_episode"] != rc["risk_per_episode"]


@pytest.mark.parametrize("searcher", ["random", "mcts", "mcts-commit"])
def test_until_budget_records_every_hazard(sims, searcher) -> None:
    res = search(sims["s3-fence-gap"], searcher, budget=200, seed=0, until="budget")
    assert res.episodes == 200 == len(res.risk_per_episode)
    assert len(res.hazards) > 1
    assert res.hazard.episode == res.hazards[0].episode
    first = search(sims["s3-fence-gap"], searcher, budget=200, seed=0)
    assert first.episodes == res.hazards[0].episode
    assert first.risk_per_episode == res.risk_per_episode[:first.episodes]
    for h in res.hazards[:5]:
        assert sims["s3-fence-gap"].run(h.actions).unsafe


@pytest.mark.parametrize("budget", [1, 13, 77])
def test_budget_is_exact_on_a_safe_cell(budget) -> None:
    for searcher in ("random", "mcts", "mcts-commit"):
        res = search("baseline", searcher, budget=budget, seed=1)
        assert not res.found and res.hazard is None
        assert res.episodes == budget == len(res.risk_per_episode)


def test_random_batch_and_stepping_agree(sims) -> None:
    """The random searcher plays chunks with run_batch; stepping the same episodes gives the same outcome."""
    from cellstress.sim.simulator import Simulator

    sim = Simulator("s2-deceptive")  # seed 5 finds its hazard within 300 episodes

    class Stepping:  # the simulator without its BatchSimulator ability
        def __init__(self):
            self.n_actions, self.actions_per_episode = sim.n_actions, sim.actions_per_episode
            self.reset, self.step, self.is_unsafe = sim.reset, sim.step, sim.is_unsafe
            self.measures, self.run = sim.measures, sim.run

    assert isinstance(sim, BatchSimulator) and not isinstance(Stepping(), BatchSimulator)
    reward = sim.criterion.reward(sim.actions_per_episode)
    a = run_search(sim, reward, "random", 300, 5, until="budget", chunk=64)
    b = run_search(Stepping(), reward, "random", 300, 5, until="budget", chunk=64)
    assert a == b and a.found


def test_public_api(sims) -> None:
    res = cellstress.search(sims["s3-fence-gap"], searcher="random", budget=20, seed=0, chunk=16)
    assert isinstance(res, SearchResult) and res.searcher == "random" and res.params == {"chunk": 16}
    assert res.episodes <= 20
