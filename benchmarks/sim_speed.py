"""Simulator speed: batched episodes/s (``run_batch``) and single-episode stepping (``Simulator.step``).

    python benchmarks/sim_speed.py [--cells baseline s3-fence-gap] [--episodes 100000] [--repeats 5]
    python benchmarks/sim_speed.py --workers [--cells s3-fence-gap] [--episodes 20000] [--repeats 7]

Per cell: median and min over the repeats of episodes/s, the ratio of the median to the target
(run_batch >= 20,000 episodes/s, stepping >= 3,000 episodes/s), and memory (reach field, state, metric row).
Actions are uniformly random (numpy Generator, seed 0); every measurement follows a warm-up call.

``--workers`` compares the two worker models on the same cell (issue 20: the articulated worker's batches at
>= 20 % of the paper worker's speed): the cell as it is and with ``human.model: articulated`` (the same body),
run_batch timed alternately, one then the other, so that both see the same load; medians of the repeats and
their ratio. Each model plays uniformly random actions of its own (30 or 112).
"""

from __future__ import annotations

import argparse
import re
import statistics
import time

import numpy as np

from cellstress.cell.load import builtin_text, parse_cell
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator

CELLS = ("baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")
TARGET_BATCH = 20_000.0
TARGET_STEP = 3_000.0


def batch_rates(sim: Simulator, actions: np.ndarray, repeats: int) -> list[float]:
    sim.run_batch(actions[:1000])  # warm-up (compiles or loads the cache, starts the thread pool)
    return [batch_rate(sim, actions) for _ in range(repeats)]


def batch_rate(sim: Simulator, actions: np.ndarray) -> float:
    t0 = time.perf_counter()
    sim.run_batch(actions)
    return actions.shape[0] / (time.perf_counter() - t0)


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


def with_worker(cell: str, model: str) -> Simulator:
    """The built-in ``cell`` with its worker model set to ``model`` (the rest of the file as it is)."""
    head, human = builtin_text(cell).split("\nhuman:\n", 1)
    human = re.sub(r"^  model: \S+", f"  model: {model}", human, count=1, flags=re.M) if "\n  model:" in \
        "\n" + human.split("\ncriterion:", 1)[0] else f"  model: {model}\n{human}"
    return Simulator(parse_cell(f"{head}\nhuman:\n{human}", f"{cell} ({model})", None))


def compare_workers(cells: list[str], episodes: int, repeats: int) -> None:
    print(f"run_batch, {episodes} episodes per call, {repeats} interleaved repeats per model")
    print()
    print("| cell | paper ep/s median | articulated ep/s median | articulated / paper | paper min..max "
          "| articulated min..max |")
    print("|---|---:|---:|---:|---:|---:|")
    for cell in cells:
        sims = {m: with_worker(cell, m) for m in ("paper", "articulated")}
        acts = {m: np.random.default_rng(0).integers(0, s.n_actions, size=(episodes, s.actions_per_episode))
                for m, s in sims.items()}
        rates: dict[str, list[float]] = {m: [] for m in sims}
        for m, s in sims.items():
            s.run_batch(acts[m][:1000])  # warm-up
        for _ in range(repeats):
            for m, s in sims.items():
                rates[m].append(batch_rate(s, acts[m]))
        p, a = statistics.median(rates["paper"]), statistics.median(rates["articulated"])
        print(f"| {cell} | {p:,.0f} | {a:,.0f} | {a / p:.2f} | {min(rates['paper']):,.0f}..{max(rates['paper']):,.0f} "
              f"| {min(rates['articulated']):,.0f}..{max(rates['articulated']):,.0f} |", flush=True)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", nargs="+", default=list(CELLS))
    ap.add_argument("--episodes", type=int, default=100_000, help="episodes per run_batch call")
    ap.add_argument("--step-episodes", type=int, default=None,
                    help="episodes per stepping run (default: episodes / 10)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--workers", action="store_true", help="the paper worker against the articulated one per cell")
    args = ap.parse_args(argv)
    if args.workers:
        compare_workers(args.cells if args.cells != list(CELLS) else ["s3-fence-gap"], args.episodes, args.repeats)
        return
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
