"""A search tree with double progressive widening (DPW) over a deterministic simulator.

Follows AdaptiveStressTesting.jl's MCTS (``MCTSdpw``), with two changes that a deterministic simulator with
30 discrete actions allows:

* action widening draws an *untried* action uniformly (from the node's own numpy Generator, seeded by
  ``SeedSequence(seed, spawn_key=(1, *path))`` so a node's draws do not depend on the order of the search);
* state widening is trivial (one next state per action), so each node caches its state: an iteration only
  simulates from the deepest node already in the tree (the new node and its rollout). It still counts as one
  episode, played from s0.

Selection: ``Q + ec * sqrt(log N / N(a))`` (an untried edge, N(a) = 0, is taken first). Widening while
``|children| <= k * N**alpha`` (AdaptiveStressTesting.jl's rule: a new action is drawn while the node has at
most that many). A new node is valued by a uniform random rollout to the horizon. Returns are
undiscounted.
"""

from __future__ import annotations

import math

import numpy as np

from cellstress.core.protocols import Revisiting, StartChoices
from cellstress.searchers.common import Recorder, rollout

ROLLOUT_KEY = 0
NODE_KEY = 1


class Node:
    __slots__ = ("state", "path", "depth", "r", "risk", "unsafe", "n", "edges", "untried", "rng")

    def __init__(self, state, path: tuple[int, ...], r: float, risk: float, unsafe: bool):
        self.state = state
        self.path = path  # actions from s0
        self.depth = len(path)
        self.r = r  # reward of the action that led here
        self.risk = risk  # its risk 1/c_S
        self.unsafe = unsafe
        self.n = 0  # visits
        self.edges: dict[int, Edge] = {}  # in the order they were tried
        self.untried: list[int] | None = None
        self.rng: np.random.Generator | None = None


class Edge:
    __slots__ = ("n", "q", "child")

    def __init__(self):
        self.n = 0
        self.q = 0.0
        self.child: Node | None = None


class Tree:
    """The DPW tree and one iteration (= one episode) of MCTS from a given root."""

    def __init__(self, problem, reward, recorder: Recorder, seed: int, ec: float, k: float, alpha: float):
        self.problem = problem
        self.reward = reward
        self.rec = recorder
        self.seed = int(seed)
        self.ec, self.k, self.alpha = float(ec), float(k), float(alpha)
        self.horizon = problem.actions_per_episode
        self.revisit = problem.revisit if isinstance(problem, Revisiting) else None
        self.rollout_rng = np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(ROLLOUT_KEY,)))
        self.root = Node(problem.reset(), (), 0.0, 0.0, bool(problem.is_unsafe(problem.reset())))

    def _widen(self, node: Node) -> None:
        if node.untried is None:
            p = self.problem  # a problem with StartChoices has other decisions at the root (start points)
            node.untried = list(range(p.choices(node.depth) if isinstance(p, StartChoices) else p.n_actions))
            node.rng = np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(NODE_KEY, *node.path)))
        a = node.untried.pop(int(node.rng.integers(len(node.untried))))
        node.edges[a] = Edge()

    def _select(self, node: Node) -> int:
        log_n = math.log(node.n)
        ec = self.ec
        best_a, best_u = -1, -math.inf
        for a, e in node.edges.items():
            if e.n == 0:
                return a
            u = e.q + ec * math.sqrt(log_n / e.n)
            if u > best_u:
                best_a, best_u = a, u
        return best_a

    def _expand(self, node: Node, a: int) -> Node:
        p = self.problem
        state, rows = p.step(node.state, a)
        unsafe = bool(p.is_unsafe(state))
        r, risk = self.reward(p.measures(rows), node.depth + 1 == self.horizon, unsafe)
        return Node(state, (*node.path, a), r, risk, unsafe)

    def iterate(self, root: Node, prefix_ret: float, prefix_risk: float) -> None:
        """One iteration from ``root`` (reached from s0 by ``root.path``, with that return and max risk)."""
        node = root
        trail: list[Edge] = []
        ret, risk = prefix_ret, prefix_risk
        leaf = 0.0
        unsafe = node.unsafe
        actions = list(node.path)
        while not unsafe and node.depth < self.horizon:
            node.n += 1
            if len(node.edges) <= self.k * node.n ** self.alpha and (node.untried is None or node.untried):
                self._widen(node)
            a = self._select(node)
            edge = node.edges[a]
            trail.append(edge)
            new = edge.child is None
            if new:
                edge.child = self._expand(node, a)
            node = edge.child
            if not new and node.unsafe and self.revisit is not None:  # e.g. distinct mode: a known hazard
                self.revisit(node)
            actions.append(a)
            ret += node.r
            risk = max(risk, node.risk)
            unsafe = node.unsafe
            if new:
                if not unsafe:
                    leaf, risk, unsafe = rollout(self.problem, self.reward, node.state, actions, risk,
                                                 self.rollout_rng)
                break
        q = leaf
        for edge in reversed(trail):  # undiscounted: Q(s, a) = mean return from s after taking a
            q += edge.child.r
            edge.n += 1
            edge.q += (q - edge.q) / edge.n
        self.rec.finish(actions, ret + leaf, risk, unsafe)

    def best_action(self, node: Node) -> int | None:
        """argmax Q over the visited edges (AdaptiveStressTesting.jl commits by Q, not by visit count)."""
        best_a, best_q = None, -math.inf
        for a, e in node.edges.items():
            if e.n > 0 and e.q > best_q:
                best_a, best_q = a, e.q
        return best_a
