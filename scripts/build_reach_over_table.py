"""Write ``src/cellstress/analysis/reach_over_sim.json``: how far beyond a fence's top the articulated worker gets, for
each body size at the default trunk flexions, on ISO 13857 Table 2's grid (rows a, columns b).

    python scripts/build_reach_over_table.py            # every body size, ~3 min each on 2 cores
    python scripts/build_reach_over_table.py --check 1400 [--body p95-male]   # one column again: still current?

The numbers are ``benchmarks/iso13857.py``'s c_sim: the deepest point beyond the panel's face at height a over every
50 ms pose of every sequence its deterministic beam search plays (8 actions from 1.32 m in front of a panel of
top b, beam width 8 and 2 per 45-degree heading). ``cellstress check`` reads them to say, for a reach over a panel
that ISO 13857 fails, whether the simulated worker can get there at all (``analysis.reach_over.worker_reach``).
They depend on the worker model and the kernels: ``tests/analysis/test_reach_over_sim.py`` recomputes one column
for one body (as ``--check`` does) and fails when the stored column is no longer what the search gives.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from cellstress.core.io import atomic_write  # noqa: E402
from cellstress.core.iso13857 import TABLE_2  # noqa: E402
from cellstress.human.anthropometry import BODY_SIZES  # noqa: E402

OUT = ROOT / "src" / "cellstress" / "analysis" / "reach_over_sim.json"
SEARCH = {"width": 8, "per_heading": 2, "depth": 8, "spa": 4}
FLEXION_DEG = 55.0  # the cell format's defaults (cell.schema: max_forward_flexion_deg, max_lateral_flexion_deg)
LATERAL_DEG = 35.0


def _bench():
    spec = importlib.util.spec_from_file_location("iso13857_bench", ROOT / "benchmarks" / "iso13857.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def column(bench, body: str, b_mm: float) -> list[float]:
    """c_sim [mm] at every row a of Table 2 beyond a panel of top b_mm (whole mm)."""
    sim = bench.reach_over_sim(b_mm / 1000.0, body, FLEXION_DEG, SEARCH["spa"])
    heights = np.array(TABLE_2.a_mm) / 1000.0
    obj = bench.Objective(heights, top=b_mm / 1000.0)
    best, _, _ = bench.beam_search(sim, obj, SEARCH["width"], SEARCH["depth"], True, SEARCH["per_heading"])
    return [float(round(max(0.0, float(v)) * 1000.0)) if np.isfinite(v) else 0.0 for v in best]


def build(bodies: list[str]) -> dict:
    bench = _bench()
    tables = {}
    for body in bodies:
        cols = [column(bench, body, b) for b in TABLE_2.b_mm]
        tables[body] = [[cols[j][i] for j in range(len(cols))] for i in range(len(TABLE_2.a_mm))]
        print(f"{body}: done", flush=True)
    return {"about": "c_sim [mm]: the articulated worker's deepest reach beyond a panel's face at height a over a "
                     "top b (scripts/build_reach_over_table.py)",
            "search": SEARCH, "flexion_deg": FLEXION_DEG, "lateral_deg": LATERAL_DEG,
            "a_mm": list(TABLE_2.a_mm), "b_mm": list(TABLE_2.b_mm), "bodies": tables}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", type=float, default=None, help="recompute this column (b in mm) and compare")
    ap.add_argument("--body", default="p95-male")
    args = ap.parse_args()
    if args.check is not None:
        stored = json.loads(OUT.read_text())
        j = stored["b_mm"].index(args.check)
        now = column(_bench(), args.body, args.check)
        old = [row[j] for row in stored["bodies"][args.body]]
        print("current" if now == old else f"stale: stored {old}, now {now}")
        sys.exit(0 if now == old else 1)
    data = build(list(BODY_SIZES))
    atomic_write(OUT, (json.dumps(data, indent=1) + "\n").encode())
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
