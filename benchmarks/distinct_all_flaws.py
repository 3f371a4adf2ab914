"""Distinct hazards on the all-flaws cell: random, mcts, mcts --distinct, evolve and evolve --distinct, one run
of 1,000 episodes (``--until budget``) per seed, seeds 0-9.

For each run: the devices bypassed by the hazards found (scanner = front-scanner, curtain = bay-curtain, none =
around the safeguards), the number of hazard classes, of hazardous episodes, and the episode at which the last of
the three devices was first met. Plain runs are clustered after the fact with the same class key as --distinct.
Prints one row per run, then a summary table (docs/results.md).
Usage: PYTHONPATH=src NUMBA_NUM_THREADS=1 python benchmarks/distinct_all_flaws.py [budget] [seeds] [searchers]
(seeds: N for 0..N-1 or A:B; searchers: comma-separated names from RUNS below, default all).
"""

from __future__ import annotations

import sys
import time

from cellstress.searchers import search
from cellstress.searchers.distinct import hazard_class
from cellstress.sim.simulator import Simulator

FLAW = {"front-scanner": "scanner", "bay-curtain": "curtain", "none": "none"}
# the flaw each start point was built for, with the device it defeats (the right start also meets the scanner
# when the worker steps into the aisle: that counts for "scanner" but not for S1)
FLAW_START = {("start:upper-end", "front-scanner"): "S1", ("start:lower-end", "bay-curtain"): "S2",
              ("start:lower-end-right", "none"): "S3"}
RUNS = {"random": ("random", False), "mcts": ("mcts", False), "mcts --distinct": ("mcts", True),
        "evolve": ("evolve", False), "evolve --distinct": ("evolve", True), "plan --distinct": ("plan", True)}


def classes_of(sim, res):
    """[(episode, start name, class key)] of a result's hazards, each class once, in the order found."""
    from cellstress.sim.starts import split_start

    if res.distinct is not None:
        return [(d["episode"], d["actions"][0], (d["class"]["device"], d["class"]["robot_link"],
                                                 d["class"]["body_region"], *d["class"]["approach_cell"][:2]))
                for d in res.distinct]
    out, seen = [], set()
    for h in res.hazards:
        run_sim, rest = split_start(sim, h["actions"])
        state = run_sim.reset()
        for a in rest:
            state, rows = run_sim.step(state, a)
            if run_sim.is_unsafe(state):
                break
        k = hazard_class(run_sim, state, rows[-1])
        if k not in seen:
            seen.add(k)
            out.append((h["episode"], h["actions"][0], k))
    return out


def main():
    budget = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    a, _, b = (sys.argv[2] if len(sys.argv) > 2 else "10").partition(":")
    seeds = range(int(a), int(b)) if b else range(int(a))
    names = sys.argv[3].split(",") if len(sys.argv) > 3 else list(RUNS)
    sim = Simulator("all-flaws")
    print("| searcher | seed | devices bypassed | classes | hazardous episodes | all three by episode | s |")
    print("|---|---:|---|---:|---:|---:|---:|")
    summary = []
    for name in names:
        searcher, distinct = RUNS[name]
        rows = []
        for seed in seeds:
            t = time.perf_counter()
            res = search(sim, searcher, budget, seed, until="budget", distinct=distinct)
            dt = time.perf_counter() - t
            found = classes_of(sim, res)
            first: dict[str, int] = {}
            flaws: set[str] = set()  # strictly: each flaw's device met from its own start point
            for ep, start, k in found:
                first.setdefault(FLAW.get(k[0], "?"), ep)
                if (start, k[0]) in FLAW_START:
                    flaws.add(FLAW_START[start, k[0]])
            by = max(first.values()) if len(first) == 3 else None
            rows.append((first, len(found), len(res.hazards), by, flaws))
            print(f"| {name} | {seed} | {', '.join(sorted(first)) or '-'} | {len(found)} | {len(res.hazards)} | "
                  f"{by if by is not None else '-'} | {dt:.1f} |", flush=True)
        summary.append((name, rows))
    n = len(seeds)
    print()
    print("| searcher | runs with all three devices | with scanner | with curtain | with none | "
          "runs with S1, S2 and S3 from their own starts | classes per run (mean) | "
          "hazardous episodes per run (mean) | all three devices by episode (mean of those runs) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, rows in summary:
        have = {f: sum(f in r[0] for r in rows) for f in ("scanner", "curtain", "none")}
        full = [r[3] for r in rows if r[3] is not None]
        mean_by = f"{sum(full) / len(full):.0f}" if full else "-"
        strict = sum(len(r[4]) == 3 for r in rows)
        print(f"| {name} | {len(full)}/{n} | {have['scanner']}/{n} | {have['curtain']}/{n} | {have['none']}/{n} | "
              f"{strict}/{n} | {sum(r[1] for r in rows) / n:.1f} | {sum(r[2] for r in rows) / n:.0f} | {mean_by} |")


if __name__ == "__main__":
    main()
