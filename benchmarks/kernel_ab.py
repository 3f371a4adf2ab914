"""A/B speed of two source trees of cellstress, interleaved in one run (fair on a noisy machine).

    python benchmarks/kernel_ab.py OLD_SRC NEW_SRC [--cells baseline s3-fence-gap] [--episodes 20000]
                                   [--rounds 3] [--step | --worker | --plan BUDGET] [--threads 1]

OLD_SRC / NEW_SRC are folders holding a ``cellstress`` package (e.g. ``git archive HEAD~3 src | tar -x -C
/tmp/old`` gives /tmp/old/src). Each measurement is a fresh process with one numba thread timing
``run_batch`` (best CPU time of 3 calls after a warm-up); rounds alternate A and B. Prints the median
episodes/s per tree and cell, and their ratio. ``--step`` times ``Simulator.step`` instead (whole episodes
stepped from Python, as a tree search does; a tenth of the episodes). ``--worker`` times the plan searcher's
worker-only kernels (``worker_paths`` of a twentieth of the episodes, then ``worker_distances`` to 4 points
per pose). ``--plan BUDGET`` times one whole ``plan`` search of BUDGET episodes (``--until budget``, seed 0;
wall time of one search after a warm-up search of 3 episodes), the candidates' prediction included.
``--threads`` sets numba's threads per process (1 by default; the worker kernels are parallel).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys

CHILD = r"""
import sys, time, numpy as np
from cellstress.sim.simulator import Simulator
sim = Simulator(sys.argv[1]); n = int(sys.argv[2])
acts = np.random.default_rng(0).integers(0, 30, size=(n, sim.actions_per_episode))
sim.run_batch(acts[:500])
best = float("inf")
for _ in range(3):
    t0 = time.process_time(); sim.run_batch(acts); best = min(best, time.process_time() - t0)
print(n / best)
"""

CHILD_STEP = r"""
import sys, time, numpy as np
from cellstress.sim.simulator import Simulator
sim = Simulator(sys.argv[1]); n = int(sys.argv[2]) // 10
acts = np.random.default_rng(0).integers(0, 30, size=(n, sim.actions_per_episode)).tolist()
def play(episodes):
    for ep in episodes:
        s = sim.reset()
        for a in ep:
            s, _ = sim.step(s, a)
            if sim.is_unsafe(s):
                break
play(acts[:100])
best = float("inf")
for _ in range(3):
    t0 = time.process_time(); play(acts); best = min(best, time.process_time() - t0)
print(n / best)
"""

CHILD_WORKER = r"""
import sys, time, numpy as np
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator
sim = Simulator(sys.argv[1]); n = int(sys.argv[2]) // 20
rng = np.random.default_rng(0)
acts = rng.integers(0, 30, size=(n, sim.actions_per_episode))
def play(a):
    poses = sim.worker_paths(a).reshape(-1, L.N_POSE)
    pts = poses[:, None, :3] + rng.normal(0.0, 0.6, size=(len(poses), 4, 3)) + np.array([0.0, 0.0, 1.0])
    sim.worker_distances(poses, pts)
play(acts[:50])
best = float("inf")
for _ in range(3):
    t0 = time.process_time(); play(acts); best = min(best, time.process_time() - t0)
print(n / best)
"""

CHILD_PLAN = r"""
import sys, time
import cellstress
cell, budget = sys.argv[1], int(sys.argv[2])
cellstress.search(cell, searcher="plan", budget=3, seed=0, until="budget")
t0 = time.perf_counter()
cellstress.search(cell, searcher="plan", budget=budget, seed=0, until="budget")
print(budget / (time.perf_counter() - t0))
"""


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--cells", nargs="+", default=["baseline", "s3-fence-gap"])
    ap.add_argument("--episodes", type=int, default=20_000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--step", action="store_true", help="time Simulator.step instead of run_batch")
    ap.add_argument("--worker", action="store_true",
                    help="time the plan searcher's worker-only kernels (worker_paths, worker_distances)")
    ap.add_argument("--plan", type=int, metavar="BUDGET", help="time one plan search of BUDGET episodes")
    ap.add_argument("--threads", type=int, default=1, help="numba threads per process")
    args = ap.parse_args(argv)
    for cell in args.cells:
        rates: dict[str, list[float]] = {args.old: [], args.new: []}
        child = CHILD_PLAN if args.plan else CHILD_WORKER if args.worker else CHILD_STEP if args.step else CHILD
        n = args.plan or args.episodes
        for _ in range(args.rounds):
            for tree in (args.old, args.new):
                env = dict(os.environ, PYTHONPATH=tree, NUMBA_NUM_THREADS=str(args.threads))
                out = subprocess.run([sys.executable, "-c", child, cell, str(n)], env=env,
                                     capture_output=True, text=True, check=True)
                rates[tree].append(float(out.stdout.split()[-1]))
        a, b = statistics.median(rates[args.old]), statistics.median(rates[args.new])
        what = f"plan, {args.plan} episodes" if args.plan else "worker kernels" if args.worker else "step" \
            if args.step else "run_batch"
        what += f", {args.threads} thread{'s' if args.threads > 1 else ''}"
        f = ",.2f" if args.plan else ",.0f"  # (a plan search plays a few episodes a second)
        print(f"{cell:20s} old {a:9{f}}  new {b:9{f}} episodes/s ({what})  new/old {b / a:.2f}"
              f"   (rounds: old {' '.join(f'{r:{f}}' for r in rates[args.old])};"
              f" new {' '.join(f'{r:{f}}' for r in rates[args.new])})", flush=True)


if __name__ == "__main__":
    main()
