"""Machinery shared by all searchers: the problem interface, rewards, the episode budget, top-k, records.

A searcher only needs a *problem* with this small interface (``Problem``): ``reset()`` -> s0,
``step(state, action)`` -> (next state, rows), ``is_unsafe(state)``, ``metrics(rows)`` -> (d_HR, v_R) at the
end of the action, ``n_actions`` and ``actions_per_episode``. ``SimProblem`` adapts the cell ``Simulator``;
the tests use a 1-D toy walk with the same interface.

Reward (the paper, via ``criteria``): after each action k < n the search receives 1/c_S; an episode that
reaches the last action without an unsafe state receives -c_S instead. Reaching U ends the episode and is
rewarded like any other step (1/c_S = e^{v_R}, since d_HR = 0): the paper gives no bonus, and neither do we.
Returns are undiscounted sums over the episode.

Randomness: every searcher draws from numpy Generators made from ``SeedSequence(seed)``; no global state.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from cellstress.errors import CellstressError

UNTIL = ("first", "budget")


class SearchError(CellstressError):
    """A bad search option (unknown searcher, budget < 1, negative seed, ...)."""


class Problem(Protocol):
    n_actions: int
    actions_per_episode: int

    def reset(self) -> np.ndarray: ...

    def step(self, state, action: int) -> tuple[object, np.ndarray]: ...

    def is_unsafe(self, state) -> bool: ...

    def metrics(self, rows) -> tuple[float, float]: ...


class SimProblem:
    """The cell simulator seen through the ``Problem`` interface."""

    def __init__(self, sim):
        from cellstress.sim import kernels as K

        self.sim = sim
        self.n_actions = sim.n_actions
        self.actions_per_episode = sim.actions_per_episode
        self._d, self._v, self._tstop = K.M_D, K.M_V, K.S_TSTOP
        self._lookahead = {}
        self.reset = sim.reset
        self.step = sim.step
        self.is_unsafe = sim.is_unsafe
        self.forces = getattr(sim, "forces", None)
        if self.forces is None:
            self.run_batch = _sim_run_batch(sim, K)
        else:  # iso15066: the reward needs the force ratio at every action end, so episodes are stepped
            self.metrics = self._iso_metrics

    def metrics(self, rows) -> tuple[float, float]:
        last = rows[-1]
        return float(last[self._d]), float(last[self._v])

    def lookahead(self, state, rows, horizon=None, speed=1.6) -> np.ndarray:
        """The predictive gap of each of ``rows`` (``sim.lookahead``; ``state`` is the state after them): an
        optional score a searcher may ask for. It plays nothing: the budget is unaffected."""
        key = (horizon, speed)
        la = self._lookahead.get(key)
        if la is None:
            la = self._lookahead[key] = self.sim.lookahead(horizon, speed)
        return la.gaps(rows, state[self._tstop])

    def _iso_metrics(self, rows) -> tuple[float, float, float]:
        """(d_HR, v_R, predicted force / transient limit) at the action's last step (see ``IsoReward``)."""
        last = rows[-1]
        return float(last[self._d]), float(last[self._v]), float(self.forces.assess(last).ratio)


def make_reward(sim):
    """The reward of a simulator's criterion: the paper's (``Reward``) or ``IsoReward``."""
    from cellstress.criteria import criterion_for

    crit = criterion_for(sim.cell.spec.criterion)
    if crit.name == "iso15066":
        from cellstress.criteria.iso15066 import IsoReward

        return IsoReward(sim.actions_per_episode)
    return Reward(crit)


class Reward:
    """The criterion's reward and risk (1/c_S) for one action end."""

    def __init__(self, criterion):
        self.criterion = criterion

    def __call__(self, d_hr: float, v_r: float, last_action: bool, unsafe: bool) -> tuple[float, float]:
        """(reward, risk) after one action; risk = 1/c_S."""
        c = self.criterion.safety_index(d_hr, v_r)
        return (-c if last_action and not unsafe else 1.0 / c), 1.0 / c


@dataclass(frozen=True)
class Episode:
    """One finished episode: the actions played (up to the unsafe one), its return and max risk."""

    index: int  # 1-based episode number
    actions: tuple[int, ...]
    ret: float
    risk: float
    unsafe: bool


