"""The searchers on a toy 1-D walk: MCTS beats random, budgets are exact, seeds decide, top-k and until."""

from __future__ import annotations

import statistics

import pytest
from toywalk import ToyWalk

from cellstress.core.records import Measures
from cellstress.criteria.contact import ContactWhileMoving
from cellstress.searchers import SearchError, make_searcher, run_search, searcher_class, searcher_names
from cellstress.searchers.common import Recorder
from cellstress.searchers.tree import Tree

REWARD = ContactWhileMoving().reward(8)
SEEDS = range(15)
# every searcher whose needs the toy meets (plan needs a cell's worker model: its tests are test_search_plan.py)
TOY_SEARCHERS = [name for name in searcher_names()
                 if all(isinstance(ToyWalk(), need) for need in searcher_class(name).needs)]


def episodes_to_hazard(searcher: str, seed: int, budget: int, **options) -> int:
    out = run_search(ToyWalk(), REWARD, searcher, budget, seed, **options)
    return out.first_hazard.index if out.found else budget


def test_toy_reward_is_the_papers() -> None:
    # d = 5 m, v = 1 m/s: c_S = 26 / e
    r, risk = REWARD(Measures(5.0, 1.0), False, False)
    assert r == pytest.approx(2.718281828 / 26) and risk == r
    r, _ = REWARD(Measures(5.0, 1.0), True, False)
    assert r == pytest.approx(-26 / 2.718281828)
    r, _ = REWARD(Measures(5.0, 0.0), True, False)  # far away at the end: about -26
    r, risk = REWARD(Measures(0.0, 1.0), True, True)  # an unsafe end is rewarded like any step (no bonus)
    assert r == pytest.approx(2.718281828) and risk == r


def test_mcts_finds_the_narrow_sequence_much_faster_than_random() -> None:
    budget = 3000
    rnd = [episodes_to_hazard("random", s, budget) for s in SEEDS]
    mcts = [episodes_to_hazard("mcts", s, budget) for s in SEEDS]
    commit = [episodes_to_hazard("mcts-commit", s, budget, n=40) for s in SEEDS]  # commits every 40
    # random needs about 5 right actions in a row (p ~ 6**-5 each time): a median near 1000 episodes
    assert statistics.median(rnd) > 600
    assert statistics.median(mcts) * 5 < statistics.median(rnd)
    assert statistics.median(commit) * 5 < statistics.median(rnd)
    assert max(mcts) < 300 and max(commit) < 300


@pytest.mark.parametrize("searcher", TOY_SEARCHERS)
@pytest.mark.parametrize("budget", [1, 7, 64, 301])
def test_budget_is_exact(searcher: str, budget: int) -> None:
    toy = ToyWalk(secret=(1,) * 9)  # longer than the horizon: never unsafe, so the whole budget is used
    out = run_search(toy, REWARD, searcher, budget, 0)
    assert out.episodes == budget and len(out.risks) == budget and not out.found
    assert toy.steps <= budget * toy.actions_per_episode
    if searcher == "random":
        assert toy.steps == budget * toy.actions_per_episode


@pytest.mark.parametrize("searcher", TOY_SEARCHERS)
def test_same_seed_same_search_other_seed_other_search(searcher: str) -> None:
    a = run_search(ToyWalk(), REWARD, searcher, 400, 3, until="budget")
    b = run_search(ToyWalk(), REWARD, searcher, 400, 3, until="budget")
    c = run_search(ToyWalk(), REWARD, searcher, 400, 4, until="budget")
    assert a == b
    assert a.risks != c.risks


def test_until_first_stops_at_the_hazard_and_budget_records_all() -> None:
    first = run_search(ToyWalk(), REWARD, "mcts", 2000, 0)
    assert first.found and first.episodes == first.first_hazard.index == len(first.risks)
    assert [h.index for h in first.hazards] == [first.episodes]
    every = run_search(ToyWalk(), REWARD, "mcts", 2000, 0, until="budget")
    assert every.episodes == 2000
    assert every.hazards[0] == first.first_hazard  # the same search up to the first hazard
    assert len(every.hazards) > 10
    for h in every.hazards:  # each recorded hazard replays to the unsafe state at its last action
        toy, state = ToyWalk(), (0, False)
        for a in h.actions:
            assert not toy.is_unsafe(state)
            state, _ = toy.step(state, a)
        assert h.unsafe and toy.is_unsafe(state)
    assert len({h.actions for h in every.hazards}) > 1
    assert every.risks[:first.episodes] == first.risks


def test_top_k_holds_the_best_distinct_sequences() -> None:
    out = run_search(ToyWalk(), REWARD, "random", 500, 1, until="budget", top_k=5)
    assert len(out.top) == 5
    assert len({e.actions for e in out.top}) == 5
    rets = [e.ret for e in out.top]
    assert rets == sorted(rets, reverse=True)
    assert out.top[0].risk == pytest.approx(max(out.risks)) or rets[0] >= max(e.ret for e in out.top)


def test_risk_is_the_max_inverse_safety_index() -> None:
    out = run_search(ToyWalk(), REWARD, "random", 50, 0, until="budget", top_k=50)
    for e in out.top:
        x, best = 0, 0
        for a in e.actions:  # replay the toy by hand
            x = x + 1 if a == (3, 1, 4, 1, 5)[x] else 0
            best = max(best, x)
        assert e.risk == pytest.approx(2.718281828459045 / ((0.25 * (5 - best)) ** 2 + 1))


def test_widening_draws_untried_actions_and_respects_the_bound() -> None:
    toy = ToyWalk(secret=(1,) * 9, n_actions=30)
    rec = Recorder(500, "budget")
    tree = Tree(toy, REWARD, rec, seed=0, ec=0.5, k=0.5, alpha=0.85)
    for _ in range(500):
        try:
            tree.iterate(tree.root, 0.0, 0.0)
        except Exception:
            break
    root = tree.root
    assert len(root.edges) == len(set(root.edges)) <= 30
    assert len(root.edges) <= 0.5 * root.n ** 0.85 + 1
    assert sorted(root.edges) == sorted(set(range(30)) - set(root.untried))
    assert sum(e.n for e in root.edges.values()) == root.n == 500


@pytest.mark.parametrize("bad", [dict(budget=0), dict(budget=-3), dict(seed=-1), dict(until="forever"),
                                 dict(searcher="annealing"), dict(searcher="mcts", ec=-1.0),
                                 dict(searcher="mcts", k=0.0), dict(searcher="mcts-commit", n=0),
                                 dict(searcher="random", ec=1.0), dict(budget=2.5)])
def test_bad_options_raise_search_error(bad) -> None:
    kw = dict(searcher="mcts", budget=10, seed=0) | bad
    with pytest.raises(SearchError):
        run_search(ToyWalk(), REWARD, **kw)


def test_default_options_are_documented() -> None:
    m = make_searcher("mcts")
    assert (m.ec, m.k, m.alpha) == (0.5, 1.0, 0.85)
    c = make_searcher("mcts-commit")
    assert c.n is None and c.iterations(200, 8) == [25] * 8 and c.iterations(203, 8) == [26] * 3 + [25] * 5
