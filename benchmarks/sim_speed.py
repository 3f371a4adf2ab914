"""Simulator speed: batched episodes/s (``run_batch``) and single-episode stepping (``Simulator.step``).

    python benchmarks/sim_speed.py [--cells baseline s3-fence-gap] [--episodes 100000] [--repeats 5]

Per cell: median and min over the repeats of episodes/s, the ratio of the median to the target
(run_batch >= 20,000 episodes/s, stepping >= 3,000 episodes/s), and memory (reach field, state, metric row).
Actions are uniformly random (numpy Generator, seed 0); every measurement follows a warm-up call.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

CELLS = ("baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")
TARGET_BATCH = 20_000.0
TARGET_STEP = 3_000.0


def batch_rates(sim: Simulator, actions: np.ndarray, repeats: int) -> list[float]:
    sim.run_batch(actions[:1000])  # warm-up (compiles or loads the cache, starts the thread pool)
    rates = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        sim.run_batch(actions)
        rates.append(actions.shape[0] / (time.perf_counter() - t0))
    return rates


def step_episodes(sim: Simulator, actions: np.ndarray) -> None:
    step, unsafe = sim.step, sim.is_unsafe
    for ep in actions.tolist():
        s = sim.reset()
        for a in ep:
            s, _ = step(s, a)
            if unsafe(s):
                break


def step_rates(sim: Simulator, actions: np.ndarray, repeats: int) -> list[float]:
    step_episodes(sim, actions[:200])  # warm-up
    rates = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        step_episodes(sim, actions)
        rates.append(actions.shape[0] / (time.perf_counter() - t0))
    return rates


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", nargs="+", default=list(CELLS))
    ap.add_argument("--episodes", type=int, default=100_000, help="episodes per run_batch call")
    ap.add_argument("--step-episodes", type=int, default=None,
                    help="episodes per stepping run (default: episodes / 10)")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    n_step = args.step_episodes or max(1, args.episodes // 10)

    rows = []
    for cell in args.cells:
        sim = Simulator(cell)
        acts = np.random.default_rng(0).integers(0, sim.n_actions, size=(args.episodes, sim.actions_per_episode))
        b = batch_rates(sim, acts, args.repeats)
        s = step_rates(sim, acts[:n_step], args.repeats)
        state = sim.reset()
        rows.append((cell, statistics.median(b), min(b), statistics.median(s), min(s),
                     sim.layout.reach.nbytes,
                     state.nbytes, L.NM * 8))
        print(f"# {cell}: done", flush=True)

    print()
    print(f"run_batch: {args.episodes} episodes x {args.repeats} repeats; "
          f"step: {n_step} episodes x {args.repeats} repeats; targets {TARGET_BATCH:,.0f} / {TARGET_STEP:,.0f} ep/s")
    print()
    print("| cell | batch ep/s median | batch ep/s min | batch / target | step ep/s median | step ep/s min "
          "| step / target | reach field bytes | state bytes | metric row bytes |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for cell, bm, bmin, sm, smin, reach, st, row in rows:
        print(f"| {cell} | {bm:,.0f} | {bmin:,.0f} | {bm / TARGET_BATCH:.2f} | {sm:,.0f} | {smin:,.0f} "
              f"| {sm / TARGET_STEP:.2f} | {reach:,} | {st} | {row} |")


if __name__ == "__main__":
    main()
