"""Record the simulator's outputs as raw bits, or check that the current code reproduces them exactly.

    python scripts/kernel_reference.py record FILE.npz [--episodes 20000]
    python scripts/kernel_reference.py check FILE.npz

For each built-in reference cell: every ``run_batch`` output for random actions (numpy Generator, seed 123),
200 whole traces (``Simulator.run``), 300 episodes played through ``Simulator.step``, s0 and its metric row.
Use it around a speed change that must not change results: record before, check after (exit 1 on any
difference, which it lists).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

CELLS = ("baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")


def outputs(episodes: int) -> dict[str, np.ndarray]:
    from cellstress.sim.simulator import Simulator

    out: dict[str, np.ndarray] = {}
    for c in CELLS:
        sim = Simulator(c)
        acts = np.random.default_rng(123).integers(0, 30, size=(episodes, sim.actions_per_episode))
        r = sim.run_batch(acts)
        for name in ("d_end", "v_end", "unsafe_step", "min_d"):
            out[f"{c}:{name}"] = getattr(r, name)
        for i in range(200):
            out[f"{c}:run{i}"] = sim.run(acts[i]).rows
        for i in range(300):
            s, rows = sim.reset(), []
            for a in acts[i]:
                s, rr = sim.step(s, int(a))
                rows.append(rr)
                if sim.is_unsafe(s):
                    break
            out[f"{c}:step{i}"] = np.concatenate(rows)
            out[f"{c}:stepstate{i}"] = s
        out[f"{c}:s0"] = sim.reset()
        out[f"{c}:row0"] = sim.initial_metrics()
    return out


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind == "f":
        return np.array_equal(a.view(f"u{a.itemsize}"), b.view(f"u{b.itemsize}"))
    return np.array_equal(a, b)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("record", "check"))
    ap.add_argument("file")
    ap.add_argument("--episodes", type=int, default=20_000)
    args = ap.parse_args(argv)
    if args.mode == "record":
        out = outputs(args.episodes)
        np.savez(args.file, **out)
        print(f"recorded {len(out)} arrays in {args.file}")
        return 0
    ref = np.load(args.file)
    n = len(ref["baseline:d_end"])
    out = outputs(n)
    bad = [k for k in ref.files if k not in out or not same_bits(ref[k], out[k])]
    for k in bad[:20]:
        print("differs:", k)
    print(f"checked {len(ref.files)} arrays; {len(bad)} differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
