"""Distinct mode with slices (``evolve --until budget --distinct``): the budget shared between start points,
each class reported once, known classes worthless to the searcher; per-start robot phases; determinism."""

from __future__ import annotations

import copy
from importlib import resources

import numpy as np
import pytest
import yaml
from toywalk import ToyWalk

from cellstress.criteria.contact import ContactWhileMoving
from cellstress.human.actions import action_index
from cellstress.searchers import run_search, search
from cellstress.searchers.evolve import Evolve
from cellstress.searchers.multistart import MultiStartProblem
from cellstress.searchers.slices import ClassRecorder, Start, run_slices
from cellstress.sim.simulator import Simulator
from cellstress.sim.starts import start_simulator

REWARD = ContactWhileMoving().reward(8)


class ForkWalk(ToyWalk):
    """ToyWalk whose last step accepts any of ``last`` (one hazard class per accepted action)."""

    def __init__(self, secret, last, name):
        super().__init__(secret=(*secret, -1), n_actions=6, horizon=8)
        self.last, self.name = tuple(last), name
        self.known_calls = 0

    def step(self, state, action):
        x, unsafe = state
        if not unsafe and x == len(self.secret) - 1 and action in self.last:
            self.steps += 1
            return (x + 1, True), np.array([[0.0, 1.0]])
        return super().step(state, action)

    def class_of(self, actions):
        assert self.is_unsafe(self.play(actions))
        return (self.name, int(actions[-1]))

    def play(self, actions):
        s = self.reset()
        for a in actions:
            s, _ = self.step(s, a)
        return s


def toy_starts(n_unreachable: int = 0):
    walks = [ForkWalk((3, 1, 4), (5, 0), "a"), ForkWalk((2, 2, 0, 1), (4, 3), "b"),
             ForkWalk((0, 5), (1, 2), "c")]
    # a start point with no hazard within the horizon (its secret is longer than 8 actions)
    walks += [ForkWalk((1,) * 9, (0,), f"never{i}") for i in range(n_unreachable)]
    return [Start(w, (i,)) for i, w in enumerate(walks)]


def run_toy(budget, seed, starts, slice_len=100):
    rec = ClassRecorder(budget, "budget", 5, None, n_starts=len(starts))
    out = run_slices(Evolve(), starts, REWARD, rec, seed, slice_len)
    return out, rec


def test_slices_find_the_classes_of_every_start_and_report_each_once():
    starts = toy_starts()
    out, rec = run_toy(1500, 0, starts)
    assert out.episodes == 1500 and sum(rec.spent) == 1500
    names = {k[0] for k in rec.classes}
    assert names == {"a", "b", "c"}
    assert len(rec.classes) == 6  # both ways to the end of each walk
    assert rec.per_start == [2, 2, 2]
    # each class listed once, at the first hazardous episode of that class, with its start as first decision
    first: dict = {}
    for h in out.hazards:
        st = starts[h.actions[0]]
        first.setdefault(st.problem.class_of(h.actions[1:]), h.index)
    assert {k: v[0] for k, v in rec.classes.items()} == first
    assert [v[0] for v in rec.classes.values()] == sorted(first.values())


def test_evolve_never_breeds_from_a_known_hazard():
    """The hook: a hazard whose class is known scores -inf, so evolve stops mutating around it."""
    def hazards(known):
        found = 0
        for seed in range(3):
            walk = ForkWalk((3, 1, 4), (5, 0), "a")
            if known:
                walk.known_hazard = lambda actions: True
            found += len(run_search(walk, REWARD, "evolve", 1500, seed, until="budget").hazards)
        return found

    plain, worthless = hazards(False), hazards(True)
    assert plain > 300 and worthless < plain / 2  # measured: 402 against 174 (seeds 0-2)


