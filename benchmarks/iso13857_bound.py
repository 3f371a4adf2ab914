"""How far beyond a protective structure a body of a given size can reach at all, against ISO 13857 Table 2
(issue 20): which of the standard's distances any honest model of that body could agree with.

    python benchmarks/iso13857_bound.py [--body p95-male] [--low-risk] [--flexion 180] [--tiptoe 0.08]
                                        [--extra-arm 0]

The body is reduced to what limits a reach over an edge, and everything else is given away, so that the reach
computed is more than the articulated worker (or a real person of that size, without climbing) can achieve:

- in the plane of the reach (x: horizontal distance beyond the structure's face, z: height), the structure is
  the segment x = 0, 0 <= z <= b, and the body has no thickness;
- the legs stand vertical on the worker's side (hip at x_H <= 0) at any hip height from the deep crouch to
  standing on tiptoe (``POSTURES``; the tiptoe lift is the assumption docs/worker.md names);
- the trunk is a straight segment from the hip to the shoulder joint, as long as the worker's own: 0.288 H up
  the trunk's axis and the shoulder joint's offset to the side (0.259 H / 2 - 0.05 m, human/body.py), since a
  worker turned sideways to the structure brings the near shoulder that much closer. It may bend forward by any
  angle up to ``--flexion`` (default 180 deg: hanging head down over the edge, far past the articulated
  worker's 55 deg and any measured range of trunk flexion); where it crosses the face it must pass at or above
  the edge (it may rest on it);
- the arm is a string of the arm's length (upper arm + forearm + hand) plus the hand capsule's radius: no joint
  limits, so it can bend over the edge at any point; its path may not pass through the structure.

The fingertip (with the hand's radius) then reaches the point (x, a) beyond the face when a path of that
length runs from the shoulder to it around the edge. The largest such x is c_bound(a, b).

Two results per cell:
- **exact**: nothing reaches height a when a is above the highest point the body can touch at all,
  hip on tiptoe + trunk + arm (+ hand radius), straight up. There c_bound = 0 with no approximation;
- **estimate**: elsewhere c_bound is the maximum over a grid of hip heights, hip positions and trunk angles,
  refined twice around the best grid point. A grid maximum approaches the model's supremum from
  below, by at most a few millimetres here (the refined step is 1 mm and 0.05 deg).

A cell's standard distance c_iso is **unattainable** for this body when c_iso > c_bound + 100 mm (one step of
the table): no model of this body that keeps its lengths reaches a hazard standing where the standard's
distance is just not met, so a simulated worker cannot agree with the standard there within one step.
docs/worker.md ("Which of Table 2's distances a body can reach at all") has the table and discusses it.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass

import numpy as np

from cellstress.core.iso13857 import TABLE_1, TABLE_2, ReachOverTable
from cellstress.human.anthropometry import BODY_SIZES, POSTURES, TIPTOE_RISE
from cellstress.human.body import B_SHOULDER_HALF, B_SHOULDER_RISE, BodyDimensions

HAND_RADIUS = 0.025  # m, the articulated worker's hand capsule (human/articulated.py)
ONE_STEP_MM = 100.0


@dataclass(frozen=True)
class Body2D:
    """What limits a reach over an edge: hip heights, trunk length, arm length (all m), trunk flexion (rad)."""

    hip_low: float
    hip_high: float
    trunk: float
    arm: float
    max_flexion: float

    @property
    def top(self) -> float:
        """Above this nothing of the body gets: hip on tiptoe, trunk and arm straight up (the trunk's full hip to
        shoulder length, more than its rise)."""
        return self.hip_high + self.trunk + self.arm


def body_2d(name: str, flexion_deg: float, tiptoe: float, extra_arm: float = 0.0) -> Body2D:
    size = BODY_SIZES[name]
    h = size.stature
    p = BodyDimensions(h, size.upper_arm, size.forearm, size.hand, walking_speed=1.6, articulated=True).params()
    return Body2D(hip_low=POSTURES["crouch"].hip_height(h), hip_high=POSTURES["stand"].hip_height(h) + tiptoe,
                  trunk=math.hypot(p[B_SHOULDER_RISE], p[B_SHOULDER_HALF]),
                  arm=size.arm_length + HAND_RADIUS + extra_arm,
                  max_flexion=math.radians(flexion_deg))


def reach_beyond(body: Body2D, a: float, b: float, hip: np.ndarray, x_hip: np.ndarray,
                 flexion: np.ndarray) -> np.ndarray:
    """For each configuration (broadcast arrays: hip height, hip position x_H <= 0, trunk flexion from vertical),
    the largest x > 0 at which the arm reaches height a beyond a structure of height b; -inf where none."""
    xs = x_hip + body.trunk * np.sin(flexion)
    zs = hip + body.trunk * np.cos(flexion)
    L = body.arm
    out = np.full(np.broadcast(xs, zs).shape, -np.inf)
    dz = a - zs
    straight = np.where(np.abs(dz) <= L, xs + np.sqrt(np.maximum(L * L - dz * dz, 0.0)), -np.inf)

    behind = xs <= 0.0
    # around the edge C = (0, b): what is left of the arm once it gets there
    rest = L - np.hypot(xs, zs - b)
    corner = np.where(rest >= abs(a - b), np.sqrt(np.maximum(rest * rest - (a - b) ** 2, 0.0)), -np.inf)
    # the straight reach is legal from behind when the arm's line passes the face at or above the edge
    with np.errstate(divide="ignore", invalid="ignore"):
        z_face = zs + dz * (-xs) / (straight - xs)
    straight_ok = (straight > 0.0) & (z_face >= b)
    from_behind = np.maximum(corner, np.where(straight_ok, straight, -np.inf))
    out = np.where(behind, from_behind, out)

    # shoulder beyond the face: the trunk crosses the face at or above the edge
    with np.errstate(divide="ignore", invalid="ignore"):
        z_cross = np.where(x_hip < 0.0, hip + (zs - hip) * (-x_hip) / (xs - x_hip), hip)
    beyond_ok = (~behind) & (z_cross >= b)
    out = np.where(beyond_ok, np.maximum(straight, xs), out)
    return np.where(out > 0.0, out, -np.inf)


def _best(body: Body2D, a: float, b: float, hips, xh, fl) -> tuple[float, tuple[float, float, float]]:
    H, X, F = np.meshgrid(hips, xh, fl, indexing="ij")
    r = reach_beyond(body, a, b, H, X, F)
    i = int(np.argmax(r))
    return float(r.flat[i]), (float(H.flat[i]), float(X.flat[i]), float(F.flat[i]))


def c_bound(body: Body2D, a: float, b: float) -> tuple[float, bool]:
    """(c_bound [m], exact): 0 exactly where a is above the body's top; else the refined grid estimate."""
    if a > body.top:
        return 0.0, True
    hips = np.linspace(body.hip_low, body.hip_high, 41)
    xh = np.linspace(-0.6, 0.0, 61)
    fl = np.linspace(0.0, body.max_flexion, 181)
    best, (h0, x0, f0) = _best(body, a, b, hips, xh, fl)
    if not math.isfinite(best):
        return 0.0, False
    for step_h, step_x, step_f in ((0.005, 0.005, math.radians(0.5)), (0.001, 0.001, math.radians(0.05))):
        hips = np.clip(h0 + step_h * np.arange(-10, 11), body.hip_low, body.hip_high)
        xh = np.clip(x0 + step_x * np.arange(-10, 11), -0.6, 0.0)
        fl = np.clip(f0 + step_f * np.arange(-10, 11), 0.0, body.max_flexion)
        cand, (h1, x1, f1) = _best(body, a, b, hips, xh, fl)
        if cand > best:
            best, h0, x0, f0 = cand, h1, x1, f1
    return best, False


def attainable(body: Body2D, c_iso_mm: float, a_mm: float, b_mm: float) -> bool:
    """Can a model of this body agree with the standard's c_iso within one step: c_iso <= c_bound + 100 mm?"""
    return c_iso_mm <= 1000.0 * c_bound(body, a_mm / 1000.0, b_mm / 1000.0)[0] + ONE_STEP_MM


def bound_table(body: Body2D, table: ReachOverTable) -> list[list[tuple[float, bool]]]:
    return [[c_bound(body, a / 1000.0, b / 1000.0) for b in table.b_mm] for a in table.a_mm]


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
    body = body_2d(args.body, args.flexion, args.tiptoe, args.extra_arm)
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
