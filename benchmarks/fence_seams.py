"""A wall of collinear runs against the same wall as one run: speed and distances.

    python benchmarks/fence_seams.py [--cells s3-fence-gap reach-over] [--episodes 500] [--repeats 3]

Each fence of the cell is drawn a second time with a point added in the middle of every panel (the same
walls, each panel now two runs meeting end to end in a straight line). Both cells play the same uniformly
random episodes (numpy Generator, seed 0) through ``run_batch``, timed alternately; the table gives the
medians, their ratio, and the largest difference of d_HR over every step of every episode (the seams must
not change a distance). A cell without fences is skipped.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
import yaml

from cellstress.cell.load import builtin_file, builtin_text, parse_cell
from cellstress.sim.simulator import Simulator


def split_fences(text: str) -> str | None:
    """The cell's YAML with a point added in the middle of every fence panel; None without fences."""
    data = yaml.safe_load(text)
    if not data.get("fences"):
        return None
    for fence in data["fences"]:
        pts = fence["points"]
        out = [pts[0]]
        for a, b in zip(pts, pts[1:], strict=False):
            out += [[(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0], b]
        fence["points"] = out
    return yaml.safe_dump(data, sort_keys=False)


def timed(sim: Simulator, actions: np.ndarray) -> tuple[float, np.ndarray]:
    t0 = time.perf_counter()
    metrics = sim.run_batch(actions)
    return actions.shape[0] / (time.perf_counter() - t0), metrics


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", nargs="+", default=["s3-fence-gap", "reach-over", "door-locked", "crawl-under"])
    ap.add_argument("--episodes", type=int, default=500)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"run_batch, {args.episodes} episodes, {args.repeats} alternating repeats")
    print()
    print("| cell | panels | one run ep/s | split ep/s | split / one run | largest d_HR difference [m] "
          "| same first unsafe step |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for cell in args.cells:
        text = builtin_text(cell)
        split = split_fences(text)
        if split is None:
            print(f"| {cell} | 0 | – | – | – | – | – |")
            continue
        where = Path(builtin_file(cell)).parent
        sims = [Simulator(parse_cell(text, cell, where)), Simulator(parse_cell(split, f"{cell} (split)", where))]
        acts = np.random.default_rng(0).integers(0, sims[0].n_actions, size=(args.episodes,
                                                                             sims[0].actions_per_episode))
        for sim in sims:
            sim.run_batch(acts[:20])  # warm-up
        rates: list[list[float]] = [[], []]
        rows = [None, None]
        for _ in range(args.repeats):
            for k, sim in enumerate(sims):
                rate, rows[k] = timed(sim, acts)
                rates[k].append(rate)
        diff = float(np.nanmax(np.abs(rows[0].d_end - rows[1].d_end)))
        same_end = int(np.sum(rows[0].unsafe_step == rows[1].unsafe_step))
        a, b = statistics.median(rates[0]), statistics.median(rates[1])
        print(f"| {cell} | {len(sims[0].params.fences)} -> {len(sims[1].params.fences)} | {a:,.0f} | {b:,.0f} "
              f"| {b / a:.2f} | {diff:.2e} | {same_end} / {args.episodes} |", flush=True)


if __name__ == "__main__":
    main()
