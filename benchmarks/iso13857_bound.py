"""How far beyond a protective structure a body of a given size can reach at all, against ISO 13857 Table 2
(issue 20): which of the standard's distances any honest model of that body could agree with.

    python benchmarks/iso13857_bound.py [--body p95-male] [--low-risk] [--flexion 180] [--tiptoe 0.08]
                                        [--extra-arm 0]

The body and the bound are `cellstress.human.reach_bound`'s (its docstring says what is given away).

A cell's standard distance c_iso is **unattainable** for this body when c_iso > c_bound + 100 mm (one step of
the table): no model of this body that keeps its lengths reaches a hazard standing where the standard's
distance is just not met, so a simulated worker cannot agree with the standard there within one step.
docs/worker.md ("Which of Table 2's distances a body can reach at all") has the table and discusses it.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from cellstress.core.iso13857 import TABLE_1, TABLE_2  # noqa: E402
from cellstress.human.anthropometry import BODY_SIZES, TIPTOE_RISE  # noqa: E402
from cellstress.human.reach_bound import ONE_STEP_MM, body_bound, bound_table  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--body", default="p95-male", choices=sorted(BODY_SIZES))
    ap.add_argument("--low-risk", action="store_true", help="Table 1 instead of Table 2")
    ap.add_argument("--flexion", type=float, default=180.0, help="largest trunk flexion [deg]")
    ap.add_argument("--tiptoe", type=float, default=TIPTOE_RISE, help="heel lift on tiptoe [m]")
    ap.add_argument("--extra-arm", type=float, default=0.0,
                    help="length added to the arm [m], e.g. for the shoulder girdle, which neither model moves")
    args = ap.parse_args()
    table = TABLE_1 if args.low_risk else TABLE_2
    body = body_bound(args.body, args.flexion, args.tiptoe, args.extra_arm)
    print(f"{table.table}, {args.body}: hip {body.hip_low:.3f}-{body.hip_high:.3f} m, trunk {body.trunk:.3f} m, "
          f"arm + hand radius {body.arm:.3f} m, flexion <= {args.flexion:g} deg, top {body.top:.3f} m")
    print("cells: c_iso / c_bound [mm]; '!' unattainable (c_iso > c_bound + 100), '=' exact (a above the top)")
    rows = bound_table(body, table)
    print("| a \\ b | " + " | ".join(f"{b:g}" for b in table.b_mm) + " |")
    print("|---" * (len(table.b_mm) + 1) + "|")
    counts = {"attainable": 0, "unattainable, exact": 0, "unattainable, estimate": 0}
    for a, c_row, bound_row in sorted(zip(table.a_mm, table.c_mm, rows, strict=True), reverse=True):
        cells = []
        for c_iso, (c_m, exact) in zip(c_row, bound_row, strict=True):
            cb = 1000.0 * c_m
            bad = c_iso > cb + ONE_STEP_MM
            counts["attainable" if not bad else ("unattainable, exact" if exact else "unattainable, estimate")] += 1
            cells.append(f"{c_iso:g} / {cb:.0f}{' !' if bad else ''}{' =' if exact else ''}")
        print(f"| {a:g} | " + " | ".join(cells) + " |")
    total = sum(counts.values())
    print(f"of {total} cells: " + ", ".join(f"{v} {k}" for k, v in counts.items()))


if __name__ == "__main__":
    main()
