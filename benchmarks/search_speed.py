"""Search speed: episodes/s of each searcher on the reference cells (whole budget, ``until="budget"``).

    python benchmarks/search_speed.py [--cells ...] [--searchers random mcts ...]  (default: every searcher)
                                      [--budget 2000] [--repeats 5] [--threads 1] [--set NAME=JSON ...]

One episode = one iteration (reset to s0 and up to 8 actions). Per cell and searcher: median and min over the
repeats (seeds 0..repeats-1) of episodes/s, and the ratio of the median to the target (mcts >= 2,000
episodes/s on one core). ``--threads 1`` (default) limits numba to one core; the random searcher plays its
episodes in batches (``run_batch``), which use all the threads allowed. Every measurement follows a warm-up.
``--set`` passes an option to every searcher that has it (e.g. ``--set score='"all"'`` for evolve's lookahead).
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from dataclasses import fields

CELLS = ("baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")
TARGET = 2_000.0


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", nargs="+", default=list(CELLS))
    ap.add_argument("--searchers", nargs="+", default=None, help="default: every registered searcher")
    ap.add_argument("--budget", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--threads", type=int, default=1, help="numba threads (0: all cores)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=JSON")
    args = ap.parse_args(argv)
    opts = {k: json.loads(v) for k, v in (s.split("=", 1) for s in args.set)}

    import numba

    if args.threads:
        numba.set_num_threads(args.threads)
    from cellstress.searchers import search, searcher_class, searcher_names
    from cellstress.sim.simulator import Simulator

    rows = []
    for cell in args.cells:
        sim = Simulator(cell)
        for name in args.searchers or list(searcher_names()):
            known = {f.name for f in fields(searcher_class(name))}
            mine = {k: v for k, v in opts.items() if k in known}
            search(sim, name, budget=50, seed=0, until="budget", **mine)  # warm-up
            rates, found = [], 0
            for seed in range(args.repeats):
                t0 = time.perf_counter()
                res = search(sim, name, budget=args.budget, seed=seed, until="budget", **mine)
                rates.append(res.episodes / (time.perf_counter() - t0))
                found += len(res.hazards)
            label = name + "".join(f" {k}={v}" for k, v in mine.items())
            rows.append((cell, label, statistics.median(rates), min(rates), found / args.repeats))
            print(f"# {cell} {label}: {statistics.median(rates):,.0f} episodes/s", flush=True)

    print()
    print(f"{args.budget} episodes per search, {args.repeats} seeds, numba threads {numba.get_num_threads()}; "
          f"target {TARGET:,.0f} episodes/s (mcts, one core)")
    print()
    print("| cell | searcher | episodes/s median | episodes/s min | median / target | hazardous episodes per search |")
    print("|---|---|---:|---:|---:|---:|")
    for cell, name, med, lo, haz in rows:
        print(f"| {cell} | {name} | {med:,.0f} | {lo:,.0f} | {med / TARGET:.2f} | {haz:.1f} |")


if __name__ == "__main__":
    main()
