"""A small grid of the MCTS constants (ec, k, alpha; MCTS2's n), scored against the paper's Table III.

Usage: python benchmarks/mcts_constants.py [--seeds 0:40] [--ec 0.25,0.5,1,2] [--k 0.5,1,2] [--alpha 0.7,0.85]
           [--n none] [--searchers mcts,mcts-commit] [--cells s1-scanner-width,...] [--resample 0] [--workers 2]

Each setting is used for all cells (the same constants for S1, S2, S3); ``--ec``, ``--k``, ``--alpha`` go to both
MCTS searchers, ``--n`` to MCTS2 only (``none``: its default, budget // horizon). For every setting it prints the
Table III rows (random's do not depend on the constants: run once, repeated): found/N, mean episodes (a failure
counts as the budget) with its interval, the mean of the successful runs alone ("hits"), and whether the paper's
success rate lies in our 95 % Wilson interval and its mean in our 95 % Student-t interval (the campaign's own
intervals, ``cellstress.campaign.table``); then the count of paper numbers inside. ``--resample B``: also, per
row, the share of B draws of 10 of our runs (with replacement) that have at most the paper's successes and at
most its mean ("fewer and faster"), or at least both ("more and slower"). A cell file named like a paper cell
(e.g. a physical variant of s2-elbow-intrusion) is compared with that cell's paper rows. Choose on seeds 0:40,
confirm on 40:80. Runs go through the campaign's backend (worker processes); docs/results.md has the results.
"""

from __future__ import annotations

import argparse
import itertools
import time

import numpy as np

from cellstress.campaign import Backend, resolve
from cellstress.campaign.plan import DEFAULT_CELLS, RunSpec
from cellstress.campaign.table import summarize

BUDGET = 200


def floats(text: str) -> list[float]:
    return [float(x) for x in text.split(",") if x.strip()]


def seed_range(text: str) -> range:
    a, b = text.split(":")
    return range(int(a), int(b))


def specs_for(cells: tuple[str, ...], searcher: str, options: dict, seeds: range) -> list[RunSpec]:
    plan = resolve(cells, (searcher,), 1, BUDGET, options)
    return [RunSpec(c, plan.searchers[0], seed, BUDGET) for c in plan.cells for seed in seeds]


def resampled(eps: list[float], found: list[bool], paper, draws: int) -> str:
    """Shares of ``draws`` 10-run experiments drawn from our runs that are 'fewer and faster' or 'more and slower'
    than the paper's row (both of its numbers matched or passed in that direction)."""
    rng = np.random.default_rng(0)
    idx = rng.integers(0, len(eps), size=(draws, paper.runs))
    k = np.asarray(found)[idx].sum(axis=1)
    m = np.asarray(eps)[idx].mean(axis=1)
    low = np.mean((k <= paper.found) & (m <= paper.mean_episodes))
    high = np.mean((k >= paper.found) & (m >= paper.mean_episodes))
    return f" | 10-run draws: fewer+faster {low:.4f}, more+slower {high:.4f}"


def rows_text(records: list[dict], draws: int = 0) -> tuple[list[str], int]:
    """Per row: found/N, mean (its interval), the mean of the successful runs alone, whether the paper's rate
    and mean are inside; and the count of paper numbers inside."""
    cells = list(dict.fromkeys(r["cell"] for r in records))
    rows = summarize(records, cells, ["random", "mcts", "mcts-commit"], BUDGET)
    out, inside = [], 0
    for r in rows:
        p = r.paper
        mine = [x for x in records if (x["cell"], x["searcher"]) == (r.cell, r.searcher)]
        hits = [x["episodes"] for x in mine if x["found"]]
        hit_mean = f"{sum(hits) / len(hits):5.1f}" if hits else "    -"
        rate_in = r.success_ci.lo <= p.found / p.runs <= r.success_ci.hi
        mean_in = r.mean_ci is not None and r.mean_ci.lo <= p.mean_episodes <= r.mean_ci.hi
        inside += rate_in + mean_in
        ci = "" if r.mean_ci is None else f"({r.mean_ci.lo:5.1f}-{r.mean_ci.hi:5.1f})"
        out.append(f"  {r.cell[:2]} {r.searcher:<11} {r.found:>3}/{r.runs} {r.mean_episodes:6.1f} {ci:<14}"
                   f" hits {hit_mean} paper {p.found}/10 {p.mean_episodes:5.1f}: rate {'in ' if rate_in else 'OUT'},"
                   f" mean {'in ' if mean_in else 'OUT'}"
                   + (resampled([x["episodes"] if x["found"] else BUDGET for x in mine], [x["found"] for x in mine],
                                p, draws) if draws else ""))
    return out, inside


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0:40", help="a:b, seeds a..b-1")
    ap.add_argument("--ec", default="0.25,0.5,1,2")
    ap.add_argument("--k", default="0.5,1,2")
    ap.add_argument("--alpha", default="0.7,0.85")
    ap.add_argument("--n", default="none", help="MCTS2's iterations per decision: whole numbers or 'none'")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--resample", type=int, default=0, help="draws of 10 runs per row (0: none)")
    ap.add_argument("--searchers", default="mcts,mcts-commit", help="which of the two MCTS searchers to run")
    ap.add_argument("--cells", default=",".join(DEFAULT_CELLS),
                    help="built-in names or files; a file named like a paper cell (e.g. a physical variant of "
                         "s2-elbow-intrusion) is compared with that cell's paper rows")
    args = ap.parse_args()
    seeds = seed_range(args.seeds)
    cells = tuple(c for c in args.cells.split(",") if c)
    backend = Backend(workers=args.workers)
    ns = [None if x.strip() == "none" else int(x) for x in args.n.split(",")]
    t0 = time.perf_counter()
    base = list(backend.run(specs_for(cells, "random", {}, seeds)))
    summary = []
    for ec, k, alpha in itertools.product(floats(args.ec), floats(args.k), floats(args.alpha)):
        dpw = dict(ec=ec, k=k, alpha=alpha)
        wanted = args.searchers.split(",")
        mcts = list(backend.run(specs_for(cells, "mcts", dpw, seeds))) if "mcts" in wanted else []
        for n in ns if "mcts-commit" in wanted else [None]:
            commit = (list(backend.run(specs_for(cells, "mcts-commit", dpw | dict(n=n), seeds)))
                      if "mcts-commit" in wanted else [])
            lines, inside = rows_text(base + mcts + commit, args.resample)
            label = f"ec={ec:g} k={k:g} alpha={alpha:g} n={n or 'budget//horizon'}"
            print(f"{label}: {inside}/{2 * len(lines)} paper numbers inside (seeds {seeds.start}-{seeds.stop - 1})")
            print("\n".join(lines), flush=True)
            summary.append((inside, label))
    print("\nsettings by paper numbers inside (two per row: rate, mean):")
    for inside, label in sorted(summary, key=lambda s: -s[0]):
        print(f"  {inside:>2}  {label}")
    print(f"({time.perf_counter() - t0:.0f} s, {args.workers} workers; the machine is shared)")


if __name__ == "__main__":
    main()
