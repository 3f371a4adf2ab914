"""What searching the arrival phase costs and finds: each flawed cell with its fixed phase (the paper's) and with
``human.arrival: cycle`` (the search chooses the phase), per searcher, over seeds.

    python benchmarks/arrival_phase.py [--seeds 10] [--budget 200] [--searchers random evolve plan]

Prints, per cell, arrival and searcher: runs that found a hazard, and the mean and median episodes to the first
hazard (a run that found none counts as the budget). The cell files with ``arrival: cycle`` are the built-ins
with that one field changed.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from importlib import resources
from pathlib import Path

import yaml

from cellstress.cell.load import load_cell, parse_cell
from cellstress.searchers import search
from cellstress.sim.simulator import Simulator

CELLS = ("s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")


def cycle_cell(name: str, folder: Path):
    data = yaml.safe_load(resources.files("cellstress.cell").joinpath("builtin", f"{name}.yaml").read_text())
    data["human"]["arrival"] = "cycle"
    return parse_cell(yaml.safe_dump(data), str(folder / f"{name}-cycle.yaml"), folder)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--searchers", nargs="+", default=["random", "evolve", "plan"])
    args = ap.parse_args()
    print(f"| cell | arrival | searcher | found | mean episodes | median | (seeds 0-{args.seeds - 1}, budget "
          f"{args.budget}) |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in CELLS:
            for arrival, cell in (("fixed", load_cell(name)), ("cycle", cycle_cell(name, Path(tmp)))):
                sim = Simulator(cell)
                for s in args.searchers:
                    eps, found = [], 0
                    for seed in range(args.seeds):
                        r = search(sim, s, budget=args.budget, seed=seed)
                        found += r.found
                        eps.append(r.episodes if r.found else args.budget)
                    print(f"| {name} | {arrival} | {s} | {found}/{args.seeds} | {statistics.mean(eps):.1f} | "
                          f"{statistics.median(eps):g} | |", flush=True)


if __name__ == "__main__":
    main()
