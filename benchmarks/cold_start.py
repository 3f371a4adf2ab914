"""The first search on a fresh installation, phase by phase: what a new user waits for.

    python benchmarks/cold_start.py [--cell s3-fence-gap] [--searcher plan] [--budget 200] [--warm] [--warm-numba]

Runs a fresh interpreter with empty caches (numba's cache in an empty NUMBA_CACHE_DIR, the reach field's in an
empty CELLSTRESS_CACHE) and times, one after the other: the imports of the command line and the simulator, the
worker's reach field (built on the first run, then read from its cache), the simulator's set-up for the cell,
the search, and the report. For each phase it prints the wall time and the part of it numba spent compiling
(from numba's ``numba:compile`` events). ``--warm`` runs the same again with the caches the first run left,
as every later run sees them. ``--warm-numba`` runs it again with numba's cache of the first run but an empty
reach-field cache: a new body size's first run, or, on a branch whose compiled code differs from the shipped
archive (the first run then compiles it), what a user will wait once the archive is rebuilt. The kernels
compiled ahead and shipped with the package (cellstress.core.jit) are used as on a user's machine;
``--no-shipped`` switches them off to time numba compiling everything (what a user of another numba or Python
waits). Run it on an idle machine; the first line says how many cores it had.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

CHILD = r"""
import json, sys, time
cell, searcher, budget, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
phases = []
t = time.perf_counter()
import cellstress.cli  # noqa: F401  (what `cellstress` imports before it runs a command)
from cellstress.sim.compiling import watching
from cellstress.sim.simulator import Simulator
from cellstress.searchers import search
phases.append(("imports", time.perf_counter() - t, 0.0))

def phase(name, work):
    with watching() as w:
        t = time.perf_counter()
        value = work()
        phases.append((name, time.perf_counter() - t, w.seconds))
    return value

from cellstress.cell.load import load_cell
from cellstress.human.reach import reach_field
c = load_cell(cell)
a = c.spec.human.anthropometry
phase("reach field", lambda: reach_field(a.upper_arm, a.forearm, a.hand))
sim = phase("simulator set-up", lambda: Simulator(c))
result = phase("search", lambda: search(sim, searcher, budget, 0))
from cellstress.report.make import write_report
phase("report", lambda: write_report(result, out, sim=sim))
print(json.dumps({"phases": phases, "episodes": result.episodes, "found": result.found}))
"""


def run(cell: str, searcher: str, budget: int, numba_dir: str, cache_dir: str, shipped: bool) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=numba_dir, CELLSTRESS_CACHE=cache_dir,
               CELLSTRESS_SHIPPED_KERNELS="1" if shipped else "0")
    for name in ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):  # as on a fresh machine: the package chooses
        env.pop(name, None)
    with tempfile.TemporaryDirectory() as out:
        p = subprocess.run([sys.executable, "-c", CHILD, cell, searcher, str(budget), out], env=env,
                           capture_output=True, text=True, check=False)
    if p.returncode != 0:
        sys.exit(f"the child failed:\n{p.stderr[-3000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def show(title: str, doc: dict) -> None:
    print(f"\n{title}: {doc['episodes']} episodes, hazard found: {doc['found']}")
    print(f"{'phase':<18} {'seconds':>8} {'compiling':>10}")
    for name, seconds, compiling in doc["phases"]:
        print(f"{name:<18} {seconds:>8.1f} {compiling:>10.1f}")
    first_search = sum(s for name, s, _ in doc["phases"] if name != "report")
    print(f"{'first search':<18} {first_search:>8.1f}   (imports + reach field + set-up + search)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cell", default="s3-fence-gap")
    ap.add_argument("--searcher", default="plan")
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--warm", action="store_true", help="run again with the caches of the first run")
    ap.add_argument("--warm-numba", action="store_true",
                    help="run again with numba's cache of the first run and an empty reach-field cache")
    ap.add_argument("--no-shipped", action="store_true", help="switch off the kernels shipped compiled")
    args = ap.parse_args()
    print(f"{os.cpu_count()} cores; cell {args.cell}, searcher {args.searcher}, budget {args.budget}; "
          f"shipped kernels {'off' if args.no_shipped else 'on'}")
    shipped = not args.no_shipped
    with tempfile.TemporaryDirectory() as numba_dir, tempfile.TemporaryDirectory() as cache_dir:
        show("cold (empty caches)", run(args.cell, args.searcher, args.budget, numba_dir, cache_dir,
                                                   shipped))
        if args.warm:
            show("warm (the caches of the cold run)", run(args.cell, args.searcher, args.budget, numba_dir,
                                                           cache_dir, shipped))
        if args.warm_numba:
            with tempfile.TemporaryDirectory() as fresh_cache_dir:
                show("numba's cache of the cold run, empty reach-field cache",
                     run(args.cell, args.searcher, args.budget, numba_dir, fresh_cache_dir, shipped))


if __name__ == "__main__":
    main()
