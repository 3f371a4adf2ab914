"""ISO 13857 reaching over a fence panel, for the static check: the hazard zone in three dimensions and the
horizontal distance c(a, b) of ISO 13857:2019 Table 2 behind every panel.

The standard asks that a hazard zone at height a lie at least c(a, b) horizontally behind a protective structure
of height b (clause 4.2.2). The check uses Table 2, the high-risk table: an industrial robot's moving links can
crush and strike, and which table applies is chosen by a risk assessment (ISO 12100) that the check cannot make,
so it takes the table for high risk, which never asks less than Table 1 (``TABLE_2_COVERS_TABLE_1``).

**The hazard zone in height.** The robot's capsules are posed every ``SAMPLE_DT`` over one cycle, as for the
floor footprint (``analysis.hazard_zone``), and each capsule is covered by balls along its axis (centres at most
``BALL_STEP`` apart, each ball's radius grown so that the balls together contain the capsule: the distances
are at most ~1 mm short, on the safe side). A ball reaches the heights of a table row band [a_i, a_i+1] with the
disc it cuts at the band's nearer edge (its whole radius where its centre lies in the band).

**Between the rows** the standard takes the value giving the greater safety (``iso13857.reach_over_distance``):
every part of the zone between rows a_i and a_i+1 must keep the larger of the two rows' distances; parts below
the floor count as in the lowest band (0..200 mm), parts at 2.7 m and above are out of reach (clause 4.2.1: the top
row is zero).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cellstress.analysis.hazard_zone import SAMPLE_DT, robot_poses
from cellstress.analysis.plane import point_segment
from cellstress.core import iso13857 as T

BALL_STEP = 0.02  # m, at most this far between the centres of the balls covering a capsule
TABLE_2_COVERS_TABLE_1 = all(
    T.reach_over_distance(a, b, True) >= T.TABLE_1.c(a, b)
    for a in T.TABLE_1.a_mm for b in T.TABLE_1.b_mm)


@dataclass(frozen=True, eq=False)
class HazardVolume:
    """The robot's swept volume over one cycle as balls (exact repeats, such as the dwells, kept once)."""

    c: np.ndarray  # (n, 3) ball centres [m]
    r: np.ndarray  # (n,) radii [m]
    t: np.ndarray  # (n,) episode time [s] of the pose (first occurrence), in [0, cycle)
    part: np.ndarray  # (n,) int capsule index
    part_names: tuple[str, ...]


@dataclass(frozen=True)
class ReachOver:
    """ISO 13857 Table 2 behind one panel: the row band where the zone comes closest to its required distance."""

    top: float  # m, the panel's top b
    hazard_height: float  # m, a: the height of the zone's nearest point in that band (nan: no band asks a distance)
    behind: float  # m, horizontal distance from the panel to the zone at that height (inf: none in the band)
    required: float  # m, Table 2's c for that band (0: the top is out of reach of every height; inf: top < 1 m)
    band: tuple[float, float]  # m, the rows a_i..a_i+1 of that band
    robot_part: str = ""  # the robot capsule there
    t: float = math.nan  # s, episode time of that pose (mod the cycle)
    side: int = 0  # the worker's side of the panel (+1 left of start->end, -1 right; 0: both, the zone all round)

    @property
    def ok(self) -> bool:
        """Table 2 is met (never below 1 m: no distance is enough behind what is no barrier)."""
        return math.isfinite(self.required) and self.behind >= self.required - 1e-9


def hazard_volume(layout, sample_dt: float = SAMPLE_DT, robot: int | None = None) -> HazardVolume:
    """Balls covering the robot capsules over one cycle (before any stop), posed as ``hazard_zone`` poses them;
    in a cell of several robots every robot's, each over its own cycle, or robot ``robot``'s only."""
    P = layout.params
    cs, rs, ts, ps = [], [], [], []
    for times, caps, ra, rb in robot_poses(P, sample_dt, robot):
        for j, cap in enumerate(caps):
            rad = float(P.cap_r[cap])
            length = float(np.linalg.norm(rb[0, j] - ra[0, j]))  # rigid: the same at every pose
            n = max(int(math.ceil(length / BALL_STEP)), 1)
            s = np.linspace(0.0, 1.0, n + 1)
            cen = ra[:, j, None, :] + s[None, :, None] * (rb[:, j, None, :] - ra[:, j, None, :])
            cs.append(cen.reshape(-1, 3))
            # a ball of radius sqrt(r^2 + (step/2)^2) at every centre: together they contain the capsule
            rs.append(np.full(cen.shape[0] * cen.shape[1], math.hypot(rad, 0.5 * length / n)))
            ts.append(np.repeat(times, n + 1))
            ps.append(np.full(cen.shape[0] * cen.shape[1], cap))
    c, r_, t_, p_ = (np.concatenate(x) for x in (cs, rs, ts, ps))
    key = np.round(np.concatenate([c, r_[:, None]], axis=1) * 1e6).astype(np.int64)
    _, first = np.unique(key, axis=0, return_index=True)
    first = np.sort(first)
    return HazardVolume(np.ascontiguousarray(c[first]), r_[first], t_[first], p_[first],
                        tuple(cap.name for cap in layout.capsules))