def test_budget_flows_to_the_start_points_without_a_hazard():
    starts = toy_starts(n_unreachable=1)
    out, rec = run_toy(1000, 1, starts, slice_len=100)
    assert rec.per_start[3] == 0 and rec.per_start[:3] == [1, 1, 1]
    # every start got a slice; once the three walks had a class each, every episode went to the fourth start
    # (measured: spent 170 / 74 / 30 / 726 episodes, classes at episodes 174, 204 and 374)
    last = max(ep for ep, _ in rec.classes.values())
    assert min(rec.spent) > 0 and sum(rec.spent) == 1000
    assert rec.spent[3] >= 1000 - last and rec.spent[3] == max(rec.spent)
    # each walk's first class came within its first three slices of 100 episodes
    assert all(s <= 300 for s in rec.spent[:3])
    # the first slice goes to the first start: it found the first class or spent a whole slice
    assert [h.actions[0] for h in out.hazards][0] == 0 or rec.spent[0] >= 100


def test_slices_are_a_pure_function_of_the_seed():
    a, ra = run_toy(600, 3, toy_starts())
    b, rb = run_toy(600, 3, toy_starts())
    c, _ = run_toy(600, 4, toy_starts())
    assert a == b and ra.classes == rb.classes and ra.spent == rb.spent
    assert a.risks != c.risks


# ---- the all-flaws cell ------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def af():
    return Simulator("all-flaws")


def test_start_points_carry_their_robot_phase(af, tmp_path):
    starts = {s.name: s for s in af.cell.spec.human.starts}
    assert starts["upper-end"].phase == 4.75 and starts["lower-end"].phase is None
    assert start_simulator(af, starts["lower-end"]).phase == af.phase == 2.75
    up = start_simulator(af, starts["upper-end"])
    assert up.phase == 4.75 and af.phase == 2.75  # the cell's simulator is unchanged
    # a start's phase is exactly the cell with that robot phase and that start pose
    doc = yaml.safe_load(resources.files("cellstress.cell").joinpath("builtin", "all-flaws.yaml").read_text())
    one = copy.deepcopy(doc)
    one["robot"]["task"]["phase"] = 4.75
    one["human"]["start"] = {"xy": [0.7, 3.35], "heading_deg": -90.0}
    del one["human"]["starts"]
    path = tmp_path / "upper.yaml"
    path.write_text(yaml.safe_dump(one), encoding="utf-8")
    ref = Simulator(path)
    acts = np.random.default_rng(5).integers(0, 30, (300, 8))
    a, b = up.run_batch(acts), ref.run_batch(acts)
    assert np.array_equal(a.unsafe_step, b.unsafe_step) and np.array_equal(a.min_d, b.min_d)
    seq = ["walk+bend-forward", "walk+bend-forward", "walk+bend-forward-left", "walk+bend-forward-left",
           "walk+bend-forward-left"]
    trace = af.run(["start:upper-end", *seq])
    assert np.array_equal(trace.rows, ref.run(seq).rows)
    assert trace.unsafe  # the S1 hazard from the upper end at that phase (evolve --distinct, seed 0)
    # and the multi-start problem plays the same episode (the tree searchers' view)
    p = MultiStartProblem(af)
    state, rows = p.step(p.reset(), 0)
    parts = [rows]
    for a in seq:
        state, r = p.step(state, action_index(a))
        parts.append(r)
    assert np.array_equal(np.concatenate(parts), trace.rows)


def test_evolve_distinct_on_all_flaws_finds_all_three_flaws_and_replays(af):
    res = search(af, "evolve", 700, 0, until="budget", distinct=True)
    again = search(af, "evolve", 700, 0, until="budget", distinct=True)
    assert res.to_json() == again.to_json()
    found = {(d.actions[0], d.klass.device) for d in res.distinct}
    assert {("start:upper-end", "front-scanner"), ("start:lower-end", "bay-curtain"),
            ("start:lower-end-right", "none")} <= found
    keys = [tuple(map(str, d.klass.model_dump().values())) for d in res.distinct]
    assert len(set(keys)) == len(keys)
    for d in res.distinct:
        trace = af.run(d.actions)
        assert trace.unsafe and trace.records() == d.trace
    assert res.episodes == 700 and res.hazard.episode == min(d.episode for d in res.distinct)  # (listed worst first)


def test_plain_evolve_is_unchanged_by_the_hook(af):
    """Without --distinct evolve runs as before: one search over the multi-start problem."""
    res = search(af, "evolve", 120, 2, until="budget")
    assert res.distinct is None and all(t.actions[0].startswith("start:") for t in res.top)
