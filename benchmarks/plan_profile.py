"""Where the ``plan`` searcher's time goes: one search, with its model's parts timed.

    python benchmarks/plan_profile.py [--cell door-locked] [--budget 300] [--seed 0]

Runs ``cellstress.search(CELL, searcher="plan", budget=..., until="budget")`` once in this process (run any
command once first so that the kernels are compiled) and prints the wall time of the whole search and the
seconds spent in ``_Model.predict`` (scoring the candidate sequences before each episode), within it building
and querying the k-d tree of learned worker poses (which devices see a pose), ``Simulator.worker_paths_from`` and
``Simulator.worker_distances``, and in ``_Model.learn``. The timers wrap the calls; the search itself is the
same (same episodes, same result).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import defaultdict
from pathlib import Path

import scipy.spatial

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import cellstress  # noqa: E402
from cellstress.searchers import plan  # noqa: E402
from cellstress.sim.simulator import Simulator  # noqa: E402

SPENT: dict[str, float] = defaultdict(float)
KDTree = scipy.spatial.cKDTree


class TimedTree:
    """cKDTree with its construction and queries timed (``plan`` imports it from scipy.spatial at each call)."""

    def __init__(self, data):
        t0 = time.perf_counter()
        self.tree = KDTree(data)
        SPENT["k-d tree build"] += time.perf_counter() - t0

    def query(self, x, *args, **kwargs):
        t0 = time.perf_counter()
        out = self.tree.query(x, *args, **kwargs)
        SPENT["k-d tree query"] += time.perf_counter() - t0
        return out


def timed(owner, name: str, label: str) -> None:
    inner = getattr(owner, name)

    def call(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            SPENT[label] += time.perf_counter() - t0

    setattr(owner, name, call)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cell", default="door-locked")
    ap.add_argument("--budget", type=int, default=300)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    scipy.spatial.cKDTree = TimedTree
    timed(plan._Model, "predict", "predict (all)")
    timed(plan._Model, "learn", "learn")
    timed(Simulator, "worker_paths_from", "worker_paths")  # (worker_paths calls it)
    timed(Simulator, "worker_distances", "worker_distances")
    t0 = time.perf_counter()
    res = cellstress.search(args.cell, searcher="plan", budget=args.budget, seed=args.seed, until="budget")
    wall = time.perf_counter() - t0
    print(f"{args.cell}, plan, budget {args.budget}, seed {args.seed}: {wall:.1f} s, {res.episodes} episodes "
          f"({1000.0 * wall / max(1, res.episodes):.0f} ms each)")
    for label in ("predict (all)", "k-d tree build", "k-d tree query", "worker_paths", "worker_distances", "learn"):
        print(f"  {label:18s} {SPENT[label]:8.2f} s  {SPENT[label] / wall:6.1%}")


if __name__ == "__main__":
    main()
