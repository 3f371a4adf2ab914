"""Wall time of the Table III campaign (``cellstress campaign``) with 1 and 2 workers, and a worker's start-up.

    python benchmarks/campaign_speed.py [--workers 1 2] [--repeats 3] [--seeds 10] [--budget 200]

Each repeat runs ``python -m cellstress campaign --out <fresh folder> --workers N`` (the default campaign:
3 flawed cells x random, mcts, mcts-commit x seeds, budget 200) as a new process and times it from start to
exit: interpreter start, imports, worker start-up, the runs, the table. Prints the median and minimum per worker
count, the CPU time of all its processes (robust against other jobs on the machine, unlike wall time), checks
that every repeat wrote the same runs.jsonl lines (sorted), and the target (<= 20 s on the project's 2-core
machine). Then, in a freshly spawned worker process (as the campaign starts them), the cost
of each start-up step: imports, the reach field (disk cache), the cell layouts, compiled kernels loaded from
numba's cache, and the first run of each searcher. The numba cache must be warm (run any command once after
changing the simulator): a cold cache compiles for a minute or more.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")
CELLS = ("s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")
SEARCHERS = ("random", "mcts", "mcts-commit")
TARGET_S = 20.0


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = SRC + os.pathsep + env.get("PYTHONPATH", "")  # this checkout
    return env


def _children_cpu() -> float:
    # user + system time of finished descendants: the campaign process and the pool workers it joined
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def time_campaign(workers: int, seeds: int, budget: int) -> tuple[float, float, float, list[str]]:
    """(process wall time, the command's own 'in X s' figure, CPU seconds of all its processes, sorted
    runs.jsonl lines) of one fresh campaign."""
    with tempfile.TemporaryDirectory(prefix="campaign-bench-") as tmp:
        out = Path(tmp) / "out"
        cmd = [sys.executable, "-m", "cellstress", "campaign", "--workers", str(workers), "--seeds", str(seeds),
               "--budget", str(budget), "--out", str(out)]
        cpu0 = _children_cpu()
        t0 = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True, env=_env())
        wall = time.perf_counter() - t0
        cpu = _children_cpu() - cpu0
        if done.returncode != 0:
            raise SystemExit(f"campaign failed ({done.returncode}): {done.stderr}")
        inner = float(re.search(r" in ([0-9.]+) s;", done.stdout).group(1))
        lines = sorted((out / "runs.jsonl").read_text().splitlines())
    return wall, inner, cpu, lines


def startup_profile(threads: int) -> list[tuple[str, float]]:
    """Runs inside a fresh spawned worker: the time of each start-up step, in order."""
    steps: list[tuple[str, float]] = []
    t = time.perf_counter()

    def mark(name: str) -> None:
        nonlocal t
        now = time.perf_counter()
        steps.append((name, now - t))
        t = now

    import numba

    from cellstress.campaign.worker import set_threads

    set_threads(threads)
    from cellstress.cell.load import load_cell
    from cellstress.searchers import search
    from cellstress.sim.build import build_layout
    from cellstress.sim.simulator import Simulator

    mark("imports (numpy, numba, pydantic, cellstress)")
    cells = [load_cell(c) for c in CELLS]
    mark("load and validate 3 cell files (imports pinocchio, reads the UR10 URDF)")
    from cellstress.human.reach import reach_field

    a = cells[0].spec.human.anthropometry
    reach_field(a.upper_arm, a.forearm, a.hand)
    mark("reach field (from the disk cache)")
    layouts = [build_layout(c) for c in cells]
    mark("3 layouts (URDF, capsules, trajectory tables)")
    sims = [Simulator(lay) for lay in layouts]
    mark("3 simulators (compiled kernels loaded from numba's cache)")
    for name in SEARCHERS:
        search(sims[0], name, 2, 0)
    mark("first run of each searcher (their compiled code)")
    del numba
    return steps


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--budget", type=int, default=200)
    args = ap.parse_args(argv)

    print(f"campaign: {len(CELLS)} cells x {len(SEARCHERS)} searchers x {args.seeds} seeds, budget {args.budget}; "
          f"{args.repeats} repeats, {os.cpu_count()} cores, load average before "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}\n")
    print("| workers | wall median [s] | wall min [s] | of which the campaign [s] | CPU, all processes [s] | "
          "target [s] | lines |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    reference: list[str] | None = None
    for w in args.workers:
        walls, inners, cpus = [], [], []
        for _ in range(args.repeats):
            wall, inner, cpu, lines = time_campaign(w, args.seeds, args.budget)
            walls.append(wall)
            inners.append(inner)
            cpus.append(cpu)
            if reference is None:
                reference = lines
            elif lines != reference:
                raise SystemExit(f"runs.jsonl with {w} workers differs from the first campaign's")
        print(f"| {w} | {statistics.median(walls):.1f} | {min(walls):.1f} | {statistics.median(inners):.1f} | "
              f"{statistics.median(cpus):.1f} | {TARGET_S:.0f} | {len(reference)} |")
    print(f"\nall repeats wrote the same runs.jsonl lines (sorted); load average after "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}")

    ctx = multiprocessing.get_context("spawn")
    print("\nstart-up of one worker process (spawned, one numba thread), median of the repeats:\n")
    profiles = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        with ProcessPoolExecutor(1, mp_context=ctx) as pool:
            steps = pool.submit(startup_profile, 1).result()
        profiles.append((steps, time.perf_counter() - t0))
    print("| step | seconds |")
    print("|---|---:|")
    for i, (name, _) in enumerate(profiles[0][0]):
        print(f"| {name} | {statistics.median(p[0][i][1] for p in profiles):.2f} |")
    print(f"| total in the worker | {statistics.median(sum(s for _, s in p[0]) for p in profiles):.2f} |")
    print(f"| process start to result, incl. interpreter and pool | {statistics.median(p[1] for p in profiles):.2f} |")


if __name__ == "__main__":
    main()
