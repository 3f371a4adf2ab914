"""Brute-force probe behind a cell's light curtain (``cellstress.analysis.probe``): how close the robot comes to an
unseen worker standing still.

    python scripts/curtain_probe.py [CELL] [--step 0.05]
"""

from __future__ import annotations

import argparse

from cellstress.analysis.probe import probe


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cell", nargs="?", default="s2-elbow-intrusion")
    ap.add_argument("--step", type=float, default=0.05)
    args = ap.parse_args()
    r = probe(args.cell, args.step)
    print(f"{r['cell']}: {r['poses']} standing poses behind the curtain (y <= {r['curtain_y']}), {r['unseen']} unseen "
          f"and clear of fences, {r['robot_poses']} robot poses each")
    print(f"smallest d_HR {r['d']:.3f} m: stand at ({r['x']}, {r['y']}), heading {r['heading_deg']} deg, posture "
          f"(forward, lateral) {r['posture']}, path time {r['path_time']} s, robot link {r['link']}, "
          f"body part {r['part']}")


if __name__ == "__main__":
    main()
