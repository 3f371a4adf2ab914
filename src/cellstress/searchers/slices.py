"""Distinct mode for whole-episode searchers (``evolve`` or ``plan`` with ``--until budget --distinct``): the
budget shared between the start points in slices, a fresh search in each slice, hazards of known classes worthless
(to ``evolve``, which has the hook).

Why not one search over all start points: a searcher that picks the start with the first decision (``mcts``
over ``MultiStartProblem``) commits to the start point whose episodes first pay and rarely returns to the others
(docs/results.md, "Distinct hazards on all-flaws"). Here the start is not a decision of the searcher:

* **Slices.** The search is a sequence of slices. A slice is a fresh run of the searcher (e.g. ``Evolve``) on
  *one* start point's problem (the worker's 8 actions from that start) for at most ``slice_len`` episodes; it
  ends early when it finds a hazard of a class not found before (classes: ``search.distinct``).
* **Which start next.** Each slice goes to the start point with the fewest classes found so far; ties go to the
  start that has played the fewest episodes, then to the cell's order. So the budget flows to the start points
  where nothing has been found yet, and a start point whose hazards are known gets more only when the others
  have as many classes.
* **Novelty inside a slice.** A hazard of a class already found (from any start) is worthless to the searcher:
  the problem's ``known_hazard(actions)`` says so, and ``evolve`` scores such an episode -inf (never a parent),
  so a restarted search does not climb back to it. Rediscoveries still count as hazardous episodes.

Measured on ``all-flaws`` (docs/results.md): all three flaws in one run of 1,000 episodes for 50 of 50 seeds;
the slices and the schedule do that (slices of 50 to 1,000 episodes all give 40/40 on seeds 0-39); the novelty
scoring only lowers the rediscoveries (34 instead of 40 hazardous episodes per run).

Every episode is recorded as ``MultiStartProblem`` records it (first decision = start index, then the worker's
actions; ``start:NAME`` in the result), with the first decision's reward and risk added, so that returns and
replays are the same as in the tree searchers' multi-start episodes. A cell without ``human.starts`` is one
start point with no leading decision.

Randomness: slice n runs the searcher with the seed ``SeedSequence(seed, spawn_key=(SLICE_KEY, n))`` draws
(its first 32-bit word), so a result depends only on (cell, searcher options, seed, budget).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.core.protocols import StartChoices
from cellstress.searchers.common import Outcome, Recorder, Stop
from cellstress.searchers.distinct import hazard_class
from cellstress.searchers.multistart import ArrivalProblem, PhaseProblem

SLICE_KEY = 7
SLICE_LEN = 200  # evolve finds S2, the hardest single flaw, within 200 episodes in 166 of 200 seeds (results.md)


class SliceOver(Exception):  # noqa: N818 (a signal, like Stop)
    """Raised inside a slice when it has used its episodes or found a new class."""


@dataclass(frozen=True)
class Start:
    """One start point as the slices see it: its problem (with ``class_of(actions)``), the decisions recorded
    before the worker's actions, and that prefix's reward and risk."""

    problem: object
    prefix: tuple[int, ...] = ()
    ret0: float = 0.0
    risk0: float = 0.0
    # a start point whose problem chooses the phase first (a PhaseProblem): (its index, the number of starts),
    # so that its first decision j is recorded as the whole cell's first decision index + starts * j
    phased: tuple[int, int] | None = None

    def recorded(self, actions: tuple[int, ...]) -> tuple[int, ...]:
        """A slice's episode as the whole cell's ``ArrivalProblem`` records it."""
        if self.phased is None:
            return (*self.prefix, *actions)
        i, m = self.phased
        return (i + m * (actions[0] % self.problem.n_choices), *actions[1:])


class CellStart:
    """A start point's simulator as the searchers see it (every ability of the simulator: attributes are looked up
    on it), with the class of an unsafe episode (``class_of``) and, during ``run_slices``, the novelty hook
    ``known_hazard`` (``core.protocols.NoveltyAware``)."""

    def __init__(self, sim, known: dict | None = None):
        self.sim = sim
        self._classes: dict[tuple[int, ...], tuple] = {}
        self._known = {} if known is None else known

    def __getattr__(self, name: str):
        return getattr(self.sim, name)

    def known_hazard(self, actions) -> bool:
        """The unsafe episode ``actions`` is of a class already found (in this run, from any start)."""
        return self.class_of(actions) in self._known

    def class_of(self, actions) -> tuple:
        """The hazard class of an unsafe episode (replayed from s0; remembered per action sequence)."""
        key = tuple(int(a) for a in actions)
        cls = self._classes.get(key)
        if cls is None:
            sim, acts = self.sim, key
            if isinstance(sim, StartChoices):  # the first decision picks the arrival: replay in its simulator
                sim, acts = sim.simulator(key[0]), key[1:]
            state = sim.reset()
            for a in acts:
                state, rows = sim.step(state, a)
                if sim.is_unsafe(state):
                    break
            else:
                raise ValueError(f"not an unsafe episode: {key}")
            cls = self._classes[key] = hazard_class(sim, state, rows[-1])
        return cls


def cell_starts(problem, reward) -> list[Start]:
    """The start points of a cell's problem: a ``MultiStartProblem`` (one per ``human.starts`` entry, with
    its first decision's reward) or a ``SimProblem`` (one start, no prefix)."""
    if not isinstance(problem, ArrivalProblem):
        return [Start(CellStart(problem))]
    if not problem.starts:  # one start point: its problem chooses the phase (a PhaseProblem)
        return [Start(CellStart(problem))]
    if problem.n_phases > 1:  # each start point's slices choose its phase themselves
        return [Start(CellStart(PhaseProblem(problem.sim, i)), phased=(i, problem.m)) for i in range(problem.m)]
    out = []
    for i, sim in enumerate(problem.sims):
        _, rows = problem.step(problem.reset(), i)  # the first decision, exactly as MultiStartProblem plays it
        r, risk = reward(problem.measures(rows), problem.actions_per_episode == 1, False)
        out.append(Start(CellStart(sim), (i,), float(r), float(risk)))
    return out


