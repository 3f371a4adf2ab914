"""Random search (the paper's baseline): every action uniform over the action set, a full episode each.

Actions come from one numpy Generator (``SeedSequence(seed, spawn_key=(2,))``), one row of
``actions_per_episode`` draws per episode. If the problem can play many episodes at once (``run_batch``,
the cell simulator on all cores) the episodes are played in chunks; the outcome is the same as stepping
them one by one (the simulator's determinism check covers this), only faster.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from cellstress.core.protocols import BatchSimulator
from cellstress.core.records import Measures
from cellstress.searchers.common import Recorder, first_range, rollout, whole

RANDOM_KEY = 2


@dataclass(frozen=True)
class RandomSearch:
    """Options of ``random``: ``chunk`` = episodes drawn (and, with ``run_batch``, played) at a time.

    A chunk's actions are always drawn whole, so the episodes do not depend on the budget."""

    chunk: int = 256

    name: ClassVar[str] = "random"
    needs: ClassVar[tuple[type, ...]] = ()
    whole_episodes: ClassVar[bool] = False
    paper_name: ClassVar[str | None] = "Random"
    color: ClassVar[str | None] = "#7f7f7f"

    def __post_init__(self):
        whole("chunk", self.chunk, 1, 100_000)

    def run(self, problem, reward, rec: Recorder, seed: int) -> None:
        rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(RANDOM_KEY,)))
        n, na = problem.actions_per_episode, problem.n_actions
        first = first_range(problem)
        batch = problem.run_batch if isinstance(problem, BatchSimulator) else None
        s0 = problem.reset()
        while True:
            acts = rng.integers(0, na, size=(self.chunk, n))
            if first > na:  # more first choices than actions (start points x arrival phases)
                acts[:, 0] = rng.integers(0, first, size=self.chunk)
            m = min(rec.left, self.chunk)
            if batch is None:
                for e in range(m):
                    actions: list[int] = []
                    ret, risk, unsafe = rollout(problem, reward, s0, actions, 0.0, _Row(acts[e]))
                    rec.finish(actions, ret, risk, unsafe)
                continue
            b = batch(acts[:m])
            played, unsafe, sev = b.played, b.unsafe, b.severity_end
            for e in range(m):
                k_end = int(played[e])
                ret, risk = 0.0, 0.0
                for k in range(k_end):
                    last_unsafe = bool(unsafe[e]) and k == k_end - 1
                    ms = Measures(float(b.d_end[e, k]), float(b.v_end[e, k]), None if sev is None else float(sev[e, k]))
                    r, rk = reward(ms, k == n - 1, last_unsafe)
                    ret += r
                    risk = max(risk, rk)
                rec.finish(acts[e, :k_end], ret, risk, bool(unsafe[e]))


class _Row:
    """A stand-in Generator that hands out one pre-drawn row of actions."""

    def __init__(self, row):
        self.row = row

    def integers(self, lo, hi, size):
        return self.row[len(self.row) - size:]
