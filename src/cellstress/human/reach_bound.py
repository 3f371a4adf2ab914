"""How far beyond the top of a protective structure a body of a given size can reach at all (ISO 13857 Table 2's
situation, reduced to a plane): an upper bound on any honest model of that body, and on the articulated worker
when given its own trunk flexion limit.

The body is reduced to what limits a reach over an edge, and everything else is given away, so that the reach
computed is more than the articulated worker (or a real person of that size, without climbing) can achieve:

- in the plane of the reach (x: horizontal distance beyond the structure's face, z: height), the structure is
  the segment x = 0, 0 <= z <= b, and the body has no thickness;
- the legs stand vertical on the worker's side (hip at x_H <= 0) at any hip height from the deep crouch to
  standing on tiptoe (``anthropometry.POSTURES``; the tiptoe lift is the assumption docs/worker.md names);
- the trunk is a straight segment from the hip to the shoulder joint, as long as the worker's own: 0.288 H up
  the trunk's axis and the shoulder joint's offset to the side (0.259 H / 2 - 0.05 m, ``human.body``), since a
  worker turned sideways to the structure brings the near shoulder that much closer. It may bend forward by any
  angle up to the flexion given (180 deg: hanging head down over the edge, far past any measured range); where
  it crosses the face it must pass at or above the edge (it may rest on it);
- the arm is a string of the arm's length (upper arm + forearm + hand) plus the hand capsule's radius: no joint
  limits, so it can bend over the edge at any point; its path may not pass through the structure.

The fingertip (with the hand's radius) then reaches the point (x, a) beyond the face when a path of that
length runs from the shoulder to it around the edge. The largest such x is ``c_bound(a, b)``: exactly 0 when a
is above the highest point the body can touch at all (hip on tiptoe + trunk + arm, straight up); elsewhere the
maximum over a grid of hip heights, hip positions and trunk angles, refined twice around the best grid point
(it approaches the model's supremum from below, by at most a few millimetres: the refined step is 1 mm and
0.05 deg). ``tests/human/test_reach_bound.py`` checks it against hand cases and an independent sampling.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cellstress.human.actions import A_DROP, A_FWD, A_LAT
from cellstress.human.anthropometry import BODY_SIZES, POSTURES, TIPTOE_RISE
from cellstress.human.body import (
    B_ARM_LEN,
    B_HIP_Z,
    B_SHOULDER_HALF,
    B_SHOULDER_RISE,
    BodyDimensions,
)

GENEROUS_FLEXION_DEG = 180.0  # deg: the body bound's trunk, bent further than any person can

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


def body_bound(name: str, flexion_deg: float = GENEROUS_FLEXION_DEG, tiptoe: float = TIPTOE_RISE,
               extra_arm: float = 0.0) -> Body2D:
    """The reduced body of size ``name`` (``anthropometry.BODY_SIZES``), its trunk bent up to ``flexion_deg``."""
    size = BODY_SIZES[name]
    h = size.stature
    p = BodyDimensions(h, size.upper_arm, size.forearm, size.hand, walking_speed=1.6, articulated=True).params()
    return Body2D(hip_low=POSTURES["crouch"].hip_height(h), hip_high=POSTURES["stand"].hip_height(h) + tiptoe,
                  trunk=math.hypot(p[B_SHOULDER_RISE], p[B_SHOULDER_HALF]),
                  arm=size.arm_length + HAND_RADIUS + extra_arm,
                  max_flexion=math.radians(flexion_deg))


def worker_body(body: np.ndarray, act: np.ndarray, arm_extra: float) -> Body2D:
    """The reduced body of a simulated worker: its own trunk and arm (``body``, the B_* vector), its hip from the
    lowest to the highest stance of its action table ``act`` (the paper's worker stands), and a trunk that tilts
    as far as the largest forward and sideways flexions together tilt it from vertical (cos t = cos f cos l:
    turned to the panel, either bend or both bring the shoulder over it). ``arm_extra``: added to the arm (the
    hand capsule's radius, or the reach volume's interpolation slack)."""
    fwd = float(np.abs(act[:, A_FWD]).max(initial=0.0))
    lat = float(np.abs(act[:, A_LAT]).max(initial=0.0))
    hip = float(body[B_HIP_Z])
    return Body2D(hip_low=hip + min(float(act[:, A_DROP].min(initial=0.0)), 0.0),
                  hip_high=hip + max(float(act[:, A_DROP].max(initial=0.0)), 0.0),
                  trunk=math.hypot(float(body[B_SHOULDER_RISE]), float(body[B_SHOULDER_HALF])),
                  arm=float(body[B_ARM_LEN]) + arm_extra,
                  max_flexion=math.acos(math.cos(fwd) * math.cos(lat)))


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


def bound_table(body: Body2D, table) -> list[list[tuple[float, bool]]]:
    """``c_bound`` for every cell of a ``core.iso13857.ReachOverTable`` (rows a, columns b)."""
    return [[c_bound(body, a / 1000.0, b / 1000.0) for b in table.b_mm] for a in table.a_mm]
