"""The safeguard scenarios of issue 18: each flawed cell searched over seeds (does the searcher find its flaw
within the budget?), each fixed twin searched with a larger budget to the end (no hazard expected).

    python benchmarks/safeguards.py [--seeds 10] [--budget 200] [--twin-budget 1000] [--searchers plan evolve random]

Prints one Markdown row per cell and searcher: runs that found a hazard, and the mean and median episodes to the
first hazard (a run that found none counts as the budget); for a twin, the hazards found in its whole budget.
"""

from __future__ import annotations

import argparse
import statistics

from cellstress.searchers import search
from cellstress.sim.simulator import Simulator

FLAWED = ("restart-auto", "warning-field-short", "mat-short", "door-unlocked", "muting-long", "ssm-latency")
TWINS = ("restart-manual", "warning-field-ok", "mat-ok", "door-locked", "muting-ok", "ssm-ok")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--twin-budget", type=int, default=1000)
    ap.add_argument("--twin-seeds", type=int, default=1)
    ap.add_argument("--searchers", nargs="+", default=["plan", "evolve", "random"])
    ap.add_argument("--cells", nargs="+", default=list(FLAWED + TWINS))
    args = ap.parse_args()
    print("| cell | searcher | seeds | budget | runs with a hazard | mean episodes to the first | median |")
    print("|---|---|---|---|---|---|---|")
    for name in args.cells:
        sim = Simulator(name)
        twin = name in TWINS
        seeds, budget = (args.twin_seeds, args.twin_budget) if twin else (args.seeds, args.budget)
        for s in args.searchers:
            eps, found = [], 0
            for seed in range(seeds):
                r = search(sim, s, budget=budget, seed=seed, until="budget" if twin else "first")
                found += r.found
                eps.append(r.episodes if r.found and not twin else budget)
            mean = "-" if twin else f"{statistics.mean(eps):.1f}"
            med = "-" if twin else f"{statistics.median(eps):g}"
            print(f"| {name} | {s} | 0-{seeds - 1} | {budget} | {found}/{seeds} | {mean} | {med} |", flush=True)


if __name__ == "__main__":
    main()
