"""A toy problem for the searchers: a 1-D walk along one narrow failing action sequence.

The walker stands at x = 0. Playing ``secret[x]`` moves it one step on (x + 1); any other action moves it
one step back (not below 0). Reaching x = len(secret) is the unsafe state. Metrics as the cell simulator's:
d_HR = ``spacing`` x the remaining steps (0.25 m, so that returns spread about as on the reference cells) and
v_R = 1 m/s, so the reward 1/c_S = e / (d^2 + 1) grows as the walker gets closer. It has the interface the
searchers use (``core.protocols.Simulator``): reset / step / is_unsafe / measures / run, n_actions,
actions_per_episode.
"""

from __future__ import annotations

import numpy as np

from cellstress.core.records import Measures


class ToyWalk:
    def __init__(self, secret=(3, 1, 4, 1, 5), n_actions: int = 6, horizon: int = 8,
                 spacing: float = 0.25):
        self.spacing = spacing
        self.secret = tuple(secret)
        self.n_actions = n_actions
        self.actions_per_episode = horizon
        self.steps = 0  # actions played, for budget checks

    def reset(self):
        return (0, False)

    def step(self, state, action):
        x, unsafe = state
        if unsafe:
            return state, np.array([[0.0, 1.0]])
        self.steps += 1
        x = x + 1 if x < len(self.secret) and action == self.secret[x] else max(x - 1, 0)
        unsafe = x == len(self.secret)
        return (x, unsafe), np.array([[self.spacing * (len(self.secret) - x), 1.0]])

    @staticmethod
    def is_unsafe(state) -> bool:
        return state[1]

    @staticmethod
    def measures(rows) -> Measures:
        return Measures(float(rows[-1, 0]), float(rows[-1, 1]))

    def run(self, actions) -> ToyTrace:
        state, rows = self.reset(), []
        for a in actions:
            state, r = self.step(state, int(a))
            rows.append(r)
            if state[1]:
                break
        return ToyTrace(np.concatenate(rows) if rows else np.zeros((0, 2)), state[1])


class ToyTrace:
    def __init__(self, rows, unsafe: bool):
        self.rows = rows
        self.unsafe = bool(unsafe)

    @property
    def unsafe_row(self) -> int | None:
        return len(self.rows) - 1 if self.unsafe else None
