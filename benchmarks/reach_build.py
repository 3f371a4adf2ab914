"""The worker's reach field built from scratch (what a new body size costs on its first run), timed.

    python benchmarks/reach_build.py [--repeat 5] [--lengths 0.30 0.31 0.18] [--spacing 0.02] [--threads N]

Each repeat runs a fresh interpreter with an empty reach-field cache (CELLSTRESS_CACHE) and the numba cache
the package uses (the shipped kernels, or what numba compiled before: the first repeat may compile, so it is
reported apart and left out of the medians) and times there: the call of ``reach_field`` (loading the compiled
functions included: what a user waits for), then ``_build`` again in the same process, split into the
rasterising (``_occupied``) and the closing, filling and distance transforms (``_signed_distance``) when the
code has them. Prints every repeat and the medians. ``--threads`` sets NUMBA_NUM_THREADS for the children.
The machine is shared: compare versions by alternating runs, and read medians only.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

CHILD = r"""
import json, sys, time
lengths, spacing = tuple(float(x) for x in sys.argv[1:4]), float(sys.argv[4])
from cellstress.human import reach
from cellstress.sim.compiling import watching
with watching() as w:
    t = time.perf_counter()
    reach.reach_field(*lengths, spacing)
    out = {"first call": time.perf_counter() - t, "compiling": w.seconds}
t = time.perf_counter()
reach._build(lengths, spacing)
out["_build"] = time.perf_counter() - t
if hasattr(reach, "_occupied"):
    t = time.perf_counter()
    occupied = reach._occupied(lengths, spacing)
    out["rasterise"] = time.perf_counter() - t
    t = time.perf_counter()
    reach._signed_distance(occupied, spacing)
    out["scipy"] = time.perf_counter() - t
print(json.dumps(out))
"""


def run(lengths: list[float], spacing: float, threads: int | None) -> dict:
    with tempfile.TemporaryDirectory() as cache_dir:
        env = dict(os.environ, CELLSTRESS_CACHE=cache_dir)
        if threads:
            env["NUMBA_NUM_THREADS"] = str(threads)
        p = subprocess.run([sys.executable, "-c", CHILD, *map(str, lengths), str(spacing)], env=env,
                           capture_output=True, text=True, check=False)
    if p.returncode != 0:
        sys.exit(f"the child failed:\n{p.stderr[-3000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--lengths", type=float, nargs=3, default=[0.30, 0.31, 0.18], help="upper arm, forearm, hand")
    ap.add_argument("--spacing", type=float, default=0.02)
    ap.add_argument("--threads", type=int, default=None)
    args = ap.parse_args()
    print(f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; lengths {args.lengths} m, spacing "
          f"{args.spacing} m; NUMBA_NUM_THREADS {args.threads or os.environ.get('NUMBA_NUM_THREADS', 'default')}")
    runs = []
    for i in range(args.repeat + 1):
        doc = run(args.lengths, args.spacing, args.threads)
        print(("warm-up " if i == 0 else f"run {i:<4}") + "  ".join(f"{k} {v:.3f}" for k, v in doc.items()))
        if i:
            runs.append(doc)
    print("median   " + "  ".join(f"{k} {statistics.median(d[k] for d in runs):.3f}" for k in runs[0]))


if __name__ == "__main__":
    main()
