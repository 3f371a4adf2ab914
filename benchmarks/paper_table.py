"""A quick, serial version of the paper's Table III: 3 flawed cells x 3 searchers x N seeds, budget 200.

Usage: python benchmarks/paper_table.py [--seeds 10] [--budget 200]
Prints success counts and mean episodes to the first hazard (a failed run counts as the budget), next to the
paper's numbers. Superseded by ``cellstress campaign`` (parallel, resumable, with intervals; docs/results.md).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import cellstress
from cellstress.sim.simulator import Simulator

CELLS = ["s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap"]
SEARCHERS = ["random", "mcts", "mcts-commit"]
PAPER = {  # Huck et al. 2020, Table III: (successes of 10, mean episodes)
    ("random", 0): (3, 166.8), ("random", 1): (3, 150.4), ("random", 2): (8, 81.1),
    ("mcts", 0): (10, 70.0), ("mcts", 1): (8, 63.3), ("mcts", 2): (10, 34.9),
    ("mcts-commit", 0): (10, 49.7), ("mcts-commit", 1): (9, 80.4), ("mcts-commit", 2): (10, 38.0),
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--budget", type=int, default=200)
    args = ap.parse_args()
    t0 = time.perf_counter()
    print("| searcher | cell | found | mean episodes | paper found | paper mean |")
    print("|---|---|---|---|---|---|")
    for ci, cell in enumerate(CELLS):
        sim = Simulator(cell)
        for name in SEARCHERS:
            eps, found = [], 0
            for seed in range(args.seeds):
                r = cellstress.search(sim, searcher=name, budget=args.budget, seed=seed)
                found += bool(r.found)
                eps.append(r.episodes if r.found else args.budget)
            pf, pm = PAPER[(name, ci)]
            print(f"| {name} | {cell} | {found}/{args.seeds} | {np.mean(eps):.1f} | {pf}/10 | {pm} |")
    print(f"\n({time.perf_counter() - t0:.1f} s)")


if __name__ == "__main__":
    main()