class ClassRecorder(Recorder):
    """A ``Recorder`` that also keeps the first episode of each hazard class, in the order found
    (``classes``: class -> (episode, recorded actions)), and the classes found from each start."""

    def __init__(self, *args, n_starts: int = 1, **kwargs):
        super().__init__(*args, **kwargs)
        self.classes: dict[tuple, tuple[int, tuple[int, ...]]] = {}
        self.per_start = [0] * n_starts
        self.spent = [0] * n_starts


class _Slice:
    """The recorder a searcher sees during one slice: counts against the budget and the slice."""

    def __init__(self, rec: ClassRecorder, start: Start, index: int, limit: int):
        self.rec, self.start, self.index, self.limit = rec, start, index, limit
        self.used = 0

    @property
    def left(self) -> int:
        return min(self.rec.left, self.limit - self.used)

    def finish(self, actions, ret: float, risk: float, unsafe: bool):
        rec, st = self.rec, self.start
        if self.used >= self.limit:
            raise SliceOver
        if rec.episodes >= rec.budget:
            raise Stop
        acts = tuple(int(a) for a in actions)
        recorded = st.recorded(acts)
        new = False
        if unsafe:
            cls = st.problem.class_of(acts)
            if cls not in rec.classes:
                new = True
                rec.classes[cls] = (rec.episodes + 1, recorded)
                rec.per_start[self.index] += 1
        self.used += 1
        rec.spent[self.index] += 1
        ep = rec.finish(recorded, ret + st.ret0, max(risk, st.risk0), unsafe)  # raises Stop at the end
        if new:
            raise SliceOver
        return ep


def next_start(rec: ClassRecorder) -> int:
    """The start with the fewest classes found, then the fewest episodes played, then the first."""
    return min(range(len(rec.spent)), key=lambda i: (rec.per_start[i], rec.spent[i], i))


def run_slices(searcher, starts: list[Start], reward, rec: ClassRecorder, seed: int,
               slice_len: int = SLICE_LEN) -> Outcome:
    """Play the whole budget in slices (see the module docstring); ``rec`` must have one entry per start."""
    if len(rec.spent) != len(starts):
        raise ValueError("the recorder needs n_starts = len(starts)")
    for st in starts:  # the searcher's novelty hook (``evolve``): a class already found is worth nothing
        st.problem._known = rec.classes
    n = 0
    try:
        while True:
            i = next_start(rec)
            s = int(np.random.SeedSequence(int(seed), spawn_key=(SLICE_KEY, n)).generate_state(1)[0])
            n += 1
            sl = _Slice(rec, starts[i], i, slice_len)
            try:
                searcher.run(starts[i].problem, reward, sl, s)
            except SliceOver:
                continue
            if sl.used == 0:  # a searcher that returns without playing would loop for ever
                break
    except Stop:
        pass
    return Outcome(rec.episodes, tuple(rec.hazards), tuple(rec.top.best()), tuple(rec.risks),
                   rec.distinct_sequences)
