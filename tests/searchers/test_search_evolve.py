"""The improved searcher ``evolve`` (not the paper's): beats random on the toy walk in milliseconds, is a pure
function of its seed, checks its options, and writes byte-identical results on a cell."""

from __future__ import annotations

import statistics
import time

import pytest
from toywalk import ToyWalk

from cellstress.cli import main
from cellstress.criteria.contact import ContactWhileMoving
from cellstress.searchers import SearchError, run_search, searcher_class
from cellstress.searchers.evolve import Evolve

REWARD = ContactWhileMoving().reward(8)
SEEDS = range(15)


def episodes_to_hazard(searcher: str, seed: int, budget: int, **options) -> int:
    out = run_search(ToyWalk(), REWARD, searcher, budget, seed, **options)
    return out.first_hazard.index if out.found else budget


def test_registered_for_the_campaign() -> None:
    assert searcher_class("evolve") is Evolve
    assert Evolve().name == "evolve"


def test_evolve_beats_random_on_the_toy_walk_in_milliseconds() -> None:
    budget = 3000
    rnd = [episodes_to_hazard("random", s, budget) for s in SEEDS]
    t0 = time.perf_counter()
    evo = [episodes_to_hazard("evolve", s, budget) for s in SEEDS]
    spent = time.perf_counter() - t0
    # random needs about 5 right actions in a row (p ~ 6**-5 per episode): a median near 1000 episodes
    assert statistics.median(rnd) > 600
    assert statistics.median(evo) * 5 < statistics.median(rnd)  # measured: 117 against 977
    assert max(evo) < 1500  # measured 1039: the restart after 100 episodes without progress
    # without restarts, hill climbing can stall for good on this walk
    stalled = [episodes_to_hazard("evolve", s, budget, patience=0) for s in SEEDS]
    assert budget in stalled
    assert spent < 2.0  # 15 searches; a few ms each


def test_evolve_options_still_beat_random() -> None:
    # on the toy the scores coincide (no stop phase: "running" falls back to the risk); restarts hurt here
    for options in ({"score": "risk"}, {"patience": 20}, {"sticky": 0.0, "keep_tail": 0.0}):
        evo = [episodes_to_hazard("evolve", s, 3000, **options) for s in SEEDS]
        assert statistics.median(evo) < 500, options


def test_same_seed_same_search() -> None:
    a = run_search(ToyWalk(), REWARD, "evolve", 300, 4, until="budget")
    b = run_search(ToyWalk(), REWARD, "evolve", 300, 4, until="budget")
    c = run_search(ToyWalk(), REWARD, "evolve", 300, 5, until="budget")
    assert a == b
    assert a.risks != c.risks
    assert a.episodes == 300 and len(a.hazards) > 1  # keeps searching around the hazard until the budget


def test_no_episode_is_played_twice_before_a_hazard() -> None:
    toy = ToyWalk(secret=(1,) * 9)  # never unsafe within the horizon
    for seed in range(5):
        out = run_search(toy, REWARD, "evolve", 200, seed, top_k=200)
        assert len(out.top) == 200, seed  # TopK keeps one entry per distinct action sequence
    # the very sticky start too (its episodes are often constant sequences): measured 182 of 200 before the fix
    out = run_search(toy, REWARD, "evolve", 200, 0, top_k=200, n_init=30, init_sticky=0.95)
    assert len(out.top) == 200


def test_score_names() -> None:
    assert Evolve().uses == (0, 1)  # "both": running + risk
    assert Evolve(score="all").uses == (0, 1, 2)
    assert Evolve(score="lookahead+risk").uses == (1, 2)
    assert Evolve(score="running").uses == (0,)


def test_lookahead_falls_back_to_the_risk_on_the_toy() -> None:
    # the toy has no lookahead: the score "lookahead" is then the risk, and the search is the same
    a = run_search(ToyWalk(), REWARD, "evolve", 300, 2, until="budget", score="lookahead")
    b = run_search(ToyWalk(), REWARD, "evolve", 300, 2, until="budget", score="risk")
    assert a == b and len(a.hazards) > 1


def test_focus_still_beats_random() -> None:
    evo = [episodes_to_hazard("evolve", s, 3000, focus=0.5) for s in SEEDS]
    assert statistics.median(evo) < 500


def test_lookahead_search_on_a_cell_is_a_pure_function_of_its_seed() -> None:
    from cellstress.sim.simulator import Simulator

    sim = Simulator("s2-elbow-intrusion")
    reward = sim.criterion.reward(sim.actions_per_episode)
    runs = [run_search(sim, reward, "evolve", 40, seed, until="budget", score="all")
            for seed in (1, 1, 2)]
    plain = run_search(sim, reward, "evolve", 40, 1, until="budget")
    assert runs[0] == runs[1]
    assert runs[0].risks != runs[2].risks
    assert runs[0].episodes == 40 and len(runs[0].top) == 10
    # the third ranking changes which parents are mutated (the first n_init random episodes are shared)
    n = Evolve().n_init
    assert runs[0].risks[:n] == plain.risks[:n] and runs[0].risks != plain.risks


def test_init_sticky_shapes_only_the_start() -> None:
    toy = ToyWalk(secret=(1,) * 9)  # never unsafe within the horizon: every episode is kept in the top list
    out = run_search(toy, REWARD, "evolve", 40, 0, top_k=40, until="budget", init_sticky=1.0, n_init=8)
    start = [ep.actions for ep in out.top if ep.index <= 8]
    later = [ep.actions for ep in out.top if ep.index > 8]
    # (the top list keeps one entry per distinct sequence, and only 6 sequences are constant)
    assert len(start) >= 3 and len(later) >= 20
    assert all(len(set(a)) == 1 for a in start), start  # the start: each action repeats the first
    assert sum(len(set(a)) > 2 for a in later) > 10  # mutations draw with sticky = 0.3
    # None means "as sticky" (0.3 by default)
    assert run_search(ToyWalk(), REWARD, "evolve", 300, 3, until="budget", init_sticky=0.3) == \
        run_search(ToyWalk(), REWARD, "evolve", 300, 3, until="budget", init_sticky=None)
    assert Evolve().init_sticky == 0.9 and Evolve().sticky == 0.3


@pytest.mark.parametrize("options", [{"n_init": 0}, {"pool": 1.5}, {"keep_tail": 1.5}, {"sticky": -0.1},
                                     {"score": "distance"}, {"patience": -1}, {"n_init": True},
                                     {"score": "risk+risk"}, {"score": "risk+"}, {"score": 3}, {"focus": 1.5},
                                     {"horizon": -0.1}, {"speed": -1.0}, {"speed": float("inf")},
                                     {"horizon": True}, {"init_sticky": 1.5}, {"init_sticky": "high"},
                                     {"init_sticky": True}])
def test_bad_options(options) -> None:
    with pytest.raises(SearchError):
        Evolve(**options)


def test_result_file_is_byte_identical(tmp_path, capsys) -> None:
    args = ["search", "s3-fence-gap", "--searcher", "evolve", "--budget", "40", "--until", "budget",
            "--no-report"]
    for d in ("a", "b"):
        assert main([*args, "--seed", "3", "--out", str(tmp_path / d)]) == 0
    capsys.readouterr()
    assert (tmp_path / "a" / "result.json").read_bytes() == (tmp_path / "b" / "result.json").read_bytes()
