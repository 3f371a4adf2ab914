"""Any deterministic Gymnasium env, stress-tested by cellstress's searchers (the ``gym`` simulator plug-in).

The env must have a discrete action space, be deterministic given its reset seed, and report a **safety
measure** in ``info`` after every step: a distance to failure, 0 (or less) at a failure. Adaptive Stress Testing
searches the actions, which stand for the disturbances of the system under test; the safety measure plays the
role of d_HR (the worker's distance to the robot), and a failure that of the unsafe set.

A state is a ``GymState``: the actions played from ``reset(seed=seed)``, the last measure, and whether the env
has ended. ``step(state, action)`` is pure as the protocol asks: when ``state`` is not the one the live env is
in, the env is reset with the seed and the state's actions are replayed (the Adaptive Stress Testing pattern),
so searchers that branch (tree search) pay a replay, and those that play on (rollouts) do not. An env that ends
without a failure (it reaches its goal, or its own time limit) stays where it is for the rest of the episode.

Measures: d_HR is the safety measure and v_R is 1, so a reward of the paper's kind, 1/c_S = e / (d^2 + 1),
grows as the env comes closer to a failure (``reward``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from cellstress.core.records import Measures
from cellstress.criteria.contact import ContactWhileMoving

MOVING = 1.0  # v_R of every step: a failure is unsafe whenever it happens


@dataclass(frozen=True)
class GymState:
    actions: tuple[int, ...]
    measure: float
    ended: bool  # the env terminated or was truncated (a failure or not)
    unsafe: bool


@dataclass(frozen=True)
class GymTrace:
    """A played episode: one row per action (measure, v_R), and whether it ended in a failure."""

    rows: np.ndarray
    unsafe: bool

    @property
    def unsafe_row(self) -> int | None:
        return len(self.rows) - 1 if self.unsafe else None


class GymSimulator:
    """``env``: a registered env id (made with ``env_kwargs``) or a function that makes the env (for wrappers);
    ``measure``: the ``info`` key of the safety measure; ``horizon``: actions per episode; ``seed``: the reset
    seed every episode starts from."""

    def __init__(self, env: str | Callable[[], gymnasium.Env], measure: str, horizon: int = 8, seed: int = 0,
                 env_kwargs: dict[str, Any] | None = None):
        self._make = (lambda: gymnasium.make(env, **(env_kwargs or {}))) if isinstance(env, str) else env
        self.env = self._make()
        if not isinstance(self.env.action_space, spaces.Discrete):
            raise ValueError(f"the env's action space must be Discrete, not {self.env.action_space}")
        if isinstance(horizon, bool) or not isinstance(horizon, int) or horizon < 1:
            raise ValueError(f"horizon must be a whole number >= 1, not {horizon!r}")
        self.measure_key = measure
        self.seed = int(seed)
        self.n_actions = int(self.env.action_space.n)
        self.actions_per_episode = horizon
        self._s0 = self._restart()

    def _restart(self) -> GymState:
        _, info = self.env.reset(seed=self.seed)
        m = float(info[self.measure_key]) if self.measure_key in info else np.inf
        self._live = GymState((), m, False, m <= 0.0)
        return self._live

    def reset(self) -> GymState:
        return self._s0

    def step(self, state: GymState, action: int) -> tuple[GymState, np.ndarray]:
        if state.ended:
            return state, np.array([[state.measure, MOVING]])
        if self._live != state:  # replay from the seed (the AST pattern)
            self._restart()
            for a in state.actions:
                self._advance(int(a))
        nxt = self._advance(int(action))
        return nxt, np.array([[nxt.measure, MOVING]])

    def _advance(self, action: int) -> GymState:
        _, _, terminated, truncated, info = self.env.step(action)
        if self.measure_key not in info:
            raise KeyError(f"the env's info has no safety measure {self.measure_key!r} (its keys: "
                           f"{', '.join(map(str, info)) or 'none'})")
        m = float(info[self.measure_key])
        self._live = GymState((*self._live.actions, action), m, bool(terminated or truncated), m <= 0.0)
        return self._live

    @staticmethod
    def is_unsafe(state: GymState) -> bool:
        return state.unsafe

    @staticmethod
    def measures(rows: np.ndarray) -> Measures:
        return Measures(float(rows[-1, 0]), float(rows[-1, 1]))

    def run(self, actions: Sequence[int]) -> GymTrace:
        state, rows = self.reset(), []
        for a in actions:
            state, r = self.step(state, int(a))
            rows.append(r)
            if state.unsafe or state.ended:
                break
        return GymTrace(np.concatenate(rows) if rows else np.zeros((0, 2)), state.unsafe)

    def reward(self):
        """The paper's reward on the safety measure (1/c_S per action, -c_S at the horizon)."""
        return ContactWhileMoving().reward(self.actions_per_episode)
