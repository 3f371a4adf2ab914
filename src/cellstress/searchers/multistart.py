"""Several start points: an episode's first decision picks one (``human.starts`` in the cell file).

``MultiStartProblem`` wraps the cell simulator: its state is (start index, simulator state), -1 before the first
decision; the first decision ``a`` picks start ``a % m`` (with 30 actions and 2, 3, 5 or 6 starts a uniform
action is a uniform start), later decisions are the worker's actions. An episode is then 1 + 8 decisions, and
the recorded action sequence begins with the start, written ``start:NAME``, so that ``Simulator.run`` (and
``cellstress replay``) play exactly the same episode. The tree searchers widen the root over the m starts only
(``choices``: the ``core.protocols.StartChoices`` ability).
"""

from __future__ import annotations

from cellstress.human.actions import ACTION_NAMES
from cellstress.sim.starts import START_PREFIX, start_simulator


class MultiStartProblem:
    def __init__(self, sim):
        self.sim = sim
        self.starts = sim.cell.spec.human.starts
        self.sims = [start_simulator(sim, s) for s in self.starts]
        self.n_actions = sim.n_actions
        self.actions_per_episode = 1 + sim.actions_per_episode
        self.measures = self.sims[0].measures  # the same layout and criterion for every start

    def choices(self, depth: int) -> int:
        return len(self.sims) if depth == 0 else self.n_actions

    def reset(self):
        return (-1, None)

    def step(self, state, action: int):
        i, s = state
        if i < 0:
            j = int(action) % len(self.sims)
            return (j, self.sims[j].reset()), self.sims[j].initial_metrics()[None, :]
        nxt, rows = self.sims[i].step(s, action)
        return (i, nxt), rows

    def is_unsafe(self, state) -> bool:
        return state[0] >= 0 and self.sims[0].is_unsafe(state[1])

    def run(self, actions):
        """The trace of a recorded episode (its first decision written ``start:NAME`` or as an index)."""
        return self.sim.run(self.names(actions) if actions and not isinstance(actions[0], str) else actions)

    def names(self, actions) -> list[str]:
        """Recorded decisions as names: ``start:NAME`` and then the worker's actions."""
        acts = list(actions)
        if not acts:
            return []
        return [START_PREFIX + self.starts[int(acts[0]) % len(self.sims)].name,
                *(ACTION_NAMES[int(a)] for a in acts[1:])]
