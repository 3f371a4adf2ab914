"""Does the paper's reward point at a cell's hazard? Returns of uniform random episodes (issue 21).

    python benchmarks/reward_landscape.py CELL [--episodes 30000] [--seed 11]

Plays ``--episodes`` uniform 8-action episodes with ``run_batch`` and sums the paper's reward over each (1/c_S after
every action, -c_S after the last one unless the episode ended unsafe; c_S = (d_HR^2 + 1) exp(-v_R)). Prints the
per-episode hazard probability p, where the hazards' returns lie among all returns (median, 90th and 99th
percentiles), the share of hazards among the top 1 % of returns, and, per first action, the rank correlation of
its mean return with its hazard rate. When the hazards are the best-scoring episodes (S1, S3) an MCTS guided by
this reward finds them; when they sit near the 90th percentile (``s2-deceptive``) it is led elsewhere
(docs/cells.md, "S2 rebuilt").
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.stats import spearmanr

from cellstress.sim.simulator import Simulator


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("cell")
    ap.add_argument("--episodes", type=int, default=30_000)
    ap.add_argument("--seed", type=int, default=11)
    args = ap.parse_args()
    sim = Simulator(args.cell)
    acts = np.random.default_rng(args.seed).integers(0, sim.n_actions, (args.episodes, sim.actions_per_episode))
    b = sim.run_batch(acts)
    u = b.unsafe
    c = (b.d_end**2 + 1) * np.exp(-b.v_end)
    ret = np.zeros(len(acts))
    for k in range(sim.actions_per_episode):
        last = (k == sim.actions_per_episode - 1) & ~u
        ret += np.where(k < b.played, np.where(last, -c[:, k], 1 / c[:, k]), 0.0)
    p = u.mean()
    print(f"{args.cell}: {u.sum()} unsafe of {len(acts)}, p = {p:.5f}")
    if not u.any():
        return
    top = ret >= np.quantile(ret, 0.99)
    print(f"returns: hazards median {np.median(ret[u]):.2f}; all episodes median {np.median(ret):.2f}, "
          f"90th percentile {np.quantile(ret, 0.9):.2f}, 99th {np.quantile(ret, 0.99):.2f}")
    print(f"hazards among the top 1 % of returns: {u[top].mean():.3f} ({u[top].mean() / p:.0f} x p)")
    first = acts[:, 0]
    n = np.bincount(first, minlength=sim.n_actions)
    mean_ret = np.bincount(first, weights=ret, minlength=sim.n_actions) / np.maximum(n, 1)
    hazard = np.bincount(first, weights=u, minlength=sim.n_actions) / np.maximum(n, 1)
    print(f"first action: Spearman(mean return, hazard rate) = {spearmanr(mean_ret, hazard).correlation:.2f}")


if __name__ == "__main__":
    main()
