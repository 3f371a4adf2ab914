"""Record the simulator's outputs as raw bits, or check that the current code reproduces them exactly.

    python scripts/kernel_reference.py record FILE.npz [--episodes 20000] [--cells all | NAME ...]
    python scripts/kernel_reference.py check FILE.npz
    python scripts/kernel_reference.py compare OLD.npz NEW.npz

For each reference cell (the paper's four unless ``--cells`` names others; ``all``: every built-in cell):
every ``run_batch`` output for random actions (numpy Generator, seed 123), 200 whole traces
(``Simulator.run``), 300 episodes played through ``Simulator.step``, s0 and its metric row.
Use it around a speed change that must not change results: record before, check after (exit 1 on any
difference, which it lists). Around a change that may move d_HR within the trace's tolerance, record before
and after and ``compare``: per cell, whether the unsafe episodes and steps are the same, how far d_HR moved
(absolute and relative), whether any row within 5 cm of contact changed, and how many rows changed their
closest link or body part.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

CELLS = ("baseline", "s1-scanner-width", "s2-elbow-intrusion", "s3-fence-gap")


def cells_of(recording) -> list[str]:
    """The cells a recording holds, in the order recorded."""
    return list(dict.fromkeys(k.split(":")[0] for k in recording))


def outputs(episodes: int, cells=CELLS) -> dict[str, np.ndarray]:
    from cellstress.sim.simulator import Simulator

    out: dict[str, np.ndarray] = {}
    for c in cells:
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
    if a.ndim == b.ndim and a.ndim > 0 and a.shape[:-1] == b.shape[:-1] and a.shape[-1] < b.shape[-1]:
        b = b[..., : a.shape[-1]]  # a state or row that gained slots at the end: compared on its old slots
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind == "f":
        return np.array_equal(a.view(f"u{a.itemsize}"), b.view(f"u{b.itemsize}"))
    return np.array_equal(a, b)


def compare(old: dict, new: dict) -> int:
    """Print how far NEW's outputs moved from OLD's; 1 if the unsafe outcomes differ."""
    from cellstress.sim import layout as L

    changed_outcome = False
    for c in cells_of(old):
        same_unsafe = np.array_equal(old[f"{c}:unsafe_step"], new[f"{c}:unsafe_step"])
        a, b = old[f"{c}:d_end"], new[f"{c}:d_end"]
        ok = np.isfinite(a) & np.isfinite(b)
        dd = np.abs(a[ok] - b[ok])
        rel = dd / np.maximum(np.abs(a[ok]), 1e-9)
        rows_old = np.concatenate([old[f"{c}:run{i}"] for i in range(200)] + [old[f"{c}:step{i}"] for i in range(300)])
        rows_new = np.concatenate([new[f"{c}:run{i}"] for i in range(200)] + [new[f"{c}:step{i}"] for i in range(300)])
        if rows_old.shape != rows_new.shape:
            print(f"{c}: traces differ in length")
            changed_outcome = True
            continue
        dr = np.abs(rows_old[:, L.M_D] - rows_new[:, L.M_D])
        near = (rows_old[:, L.M_D] < 0.05) | (rows_new[:, L.M_D] < 0.05)
        who = (rows_old[:, L.M_LINK] != rows_new[:, L.M_LINK]) | (rows_old[:, L.M_PART] != rows_new[:, L.M_PART])
        n_unsafe = int((new[f"{c}:unsafe_step"] >= 0).sum())
        print(f"{c}: unsafe episodes {'same' if same_unsafe else 'DIFFER'} ({n_unsafe} of {len(a)}); "
              f"d_end moved in {int((dd > 0).sum())} of {dd.size} (max {dd.max(initial=0):.2e} m, "
              f"max rel {rel.max(initial=0):.2%}); trace rows: d moved in {int((dr > 0).sum())} of {dr.size} "
              f"(max {dr.max(initial=0):.2e} m), within 5 cm of contact {int((dr[near] > 0).sum())}, "
              f"closest link/part changed in {int(who.sum())}")
        changed_outcome |= not same_unsafe
    return 1 if changed_outcome else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("record", "check", "compare"))
    ap.add_argument("file")
    ap.add_argument("new", nargs="?", help="compare: the second recording")
    ap.add_argument("--episodes", type=int, default=20_000)
    ap.add_argument("--cells", nargs="+", default=list(CELLS), help="record: cells by name, or all built-in ones")
    args = ap.parse_args(argv)
    if args.mode == "record":
        from cellstress.cell.load import BUILTIN_CELLS

        out = outputs(args.episodes, BUILTIN_CELLS if args.cells == ["all"] else args.cells)
        np.savez(args.file, **out)
        print(f"recorded {len(out)} arrays in {args.file}")
        return 0
    if args.mode == "compare":
        if args.new is None:
            ap.error("compare needs OLD.npz NEW.npz")
        return compare(np.load(args.file), np.load(args.new))
    ref = np.load(args.file)
    cells = cells_of(ref)
    out = outputs(len(ref[f"{cells[0]}:d_end"]), cells)
    bad = [k for k in ref.files if k not in out or not same_bits(ref[k], out[k])]
    for k in bad[:20]:
        print("differs:", k)
    print(f"checked {len(ref.files)} arrays; {len(bad)} differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
