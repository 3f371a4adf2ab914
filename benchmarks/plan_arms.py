"""``plan`` with the articulated worker: its d_HR predicted to the body capsules (now) or to the reach volumes
(before issue 20's searcher change), 10 seeds x 200 episodes per cell.

    python benchmarks/plan_arms.py [--cells reach-over,s1-scanner-width,s3-fence-gap] [--seeds 10] [--budget 200]
                                   [--modes capsules,envelope]

A built-in cell with the paper's worker is searched with ``human.model: articulated`` added (its body kept), as
``sim_speed.py --workers`` builds it. ``envelope`` replaces ``plan``'s worker distance by
``Simulator.worker_distances`` (reach volumes and body), which is what ``plan`` used before. Prints one Markdown
row per cell and mode: runs that found a hazard, mean and largest episodes to the first (a miss counts as the
budget), the episodes of each run, and the wall time.
"""

from __future__ import annotations

import argparse
import statistics
import time

from sim_speed import with_worker

from cellstress.searchers import plan, search

CELLS = ("reach-over", "s1-scanner-width", "s3-fence-gap")


def envelope(model, poses, points):
    return model.sim.worker_distances(poses, points)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", default=",".join(CELLS))
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--modes", default="capsules,envelope")
    args = ap.parse_args()
    capsules = plan._Model.distances
    print("| cell (articulated) | plan's worker distance | found | mean episodes | max episodes | episodes | wall |")
    print("|---|---|---|---|---|---|---|")
    for cell in args.cells.split(","):
        sim = with_worker(cell, "articulated")
        for mode in args.modes.split(","):
            plan._Model.distances = capsules if mode == "capsules" else envelope
            t0, eps = time.perf_counter(), []
            for seed in range(args.seeds):
                r = search(sim, "plan", budget=args.budget, seed=seed)
                eps.append(r.episodes if r.found else None)
            filled = [e if e is not None else args.budget for e in eps]
            print(f"| {cell} | {mode} | {sum(e is not None for e in eps)}/{args.seeds} | "
                  f"{statistics.mean(filled):.1f} | {max(filled)} | {', '.join(str(e or '-') for e in eps)} | "
                  f"{time.perf_counter() - t0:.0f} s |", flush=True)
    plan._Model.distances = capsules


if __name__ == "__main__":
    main()
