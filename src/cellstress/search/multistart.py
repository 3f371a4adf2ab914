"""Several start points: an episode's first decision picks one (``human.starts`` in the cell file).

``MultiStartProblem`` wraps the cell simulator: its state is (start index, simulator state), -1 before the first
decision; the first decision ``a`` picks start ``a % m`` (with 30 actions and 2, 3, 5 or 6 starts a uniform
action is a uniform start), later decisions are the worker's actions. An episode is then 1 + 8 decisions, and
the recorded action sequence begins with the start, written ``start:NAME``, so that ``Simulator.run`` (and
``cellstress replay``) play exactly the same episode. The tree searchers widen the root over the m starts only
(``choices``).
"""

from __future__ import annotations

START_PREFIX = "start:"


class MultiStartProblem:
    def __init__(self, sim):
        from cellstress.search.common import SimProblem

        self.sim = sim
        self.starts = sim.cell.spec.human.starts
        self.sims = [start_sim(sim, s) for s in self.starts]
        self.inner = [SimProblem(s) for s in self.sims]
        self.n_actions = sim.n_actions
        self.actions_per_episode = 1 + sim.actions_per_episode
        self.metrics = self.inner[0].metrics  # the same layout and criterion for every start

    def choices(self, depth: int) -> int:
        return len(self.sims) if depth == 0 else self.n_actions

    def reset(self):
        return (-1, None)

    def step(self, state, action: int):
        i, s = state
        if i < 0:
            j = int(action) % len(self.sims)
            return (j, self.sims[j].reset()), self.sims[j].initial_metrics()[None, :]
        nxt, rows = self.inner[i].step(s, action)
        return (i, nxt), rows

    def is_unsafe(self, state) -> bool:
        return state[0] >= 0 and self.sims[0].is_unsafe(state[1])

    def names(self, actions) -> list[str]:
        """Recorded decisions as names: ``start:NAME`` and then the worker's actions."""
        from cellstress.human.actions import ACTION_NAMES

        acts = list(actions)
        if not acts:
            return []
        return [START_PREFIX + self.starts[int(acts[0]) % len(self.sims)].name,
                *(ACTION_NAMES[int(a)] for a in acts[1:])]


def start_sim(sim, start):
    """The simulator of one ``human.starts`` entry: its pose and, if it has one, its own robot phase."""
    return sim.with_start((start.xy[0], start.xy[1], start.heading_deg), start.phase)


def split_start(sim, actions):
    """(simulator for the leading ``start:NAME`` of ``actions`` or ``sim`` itself, the remaining actions)."""
    acts = list(actions)
    if not acts or not isinstance(acts[0], str) or not acts[0].startswith(START_PREFIX):
        return sim, acts
    from cellstress.errors import ActionError

    name = acts[0][len(START_PREFIX):]
    for s in sim.cell.spec.human.starts:
        if s.name == name:
            return start_sim(sim, s), acts[1:]
    known = ", ".join(s.name for s in sim.cell.spec.human.starts) or "none"
    raise ActionError(f"unknown start {name!r} (the cell's starts: {known})")
