"""Searchers on the flawed cells over any range of seeds (the campaign runs seeds 0..N-1 only).

python benchmarks/search_seeds.py [--searchers random,mcts,mcts-commit,evolve] [--seeds 0:40] [--budget 200]
                                  [--cells s1-scanner-width,...] [--set NAME=JSON ...]

Each run stops at its first hazard; a failed run counts as the budget (as in the campaign). ``--set`` passes an
option to every searcher that has it (e.g. ``--set score='"risk"'`` for evolve). Prints one Markdown row per
searcher: found and mean episodes per cell. Same code path as the campaign (``run_search`` on the cell ``Simulator``).
"""

from __future__ import annotations

import argparse
import json
import statistics
from dataclasses import fields

from cellstress.searchers import make_searcher, run_search, searcher_class
from cellstress.sim.simulator import Simulator

CELLS = ("s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--searchers", default="random,mcts,mcts-commit,evolve")
    ap.add_argument("--seeds", default="0:40", help="first:stop")
    ap.add_argument("--cells", default=",".join(CELLS), help="comma-separated flawed cells")
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--set", action="append", default=[], metavar="NAME=JSON")
    args = ap.parse_args()
    lo, hi = (int(v) for v in args.seeds.split(":"))
    opts = {k: json.loads(v) for k, v in (s.split("=", 1) for s in args.set)}
    cells = args.cells.split(",")
    problems = {}
    for c in cells:
        sim = Simulator(c)
        problems[c] = (sim, sim.criterion.reward(sim.actions_per_episode))
    print("| seeds | searcher | " + " | ".join(f"{c} found | {c} mean" for c in cells) + " |")
    print("|---|---|" + "---:|---:|" * len(cells))
    for name in args.searchers.split(","):
        known = {f.name for f in fields(searcher_class(name))}
        mine = {k: v for k, v in opts.items() if k in known}
        cols = []
        for c in cells:
            problem, reward = problems[c]
            eps, found = [], 0
            for seed in range(lo, hi):
                out = run_search(problem, reward, make_searcher(name, **mine), args.budget, seed)
                found += out.found
                eps.append(out.first_hazard.index if out.found else args.budget)
            cols.append(f"{found}/{len(eps)} | {statistics.mean(eps):.1f}")
        label = name + "".join(f" {k}={v}" for k, v in mine.items())
        print(f"| {lo}–{hi - 1} | {label} | " + " | ".join(cols) + " |", flush=True)


if __name__ == "__main__":
    main()
