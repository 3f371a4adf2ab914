"""The issue-17 and issue-20 built-in cells: each flawed cell's hazard found per seed within the budget, and its
fixed twin searched for a hazard with a large budget.

    python benchmarks/new_cells.py [--seeds 10] [--budget 200] [--twin-budget 1000] [--twin-seeds 3]
                                   [--cells palletizing,two-robots,reach-over] [--searchers plan,evolve,random]

Prints one Markdown row per cell and searcher: runs that found a hazard, mean and largest episodes to the first
hazard (a run without one counts as the budget); for a twin, hazardous episodes over whole budgets.
"""

from __future__ import annotations

import argparse
import statistics

from cellstress.searchers import search
from cellstress.sim.simulator import Simulator

PAIRS = (("palletizing", "palletizing-fixed"), ("two-robots", "two-robots-fixed"), ("reach-over", "reach-over-ok"))
SEARCHERS = ("plan", "evolve", "random")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--twin-budget", type=int, default=1000)
    ap.add_argument("--twin-seeds", type=int, default=3)
    ap.add_argument("--cells", default=",".join(f for f, _ in PAIRS), help="the flawed cells of the pairs to run")
    ap.add_argument("--searchers", default=",".join(SEARCHERS), help="registered searchers, e.g. plan,evolve,mcts")
    ap.add_argument("--no-twin", action="store_true", help="search the flawed cells only")
    ap.add_argument("--twin-only", action="store_true", help="search the twins only")
    args = ap.parse_args()
    chosen, searchers = args.cells.split(","), args.searchers.split(",")
    print("| cell | searcher | runs | found | mean episodes | max episodes | hazardous episodes |")
    print("|---|---|---|---|---|---|---|")
    for flawed, twin in (p for p in PAIRS if p[0] in chosen):
        sim = Simulator(flawed)
        for s in () if args.twin_only else searchers:
            eps = []
            for seed in range(args.seeds):
                r = search(sim, s, budget=args.budget, seed=seed)
                eps.append(r.episodes if r.found else None)
            found = [e for e in eps if e is not None]
            filled = [e if e is not None else args.budget for e in eps]
            print(f"| {flawed} | {s} | {args.seeds} x {args.budget} | {len(found)}/{args.seeds} | "
                  f"{statistics.mean(filled):.1f} | {max(filled)} | |", flush=True)
        if args.no_twin:
            continue
        sim = Simulator(twin)
        for s in searchers:
            hazardous = 0
            for seed in range(args.twin_seeds):
                r = search(sim, s, budget=args.twin_budget, seed=seed, until="budget")
                hazardous += len(r.hazards)
            print(f"| {twin} | {s} | {args.twin_seeds} x {args.twin_budget} | | | | {hazardous} |", flush=True)


if __name__ == "__main__":
    main()
