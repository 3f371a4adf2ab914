"""`cellstress fix` on one-line variants of built-in cells, one per candidate kind of analysis/device_remedies.py.

    python benchmarks/fix_variants.py [--budget 100] [--time-limit 30] [--out fix-variants]

Each variant changes one thing of a built-in cell (the same edits as tests/analysis/test_device_remedies.py),
is written to OUT/NAME.yaml and fixed with ``cellstress fix`` (defaults as given); the table lists the failing
rows, the exit code, the candidates kept of those tried, the cheapest proposal and how it was re-tested, and
the wall time. Run it on a quiet machine: verify's time limit decides between a proof and a search.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from cellstress.cell.load import builtin_file
from cellstress.cli import main as cli

MAT = ("polygon: [[-1.5, 3.2], [1.5, 3.2], [1.5, -0.4], [1.0, -0.4], [1.0, 1.2], [0.45, 1.2], [0.45, 0.3],\n"
       "              [-0.45, 0.3], [-0.45, 1.2], [-1.0, 1.2], [-1.0, -0.4], [-1.5, -0.4]]")
S3_FIELD = "polygon: [[-1.5, 3.2], [1.5, 3.2], [1.5, -0.4], [1.0, -0.4], [1.0, 1.2]"

# name -> (built-in cell, [(old, new), ...], what the variant is)
VARIANTS = {
    "warning-short": ("warning-field-ok", [("polygon: [[-1.5, 3.6], [1.5, 3.6]", "polygon: [[-1.5, 3.3], [1.5, 3.3]")],
                      "warning field's front edge from y = 3.6 to 3.3"),
    "protective-short": ("warning-field-ok", [("polygon: [[-1.5, 2.9], [1.5, 2.9]",
                                               "polygon: [[-1.5, 2.8], [1.5, 2.8]")],
                         "protective front edge from y = 2.9 to 2.8"),
    "speed-limit": ("warning-field-ok", [("      reduced_speed: 0.25\n",
                                          "      reduced_speed: 0.25\n      speed_limit: 0.2\n")],
                    "warning field's speed_limit 0.2 m/s"),
    "no-warning": ("baseline", [("    height: 0.3\n    response_time: 0.35\n",
                                 "    height: 0.3\n    response_time: 0.1\n"),
                                ("polygon: [[-1.5, 3.2], [1.5, 3.2]", "polygon: [[-1.5, 2.45], [1.5, 2.45]")],
                   "scanner response 0.1 s, front edge from y = 3.2 to 2.45, no warning field"),
    "coarse-scanner": ("baseline", [("    height: 0.3\n    response_time: 0.35\n",
                                     "    height: 0.3\n    response_time: 0.35\n    resolution_mm: 150\n")],
                       "scanner resolution 150 mm at 300 mm"),
    "shallow-mat": ("mat-ok", [(MAT, "polygon: [[-1.5, 3.2], [1.5, 3.2], [1.5, 2.7], [-1.5, 2.7]]")],
                    "mat cut to a 0.5 m strip at the front"),
    "unseen-aisle": ("s3-fence-gap", [(S3_FIELD, "polygon: [[-1.5, 3.2], [1.5, 3.2], [1.5, 1.0], [1.0, 1.0], "
                                                 "[1.0, 1.2]")],
                     "scanner's right aisle cut off at y = 1.0"),
    "slow-monitor": ("ssm-ok", [("    max_speed: 1.2 ", "    max_speed: 0.8 ")], "monitor set for 0.8 m/s"),
}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=int, default=100)
    ap.add_argument("--time-limit", type=float, default=30.0)
    ap.add_argument("--out", type=Path, default=Path("fix-variants"))
    ap.add_argument("--only", nargs="*", default=None)
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    print("| variant | change | failing rows | exit | kept of tried | cheapest proposal | re-test | s |")
    print("|---|---|---|---:|---|---|---|---:|")
    for name, (cell, edits, words) in VARIANTS.items():
        if args.only and name not in args.only:
            continue
        text = Path(builtin_file(cell)).read_text()
        for old, new in edits:
            assert text.count(old) == 1, (name, old)
            text = text.replace(old, new)
        path = args.out / f"{name}.yaml"
        path.write_text(text)
        t0 = time.perf_counter()
        code = cli(["fix", str(path), "--out", str(args.out / name), "--budget", str(args.budget),
                    "--time-limit", str(args.time_limit)])
        seconds = time.perf_counter() - t0
        doc = json.loads((args.out / name / "fix.json").read_text())
        kept = sorted((c for c in doc["candidates"] if c["kept"]), key=lambda c: c["proposal"])
        best = kept[0] if kept else None
        retest = best["retest"]["words"] if best else "-"
        cheapest = f"{best['kind']}: {best['change']}" if best else "-"
        print(f"| `{name}` ({cell}) | {words} | {', '.join(doc['failing_before'])} | {code} | "
              f"{len(kept)} of {len(doc['candidates'])} | {cheapest} | {retest} | {seconds:.0f} |", flush=True)


if __name__ == "__main__":
    main()