class TopK:
    """The k episodes with the highest return, keyed by action sequence (ties: the earlier episode wins)."""

    def __init__(self, k: int):
        self.k = k
        self._heap: list[tuple[float, int, tuple[int, ...], Episode]] = []
        self._keys: dict[tuple[int, ...], Episode] = {}

    def add(self, ep: Episode) -> None:
        if self.k <= 0:
            return
        old = self._keys.get(ep.actions)
        if old is not None:  # deterministic simulator: the same sequence always gives the same return
            return
        item = (ep.ret, -ep.index, ep.actions, ep)
        if len(self._heap) < self.k:
            heapq.heappush(self._heap, item)
            self._keys[ep.actions] = ep
        elif item[:2] > self._heap[0][:2]:
            gone = heapq.heapreplace(self._heap, item)
            del self._keys[gone[2]]
            self._keys[ep.actions] = ep

    def best(self) -> list[Episode]:
        return [it[3] for it in sorted(self._heap, key=lambda it: it[:2], reverse=True)]


class Stop(Exception):
    """Raised inside a searcher when the search is over (budget used up, or first hazard with until=first)."""


@dataclass
class Recorder:
    """Counts episodes against the budget and keeps what the result needs.

    Every searcher calls ``finish`` exactly once per episode (an iteration); it raises ``Stop`` when the
    search is over, so no searcher can overrun the budget.
    """

    budget: int
    until: str = "first"
    top_k: int = 10
    progress: Callable[[int, float], None] | None = None
    episodes: int = 0
    risks: list[float] = field(default_factory=list)
    hazards: list[Episode] = field(default_factory=list)
    best_risk: float = 0.0

    def __post_init__(self):
        self.top = TopK(self.top_k)

    @property
    def left(self) -> int:
        return self.budget - self.episodes

    def finish(self, actions, ret: float, risk: float, unsafe: bool) -> Episode:
        if self.episodes >= self.budget:
            raise Stop
        self.episodes += 1
        ep = Episode(self.episodes, tuple(int(a) for a in actions), float(ret), float(risk), bool(unsafe))
        self.risks.append(ep.risk)
        self.best_risk = max(self.best_risk, ep.risk)
        self.top.add(ep)
        if unsafe:
            self.hazards.append(ep)
        if self.progress is not None:
            self.progress(self.episodes, self.best_risk)
        if (unsafe and self.until == "first") or self.episodes >= self.budget:
            raise Stop
        return ep


@dataclass(frozen=True)
class Outcome:
    """What a searcher produced on a problem (no cell facts yet: see ``result.SearchResult``)."""

    episodes: int
    hazards: tuple[Episode, ...]
    top: tuple[Episode, ...]
    risks: tuple[float, ...]

    @property
    def found(self) -> bool:
        return bool(self.hazards)

    @property
    def first_hazard(self) -> Episode | None:
        return self.hazards[0] if self.hazards else None


def rollout(problem, reward, state, actions: list[int], risk: float, rng: np.random.Generator):
    """Play uniformly random actions from ``state`` to the horizon; ``actions`` (the prefix) is extended.

    Returns (return of the rollout part, max risk incl. ``risk``, unsafe)."""
    n = problem.actions_per_episode
    depth = len(actions)
    if depth >= n or problem.is_unsafe(state):
        return 0.0, risk, problem.is_unsafe(state)
    draws = rng.integers(0, problem.n_actions, size=n - depth).tolist()
    total = 0.0
    for k, a in enumerate(draws, start=depth):
        state, rows = problem.step(state, a)
        actions.append(a)
        unsafe = problem.is_unsafe(state)
        r, rk = reward(*problem.metrics(rows), k == n - 1, unsafe)
        total += r
        if rk > risk:
            risk = rk
        if unsafe:
            return total, risk, True
    return total, risk, False


def check_common(budget, seed, until, top_k) -> None:
    if isinstance(budget, bool) or not isinstance(budget, (int, np.integer)) or budget < 1:
        raise SearchError(f"budget must be a whole number of episodes >= 1, not {budget!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise SearchError(f"seed must be a whole number >= 0, not {seed!r}")
    if until not in UNTIL:
        raise SearchError(f"until must be one of {', '.join(UNTIL)}, not {until!r}")
    if isinstance(top_k, bool) or not isinstance(top_k, (int, np.integer)) or top_k < 0:
        raise SearchError(f"top_k must be a whole number >= 0, not {top_k!r}")


def _sim_run_batch(sim, K):
    spa = sim.steps_per_action

    def run_batch(actions):
        """(d_end, v_end, actions played, unsafe) of many episodes from s0."""
        b = sim.run_batch(actions)
        unsafe = b.unsafe_step >= 0
        played = np.where(unsafe, -(-b.unsafe_step // spa), actions.shape[1])
        return b.d_end, b.v_end, played, unsafe

    return run_batch
