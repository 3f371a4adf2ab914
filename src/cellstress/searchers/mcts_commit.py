"""MCTS2 of the paper: n iterations from the current root, commit to the argmax-Q action, re-root.

(AdaptiveStressTesting.jl's ``stress_test``.) The depth counts down: after i commits the tree searches the
remaining horizon - i actions below the committed prefix; every iteration is still one episode from s0 (the
committed prefix is cached, not re-simulated). Default ``n`` = budget // horizon (the remainder goes to the
first decisions), so that the commits use exactly the budget. If the committed path ends (horizon or an
unsafe state) with budget left (only with an explicit ``n`` or ``until="budget"``), the cycle starts again at
s0, keeping the tree's statistics.

Measured against the paper's Table III (issue 21, ``benchmarks/mcts_constants.py``, docs/results.md, seeds
0-39): a fixed n of 10-40 (8 commits take 80-320 iterations; when they end within the budget, a new pass starts
at s0) made S3's MCTS2 slower (29-37 episodes against 25.8; the paper's 38.0) but S1's no faster (57.7-82.3
against 59.2; the paper's 49.7). n = 15 put all three MCTS2 rows inside our intervals on seeds 0-39, not on
40-79 (11 of 18 paper numbers inside there, as with the default), so the default stays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from cellstress.searchers.common import MAX_BUDGET, Recorder, whole
from cellstress.searchers.mcts import check_dpw
from cellstress.searchers.tree import Tree


@dataclass(frozen=True)
class MCTSCommit:
    """Options of ``mcts-commit`` (MCTS2): ``n`` iterations per decision (None: budget // horizon), ``ec``,
    ``k``, ``alpha`` as for ``mcts`` (defaults and their reasons: see ``cellstress.searchers.mcts``)."""

    n: int | None = None
    ec: float = 0.5
    k: float = 1.0
    alpha: float = 0.85

    name: ClassVar[str] = "mcts-commit"
    needs: ClassVar[tuple[type, ...]] = ()
    whole_episodes: ClassVar[bool] = False
    paper_name: ClassVar[str | None] = "MCTS2"
    color: ClassVar[str | None] = "#d62728"

    def __post_init__(self):
        check_dpw(self.ec, self.k, self.alpha)
        if self.n is not None:
            whole("n", self.n, 1, MAX_BUDGET)

    def iterations(self, budget: int, horizon: int) -> list[int]:
        if self.n is not None:
            return [self.n] * horizon
        base, extra = divmod(budget, horizon)
        return [max(1, base + (1 if i < extra else 0)) for i in range(horizon)]

    def run(self, problem, reward, rec: Recorder, seed: int) -> None:
        tree = Tree(problem, reward, rec, seed, self.ec, self.k, self.alpha)
        plan = self.iterations(rec.budget, tree.horizon)
        while True:
            root, ret, risk = tree.root, 0.0, 0.0
            for n in plan:
                for _ in range(n):
                    tree.iterate(root, ret, risk)
                a = tree.best_action(root)
                if a is None:
                    break
                root = root.edges[a].child
                ret, risk = ret + root.r, max(risk, root.risk)
                if root.unsafe or root.depth >= tree.horizon:
                    break
