"""The swept contact test against finely sampled motion (issue 34): no contact missed, false alarms counted.

    python benchmarks/sweep_check.py [--cells baseline s3-fence-gap] [--episodes 10000] [--sub 10] [--speed]

Per cell: ``--episodes`` uniformly random episodes of the cell's own length (a numpy Generator seeded with
``--seed`` and the cell's name, so a cell's episodes do not depend on which other cells are listed), from its
start point at its own arrival phase, played twice on the same continuous motion (``kernels.sweep``: the worker
on the straight line between its sampled poses, the robot on its path):

* swept: the simulator as it is, contact tested in continuous time between the 50 ms steps (``run_batch``);
* fine: contact tested at every step and at ``--sub - 1`` moments evenly between (10: every 5 ms), with no bound
  (``kernels.dense.dense_batch``).

``missed``: episodes the fine sampling finds unsafe at a step the swept test had not found unsafe by then (must
be 0). ``alarms``: episodes the swept test ends earlier than the fine sampling, or where the fine sampling finds
nothing (conservative flags at its finest sub-step, or contacts between the fine samples). ``--speed`` also
times run_batch with the swept test on and off (medians of 3, alternating) and each cell's share of baseline's
rate.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
import zlib

import numpy as np

from cellstress.cell.load import BUILTIN_CELLS
from cellstress.sim import layout as L
from cellstress.sim.kernels.dense import dense_batch
from cellstress.sim.simulator import Simulator


def unswept(sim: Simulator) -> Simulator:
    """The same cell with contact tested at the steps alone."""
    scal = sim.params.scal.copy()
    scal[L.C_SWEEP] = 0.0
    return Simulator(dataclasses.replace(sim.layout, params=sim.params._replace(scal=scal)), start=sim.start)


def compare(sim: Simulator, actions: np.ndarray, n_sub: int) -> tuple[int, int, int, int, np.ndarray]:
    """(fine unsafe, swept unsafe, missed, alarms, the missed episodes' indices) over the episodes."""
    swept = sim.run_batch(actions).unsafe_step
    fine = np.empty(len(actions), dtype=np.int64)
    dense_batch(sim.params, sim.reset(), np.ascontiguousarray(actions, dtype=np.int64), n_sub, fine)
    which = np.flatnonzero((fine >= 0) & ((swept < 0) | (swept > fine)))
    alarms = int(np.count_nonzero((swept >= 0) & ((fine < 0) | (fine > swept))))
    return int(np.count_nonzero(fine >= 0)), int(np.count_nonzero(swept >= 0)), len(which), alarms, which


def rate(sim: Simulator, actions: np.ndarray) -> float:
    t0 = time.perf_counter()
    sim.run_batch(actions)
    return len(actions) / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cells", nargs="+", default=list(BUILTIN_CELLS))
    ap.add_argument("--episodes", type=int, default=10_000)
    ap.add_argument("--sub", type=int, default=10)
    ap.add_argument("--speed", action="store_true")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--show-missed", action="store_true", help="list the missed episodes' indices")
    args = ap.parse_args()
    base_rate = None
    print(f"{'cell':24s} {'fine':>6s} {'swept':>6s} {'missed':>6s} {'alarms':>6s}"
          + ("   swept ep/s  unswept ep/s  ratio  of baseline" if args.speed else ""))
    total_missed = 0
    for cell in args.cells:
        sim = Simulator(cell)
        rng = np.random.default_rng([args.seed, zlib.crc32(cell.encode())])
        acts = rng.integers(0, sim.n_actions, size=(args.episodes, sim.actions_per_episode))
        fine, swept, missed, alarms, which = compare(sim, acts, args.sub)
        total_missed += missed
        line = f"{cell:24s} {fine:6d} {swept:6d} {missed:6d} {alarms:6d}"
        if args.speed:
            flat = unswept(sim)
            sim.run_batch(acts[:500])
            flat.run_batch(acts[:500])
            on, off = [], []
            for _ in range(3):
                on.append(rate(sim, acts))
                off.append(rate(flat, acts))
            on_m, off_m = statistics.median(on), statistics.median(off)
            if base_rate is None and cell == "baseline":
                base_rate = on_m
            share = f"{on_m / base_rate:6.2f}" if base_rate else "     -"
            line += f"   {on_m:10.0f}  {off_m:12.0f}  {on_m / off_m:5.2f}  {share}"
        print(line, flush=True)
        if args.show_missed and len(which):
            print(f"  missed episodes: {which.tolist()}", flush=True)
    print(f"missed in all: {total_missed}")


if __name__ == "__main__":
    main()
