"""Reach-over cells from 1.0 to 1.6 m (issue 34): does the articulated worker's search find what the static check
fails, or does the check name the limit of the simulated worker?

    python benchmarks/reach_over_grid.py [--tops 1.0 1.2 1.4 1.6] [--step 0.2] [--budget 200] [--seed 0]
                                         [--witness]

Each cell is ``reach-over`` with its front panel at another height b and moved so that the robot's hazard zone
lies c behind it (the panel, the side walls' front ends and the worker's start, 0.75 m in front of the panel, move
together; nothing else changes). For each b the hazard height a is the static check's own (the zone's nearest
point in the band of Table 2 that asks the most), and c runs in steps of ``--step`` from ``--step`` up to
min(c_iso, c_body): ISO 13857 Table 2 calls the panel open (c < c_iso) and the body bound
(``human.reach_bound``: any model of a p95 man, trunk bent to 180 degrees, on tiptoe) says the body can get there.
Per cell: the check's reach-over row and its ``limit`` (what the simulated worker cannot do), the other rows it
fails, and `plan`'s first hazard within the budget (seed fixed). A cell agrees when plan finds the hazard or every
row the check fails names a limit. ``--witness``: instead of one search, ``check --witness``'s searches
(``analysis.witness``), and a cell agrees when every failing row has a witness that takes its own way in or names
a limit; the plan column then counts the rows witnessed / named a limit / not reproduced.
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from cellstress.analysis.check_rows import check_rows  # noqa: E402
from cellstress.analysis.iso13855 import check_cell  # noqa: E402
from cellstress.analysis.witness import witness_searches  # noqa: E402
from cellstress.api import search  # noqa: E402
from cellstress.cell.load import builtin_text, parse_cell  # noqa: E402
from cellstress.human.reach_bound import body_bound, c_bound  # noqa: E402
from cellstress.sim.simulator import Simulator  # noqa: E402

BASE = "reach-over"
START_GAP = 0.75  # m: the worker's start in front of the panel, as in reach-over


def variant(base: dict, top: float, y: float):
    """reach-over with its front panel of height ``top`` at y (the walls' front ends and the start with it)."""
    d = copy.deepcopy(base)
    front, left, right = d["fences"][0], d["fences"][1], d["fences"][2]
    front["top"] = top
    front["points"] = [[front["points"][0][0], y], [front["points"][1][0], y]]
    left["points"][0] = [left["points"][0][0], y]
    right["points"][0] = [right["points"][0][0], y]
    d["human"]["start"]["xy"] = [d["human"]["start"]["xy"][0], round(y + START_GAP, 6)]
    d["name"] = f"reach-over-b{top:g}-y{y:.3f}"
    return parse_cell(yaml.safe_dump(d, sort_keys=False), d["name"], None)


def panel_reach(cell):
    """The static check's Table 2 verdict at the front panel (fence 1, the first), its reach-over row, and every
    row it fails."""
    static = check_cell(cell)
    reach = [pr.reach for a in (static.approach, *static.robot_approaches) for pr in a.panels_at if pr.panel.fence == 1]
    rows = [r for r in check_rows(static) if r.name.startswith("reach-over")]
    return (reach[0] if reach else None), (rows[0] if rows else None), [r for r in check_rows(static) if not r.ok]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tops", type=float, nargs="*", default=[1.0, 1.2, 1.4, 1.6])
    ap.add_argument("--step", type=float, default=0.2)
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--witness", action="store_true", help="check --witness's searches, one per failing row")
    args = ap.parse_args()
    base = yaml.safe_load(builtin_text(BASE))
    y0 = base["fences"][0]["points"][0][1]
    body = body_bound("p95-male")
    print("| b [m] | a [m] | c [m] | c_iso [m] | c_body [m] | check row | limit | failing rows (limit named) | plan "
          "| episode | s |")
    print("|---:|---:|---:|---:|---:|---|---|---|---|---:|---:|")
    agree = total = 0
    for top in args.tops:
        reach, _, _ = panel_reach(variant(base, top, y0))
        if reach is None:
            print(f"| {top:.1f} | - | - | - | - | no reach-over row at y = {y0} | | | | |")
            continue
        a, zone_y = reach.hazard_height, y0 - reach.behind
        c_iso, c_body = reach.required, c_bound(body, a, top)[0]
        c = args.step
        while c < min(c_iso, c_body) - 1e-9:
            cell = variant(base, top, round(zone_y + c, 3))
            reach_c, row, failing = panel_reach(cell)
            t0 = time.perf_counter()
            if args.witness:
                got = witness_searches(Simulator(cell), tuple(failing), args.budget, args.seed)
                seen = sum(w.witness is not None for w in got)
                named = sum(w.result is None and bool(w.limit) for w in got)
                ok = seen + named == len(got)
                found, episode = f"{seen} / {named} / {len(got) - seen - named}", \
                    ", ".join(str(w.witness.episode) for w in got if w.witness is not None) or "-"
            else:
                res = search(cell, "plan", args.budget, args.seed)
                ok = res.found or all(r.limit for r in failing)
                found, episode = "FOUND" if res.found else "none", res.episodes if res.found else "-"
            secs = time.perf_counter() - t0
            limit = row.limit if row is not None else ""
            agree += ok
            total += 1
            verdict = "FAIL" if row is not None and not row.ok else "ok"
            print(f"| {top:.1f} | {reach_c.hazard_height:.2f} | {reach_c.behind:.3f} | {reach_c.required:.3f} | "
                  f"{c_body:.3f} | {verdict} | {limit or '-'} | "
                  f"{', '.join(f'{r.name} ({bool(r.limit)})' for r in failing)} | {found} | {episode} | {secs:.0f} |",
                  flush=True)
            c += args.step
    print(f"\n{agree} of {total} cells agree (plan finds the hazard, or every row the check fails names the "
          "simulated worker's limit)")


if __name__ == "__main__":
    main()
