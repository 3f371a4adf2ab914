"""Distinct hazards on the all-flaws cell: random, mcts and mcts --distinct, 1,000 episodes, seeds 0-9.

For each run: the devices bypassed by the hazards found (front-scanner, bay-curtain, none = around the
safeguards), the number of hazard classes and of hazardous episodes. Plain runs are clustered after the
fact with the same key.
Usage: PYTHONPATH=src NUMBA_NUM_THREADS=1 python benchmarks/distinct_all_flaws.py [budget] [seeds]
"""

from __future__ import annotations

import sys

from cellstress.search import search
from cellstress.search.distinct import hazard_class
from cellstress.sim.simulator import Simulator

FLAW = {"front-scanner": "scanner", "bay-curtain": "curtain", "none": "none"}


def classes_of(sim, res):
    """(class keys, devices bypassed) of a result's hazards."""
    from cellstress.search.multistart import split_start

    if res.distinct is not None:
        keys = {(d["class"]["device"], d["class"]["robot_link"], d["class"]["body_region"],
                 *d["class"]["approach_cell"][:2]) for d in res.distinct}
    else:
        keys = set()
        for h in res.hazards:
            run_sim, rest = split_start(sim, h["actions"])
            state = run_sim.reset()
            for a in rest:
                state, rows = run_sim.step(state, a)
                if run_sim.is_unsafe(state):
                    break
            keys.add(hazard_class(run_sim, state, rows[-1]))
    return keys, {FLAW.get(k[0], "?") for k in keys}


def main():
    budget = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    seeds = range(int(sys.argv[2]) if len(sys.argv) > 2 else 10)
    sim = Simulator("all-flaws")
    print("| searcher | seed | devices bypassed | classes | hazardous episodes |")
    print("|---|---:|---|---:|---:|")
    for name, searcher, distinct in (("random", "random", False), ("mcts", "mcts", False),
                                     ("mcts --distinct", "mcts", True)):
        for seed in seeds:
            res = search(sim, searcher, budget, seed, until="budget", distinct=distinct)
            keys, flaws = classes_of(sim, res)
            print(f"| {name} | {seed} | {', '.join(sorted(flaws)) or '-'} | {len(keys)} | {len(res.hazards)} |",
                  flush=True)


if __name__ == "__main__":
    main()