def _bands() -> list[tuple[float, float, float]]:
    """(lo, hi, a inside) of Table 2's row bands [m]; the lowest open below (a hazard under the floor counts as
    row 0), the last one ending at the top row (2.7 m: out of reach above)."""
    a = [x / 1000.0 for x in T.TABLE_2.a_mm]
    return [(-math.inf if i == 0 else a[i], a[i + 1], 0.5 * (a[i] + a[i + 1])) for i in range(len(a) - 1)]


BANDS = _bands()
MAX_C = max(max(row) for row in T.TABLE_2.c_mm) / 1000.0  # m, the largest distance Table 2 asks


def _signed(p0, p1, x, y):
    """Signed distance of points from the line through p0-p1 (positive on its left, seen from p0 to p1)."""
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    n = math.hypot(dx, dy)
    return (dx * (y - p0[1]) - dy * (x - p0[0])) / n if n > 0.0 else np.zeros(np.shape(x))


def reach_over(p0, p1, top: float, vol: HazardVolume, side: int = 0) -> ReachOver:
    """Table 2 behind the panel p0-p1 of height ``top`` [m]: over every row band, the horizontal distance from the
    panel to the zone's part in the band against the band's c; returned for the band with the least margin
    (the first such band from the floor up on a tie). With ``side`` (the worker's side, as ``ReachOver.side``)
    only the zone on the other side counts, and what reaches within a ball's radius of the panel's line."""
    if top * 1000.0 < T.NO_BARRIER_BELOW_MM:
        return ReachOver(top, math.nan, math.inf, math.inf, (0.0, 0.0), side=side)
    best: ReachOver | None = None
    for row in band_rows(p0, p1, top, vol, side):
        if best is None or row.behind - row.required < best.behind - best.required - 1e-12:
            best = row
    if best is None:  # a top at 2.7 m or higher: nothing behind it can be reached over it
        return ReachOver(top, math.nan, math.inf, 0.0, (0.0, 0.0), side=side)
    return best


def band_rows(p0, p1, top: float, vol: HazardVolume, side: int = 0) -> list[ReachOver]:
    """``reach_over``'s verdict in every row band of Table 2 that asks a distance behind a panel of this top, from
    the floor up (the zone's nearest part in the band; ``behind`` inf where the zone has none in the band)."""
    b_mm = top * 1000.0
    d = point_segment(vol.c[:, 0], vol.c[:, 1], p0[0], p0[1], p1[0], p1[1])[0]
    keep = d - vol.r < MAX_C + 1e-6  # farther balls meet every band's distance
    if side:
        keep &= side * _signed(p0, p1, vol.c[:, 0], vol.c[:, 1]) <= vol.r
    near = np.flatnonzero(keep)
    d, z, rad = d[near], vol.c[near, 2], vol.r[near]
    rows = []
    for lo, hi, mid in BANDS:
        need = T.reach_over_distance(max(mid, 0.0) * 1000.0, b_mm) / 1000.0
        if need <= 0.0:
            continue
        gap = np.maximum(np.maximum(lo - z, z - hi), 0.0)  # vertical distance of each centre from the band
        cut = gap < rad
        if not cut.any():
            rows.append(ReachOver(top, math.nan, math.inf, need, (max(lo, 0.0), hi), side=side))
            continue
        dist = d[cut] - np.sqrt(rad[cut] ** 2 - gap[cut] ** 2)
        k = int(np.argmin(dist))
        i = int(near[np.flatnonzero(cut)[k]])
        rows.append(ReachOver(top, float(min(max(vol.c[i, 2], lo, 0.0), hi)), max(float(dist[k]), 0.0), need,
                              (max(lo, 0.0), hi), vol.part_names[int(vol.part[i])], round(float(vol.t[i]), 3),
                              side))
    return rows


def panels_at(xs: np.ndarray, ys: np.ndarray, panels, reach: float) -> list[tuple[int, int]]:
    """(index, side) of the panels (start, end pairs) a worker whose centre stands at one of the points (xs, ys)
    is at: a panel within ``reach`` of a point whose nearest point on the panel is not a joint with another
    panel (at a corner or a T-junction the worker is at the panel that meets them, not at the one that ends
    there); side as ``ReachOver.side`` (0 where the worker stands on both sides, or in line with the panel)."""
    segs = [(np.asarray(a, float), np.asarray(b, float)) for a, b in panels]
    A = np.array([a for a, _ in segs]).reshape(-1, 2)
    B = np.array([b for _, b in segs]).reshape(-1, 2)

    def joined(p, i: int) -> bool:
        d = point_segment(p[0], p[1], A[:, 0], A[:, 1], B[:, 0], B[:, 1])[0]
        d[i] = np.inf
        return bool((d < 1e-6).any())

    out = []
    for i, (a, b) in enumerate(segs):
        d, qx, qy = point_segment(xs, ys, a[0], a[1], b[0], b[1])
        near = d <= reach
        for end in (a, b):
            if near.any() and joined(end, i):
                near &= np.hypot(qx - end[0], qy - end[1]) > 1e-9
        if near.any():
            sd = _signed(a, b, xs[near], ys[near])
            left, right = bool((sd > 1e-9).any()), bool((sd < -1e-9).any())
            out.append((i, 1 if left and not right else -1 if right and not left else 0))
    return out
