"""Random search (the paper's baseline): every action uniform over the action set, a full episode each.

Actions come from one numpy Generator (``SeedSequence(seed, spawn_key=(2,))``), one row of
``actions_per_episode`` draws per episode. If the problem can play many episodes at once (``run_batch``,
the cell simulator on all cores) the episodes are played in chunks; the outcome is the same as stepping
them one by one (the simulator's determinism check covers this), only faster.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cellstress.search.common import Recorder, SearchError, rollout

RANDOM_KEY = 2


@dataclass(frozen=True)
class RandomSearch:
    """Options of ``random``: ``chunk`` = episodes drawn (and, with ``run_batch``, played) at a time.

    A chunk's actions are always drawn whole, so the episodes do not depend on the budget."""

    chunk: int = 256

    name = "random"

    def __post_init__(self):
        if isinstance(self.chunk, bool) or not isinstance(self.chunk, int) or self.chunk < 1:
            raise SearchError(f"chunk must be a whole number >= 1, not {self.chunk!r}")

    def run(self, problem, reward, rec: Recorder, seed: int) -> None:
        rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(RANDOM_KEY,)))
        n, na = problem.actions_per_episode, problem.n_actions
        batch = getattr(problem, "run_batch", None)
        s0 = problem.reset()
        while True:
            acts = rng.integers(0, na, size=(self.chunk, n))
            m = min(rec.left, self.chunk)
            if batch is None:
                for e in range(m):
                    actions: list[int] = []
                    ret, risk, unsafe = rollout(problem, reward, s0, actions, 0.0, _Row(acts[e]))
                    rec.finish(actions, ret, risk, unsafe)
                continue
            d_end, v_end, played, unsafe = batch(acts[:m])
            for e in range(m):
                k_end = int(played[e])
                ret, risk = 0.0, 0.0
                for k in range(k_end):
                    last_unsafe = bool(unsafe[e]) and k == k_end - 1
                    r, rk = reward(float(d_end[e, k]), float(v_end[e, k]), k == n - 1, last_unsafe)
                    ret += r
                    risk = max(risk, rk)
                rec.finish(acts[e, :k_end], ret, risk, bool(unsafe[e]))


class _Row:
    """A stand-in Generator that hands out one pre-drawn row of actions."""

    def __init__(self, row):
        self.row = row

    def integers(self, lo, hi, size):
        return self.row[len(self.row) - size:]
