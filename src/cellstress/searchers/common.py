"""Machinery shared by all searchers: the episode budget, top-k, records, rollouts, option checks.

A searcher sees a *problem*: any ``core.protocols.Simulator`` (``reset()`` -> s0, a pure
``step(state, action)`` -> (next state, rows), ``is_unsafe(state)``, ``measures(rows)`` for the reward,
``n_actions`` and ``actions_per_episode``). The cell simulator is one; the tests use a 1-D toy walk.
The reward comes from the criterion (``Criterion.reward``): ``reward(measures, last_action, unsafe)`` ->
(reward, risk). Returns are undiscounted sums over the episode.

Randomness: every searcher draws from numpy Generators made from ``SeedSequence(seed)``; no global state.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from cellstress.core.errors import CellstressError
from cellstress.core.protocols import StartChoices

UNTIL = ("first", "budget")


class SearchError(CellstressError):
    """A bad search option (unknown searcher, budget < 1, negative seed, ...)."""


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


MAX_TRACKED = 2_000_000  # distinct sequences counted (a hash each): beyond it, "at least" this many


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
        self._seen: set[int] = set()  # hashes of the sequences played, for the count of distinct ones

    @property
    def distinct_sequences(self) -> int:
        """How many different action sequences the episodes played (exact up to ``MAX_TRACKED``)."""
        return len(self._seen)

    @property
    def left(self) -> int:
        return self.budget - self.episodes

    def finish(self, actions, ret: float, risk: float, unsafe: bool) -> Episode:
        if self.episodes >= self.budget:
            raise Stop
        self.episodes += 1
        ep = Episode(self.episodes, tuple(int(a) for a in actions), float(ret), float(risk), bool(unsafe))
        self.risks.append(ep.risk)
        if len(self._seen) < MAX_TRACKED:
            self._seen.add(hash(ep.actions))
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
    distinct_sequences: int = 0  # different action sequences played (at most MAX_TRACKED counted)

    @property
    def found(self) -> bool:
        return bool(self.hazards)

    @property
    def first_hazard(self) -> Episode | None:
        return self.hazards[0] if self.hazards else None


def first_range(problem) -> int:
    """The range an episode's first decision is drawn from: the actions, or a problem's first choices if there are
    more of them (``searchers.multistart``: a start point and an arrival phase); the problem maps a draw onto its
    choices (modulo), so with fewer choices than actions the draws are the same as for a plain problem."""
    if isinstance(problem, StartChoices):
        return max(problem.n_actions, problem.choices(0))
    return problem.n_actions


def rollout(problem, reward, state, actions: list[int], risk: float, rng: np.random.Generator):
    """Play uniformly random actions from ``state`` to the horizon; ``actions`` (the prefix) is extended.

    Returns (return of the rollout part, max risk incl. ``risk``, unsafe)."""
    n = problem.actions_per_episode
    depth = len(actions)
    if depth >= n or problem.is_unsafe(state):
        return 0.0, risk, problem.is_unsafe(state)
    draws = rng.integers(0, problem.n_actions, size=n - depth).tolist()
    if depth == 0 and isinstance(rng, np.random.Generator):  # (a pre-drawn row already holds its first decision)
        first = first_range(problem)
        if first > problem.n_actions:
            draws[0] = int(rng.integers(first))
    total = 0.0
    for k, a in enumerate(draws, start=depth):
        state, rows = problem.step(state, a)
        actions.append(a)
        unsafe = problem.is_unsafe(state)
        r, rk = reward(problem.measures(rows), k == n - 1, unsafe)
        total += r
        if rk > risk:
            risk = rk
        if unsafe:
            return total, risk, True
    return total, risk, False


MAX_BUDGET = 10_000_000  # episodes: every search keeps a risk per episode, so memory grows with the budget
MAX_TOP_K = 100_000
MAX_SEED = 2**63 - 1


def whole(name: str, value, lo: int, hi: int) -> None:
    """SearchError unless ``value`` is a whole number in lo..hi (``True`` is not a number)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= hi:
        raise SearchError(f"{name} must be a whole number in {lo}..{hi:,}, not {value!r}")


def number(name: str, value, lo: float, hi: float) -> None:
    """SearchError unless ``value`` is a number in lo..hi (finite; ``True`` is not a number)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not lo <= value <= hi:
        raise SearchError(f"{name} must be a number in {lo:g}..{hi:g}, not {value!r}")


def check_common(budget, seed, until, top_k) -> None:
    whole("budget", budget, 1, MAX_BUDGET)
    whole("seed", seed, 0, MAX_SEED)
    if until not in UNTIL:
        raise SearchError(f"until must be one of {', '.join(UNTIL)}, not {until!r}")
    whole("top_k", top_k, 0, MAX_TOP_K)
