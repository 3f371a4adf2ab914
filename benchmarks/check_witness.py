"""``check --witness`` on the built-in cells: for every row the static check fails, whether a simulated worker
takes that way in (``analysis.witness``), aimed at the row's robot point and moment against the same search
unaimed.

    python benchmarks/check_witness.py [--cells all | NAME ...] [--seeds 5] [--budget 200] [--moved]
                                       [--modes aimed unaimed]

Per failing row, one Markdown line: the row's limit (what the simulated worker cannot do: not searched), or, aimed
and unaimed, the runs of ``--seeds`` that found a witness of the row and the median episode of it (a run without
counts as the budget). ``--moved`` also runs each cell with the worker's start moved to the floor's four corners
(0.6 m in; a corner where the worker cannot stand is left out): further from the flaw, where the aim has more to
tell.
"""

from __future__ import annotations

import argparse
import statistics

import yaml

from cellstress.analysis.check_rows import check_rows
from cellstress.analysis.iso13855 import check_cell
from cellstress.analysis.program_check import check_programs
from cellstress.analysis.witness import witness_searches
from cellstress.cell.load import BUILTIN_CELLS, builtin_text, parse_cell
from cellstress.core.errors import CellstressError
from cellstress.sim.simulator import Simulator

INSET = 0.6  # m: the moved starts' distance from the floor's edges


def variants(name: str, moved: bool):
    yield name, Simulator(name)
    if not moved:
        return
    d = yaml.safe_load(builtin_text(name))
    if d["human"].get("starts"):
        return  # a cell of several start points already has its own
    fl = d.get("floor", {})
    xs = (fl.get("xmin", -5.0) + INSET, fl.get("xmax", 5.0) - INSET)
    ys = (fl.get("ymin", -5.0) + INSET, fl.get("ymax", 5.0) - INSET)
    for x in xs:
        for y in ys:
            v = dict(d, name=f"{name}@{x:g},{y:g}")
            v["human"] = dict(d["human"], start=dict(d["human"]["start"], xy=[x, y]))
            try:
                sim = Simulator(parse_cell(yaml.safe_dump(v, sort_keys=False), v["name"], None))
            except CellstressError:
                continue
            yield v["name"], sim


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", nargs="+", default=["all"])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--moved", action="store_true")
    ap.add_argument("--modes", nargs="+", choices=("aimed", "unaimed"), default=["aimed", "unaimed"],
                    help="the columns to run (each alone: two processes on two cores)")
    args = ap.parse_args()
    modes = tuple(m == "aimed" for m in args.modes)
    cells = sorted(BUILTIN_CELLS) if args.cells == ["all"] else args.cells
    print(f"| cell | row | limit | aimed: witnessed of {args.seeds}, median episode | unaimed |")
    print("|---|---|---|---|---|")
    totals = {m: [0, 0] for m in modes}
    for base in cells:
        for name, sim in variants(base, args.moved):
            static = check_cell(sim.cell, sim.layout)
            rows = check_rows(static, check_programs(sim.layout))
            if all(r.ok for r in rows):
                continue
            got = {aimed: [witness_searches(sim, rows, args.budget, seed, aimed=aimed) for seed in range(args.seeds)]
                   for aimed in modes}
            for i, w in enumerate(got[modes[0]][0]):
                if w.result is None:
                    print(f"| {name} | {w.row} | {w.limit[:70]} | - | - |", flush=True)
                    continue
                cols = []
                for aimed in (True, False):
                    if aimed not in got:
                        cols.append("-")
                        continue
                    eps = [g[i].witness.episode if g[i].witness is not None else args.budget for g in got[aimed]]
                    hits = sum(g[i].witness is not None for g in got[aimed])
                    totals[aimed][0] += hits
                    totals[aimed][1] += sum(eps)
                    cols.append(f"{hits}, {statistics.median(eps):g}")
                text = "" if w.aim is not None or not modes[0] else " (no point)"
                print(f"| {name} | {w.row}{text} | | {cols[0]} | {cols[1]} |", flush=True)
    for aimed in modes:
        print(f"\n{'aimed' if aimed else 'unaimed'}: {totals[aimed][0]} witnessed runs, {totals[aimed][1]} episodes "
              "in all (a run without a witness counts as the budget)")


if __name__ == "__main__":
    main()
