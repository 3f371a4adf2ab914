"""Cold numba compile time: in total, and per compiled function.

    python benchmarks/compile_time.py [--src SRC] [--repeat N]

Each repeat runs a fresh interpreter with an empty NUMBA_CACHE_DIR (numba's cache for ``cache=True``
functions goes there instead of ``__pycache__`` when it is set, so nothing is loaded from an earlier run)
and the shipped kernel cache switched off (``CELLSTRESS_SHIPPED_KERNELS=0``, cellstress.core.jit), and does
what a user's first search does: build a cell, run a batch, one whole episode and one step, and the plan
searcher's worker-only kernels. It prints the wall time of each stage and, from numba's
``numba:compile`` events, every function that was compiled with its own time (excluding the functions
compiled inside it) and its time including them. ``--src`` runs another checkout's sources (e.g. an older
tree from ``git archive``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import json, time
t0 = time.perf_counter()
from numba.core import event

stack, rows = [], []

class Listener(event.Listener):
    def on_start(self, ev):
        stack.append([ev.data["dispatcher"].py_func.__qualname__, time.perf_counter(), 0.0,
                      [str(a) for a in ev.data["args"]]])

    def on_end(self, ev):
        name, start, inner, args = stack.pop()
        total = time.perf_counter() - start
        rows.append((name, total, total - inner, args))
        if stack:
            stack[-1][2] += total

event.register("numba:compile", Listener())
import numpy as np
from cellstress.sim.simulator import Simulator
stages = {"import": time.perf_counter() - t0}
t = time.perf_counter(); s = Simulator("s3-fence-gap"); stages["Simulator('s3-fence-gap')"] = time.perf_counter() - t
t = time.perf_counter(); s.run_batch(np.zeros((4, 8), dtype=np.int64)); stages["run_batch"] = time.perf_counter() - t
t = time.perf_counter(); s.run(["walk+upright"]); stages["run"] = time.perf_counter() - t
t = time.perf_counter(); s.step(s.reset(), 0); stages["step"] = time.perf_counter() - t
t = time.perf_counter(); s.worker_paths(np.zeros((2, 8), dtype=np.int64))
s.worker_distances(np.zeros((2, 5)), np.zeros((2, 3, 3))); stages["worker (plan)"] = time.perf_counter() - t
stages["total"] = time.perf_counter() - t0
print(json.dumps({"stages": stages, "compiled": rows}))
"""


def one_run(src: str | None) -> dict:
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory() as cache:
        env["NUMBA_CACHE_DIR"] = cache
        env["CELLSTRESS_SHIPPED_KERNELS"] = "0"  # compile: measure numba, not the shipped cache (core/jit.py)
        out = subprocess.run([sys.executable, "-c", CHILD], env=env, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--src", help="a src folder to run instead of the installed package")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--json", type=Path, help="also write every run's raw numbers here")
    a = ap.parse_args()
    runs = [one_run(a.src) for _ in range(a.repeat)]
    if a.json:
        a.json.write_text(json.dumps(runs, indent=1))
    for i, r in enumerate(runs):
        print(f"run {i}: " + ", ".join(f"{k} {v:.1f} s" for k, v in r["stages"].items()))
    # per function: median over runs of own and inclusive time (a function compiled twice, for two
    # signatures, is summed within a run)
    per: dict[str, list[tuple[float, float, int]]] = {}
    for r in runs:
        acc: dict[str, list[float]] = {}
        for name, total, own, _ in r["compiled"]:
            x = acc.setdefault(name, [0.0, 0.0, 0])
            x[0] += own
            x[1] += total
            x[2] += 1
        for name, (own, total, n) in acc.items():
            per.setdefault(name, []).append((own, total, n))

    def med(xs: list[float]) -> float:
        xs = sorted(xs)
        return xs[len(xs) // 2]

    table = sorted(((med([o for o, _, _ in v]), med([t for _, t, _ in v]), v[0][2], k) for k, v in per.items()),
                   reverse=True)
    print("\n| function | own [s] | incl. nested [s] | compiles |\n|---|---:|---:|---:|")
    for own, total, n, name in table:
        if own >= 0.05:
            print(f"| {name} | {own:.2f} | {total:.2f} | {n} |")
    rest = sum(own for own, _, _, _ in table if own < 0.05)
    print(f"| (others, {sum(1 for t in table if t[0] < 0.05)} functions) | {rest:.2f} | | |")
    print(f"| **sum of own times** | {sum(t[0] for t in table):.2f} | | |")
    # a function compiled for several signatures: which arguments' types differ (first run)
    sigs: dict[str, list[list[str]]] = {}
    for name, _, _, args in runs[0]["compiled"]:
        sigs.setdefault(name, []).append(args)
    for name, variants in sigs.items():
        if len(variants) > 1 and name in {t[3] for t in table if t[0] >= 1.0}:
            print(f"\n{name}: {len(variants)} signatures")
            for i in range(max(len(v) for v in variants)):
                kinds = {v[i] if i < len(v) else "-" for v in variants}
                if len(kinds) > 1:
                    print(f"  argument {i}: " + " | ".join(sorted(k[:160] for k in kinds)))


if __name__ == "__main__":
    main()
