"""The hazard zone of the static check: the floor footprint of everything the robot sweeps in one cycle, and the
distance from a floor segment to it (ISO 13855 measures safety distances horizontally to this zone)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cellstress.analysis.plane import point_segment
from cellstress.sim import kernels as K
from cellstress.sim import layout as L

SAMPLE_DT = 0.01  # s between robot poses when sampling the hazard zone


@dataclass(frozen=True, eq=False)
class HazardZone:
    """The robot's swept floor footprint: stadiums (segment a-b inflated by r); exact repeats (the base, the
    dwells) are kept once."""

    a: np.ndarray  # (n, 2)
    b: np.ndarray  # (n, 2)
    r: np.ndarray  # (n,)
    t: np.ndarray  # (n,) episode time [s] of the pose (first occurrence), in [0, cycle)
    part: np.ndarray  # (n,) int capsule index
    part_names: tuple[str, ...]
    cycle: float
    sample_dt: float
    n_poses: int

    def extent(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax) of the footprint."""
        lo = np.minimum(self.a, self.b) - self.r[:, None]
        hi = np.maximum(self.a, self.b) + self.r[:, None]
        return float(lo[:, 0].min()), float(hi[:, 0].max()), float(lo[:, 1].min()), float(hi[:, 1].max())


@dataclass(frozen=True)
class Closest:
    """Where a distance is attained: a point on our side, the nearest point of the hazard zone, the robot
    capsule there and the episode time [s] (modulo the cycle) at which the robot sweeps it."""

    point: tuple[float, float]
    hazard_point: tuple[float, float]
    robot_part: str
    t: float


def segment_to_zone(p0, p1, zone: HazardZone, t_max: float = math.inf):
    """Horizontal distance from segment p0-p1 to the hazard zone (only poses at t <= t_max):
    (distance, our point, zone point, index)."""
    sel = np.flatnonzero(zone.t <= t_max + 1e-9)
    if len(sel) == 0:
        return math.inf, tuple(p0), tuple(p0), -1
    ax, ay, bx, by = zone.a[sel, 0], zone.a[sel, 1], zone.b[sel, 0], zone.b[sel, 1]
    (x0, y0), (x1, y1) = p0, p1
    cands = []
    # the four endpoint-to-segment distances; each gives (d, point on p0p1, point on the zone's axis)
    d, qx, qy = point_segment(x0, y0, ax, ay, bx, by)
    cands.append((d, np.full_like(d, x0), np.full_like(d, y0), qx, qy))
    d, qx, qy = point_segment(x1, y1, ax, ay, bx, by)
    cands.append((d, np.full_like(d, x1), np.full_like(d, y1), qx, qy))
    d, qx, qy = point_segment(ax, ay, x0, y0, x1, y1)
    cands.append((d, qx, qy, ax, ay))
    d, qx, qy = point_segment(bx, by, x0, y0, x1, y1)
    cands.append((d, qx, qy, bx, by))
    stack = np.array(cands)  # (4, 5, n)
    k = np.argmin(stack[:, 0, :], axis=0)
    best = stack[k, :, np.arange(len(k))]  # (n, 5)
    # proper intersections: distance 0
    def orient(ux, uy, vx, vy, wx, wy):
        return (vx - ux) * (wy - uy) - (vy - uy) * (wx - ux)
    o1, o2 = orient(x0, y0, x1, y1, ax, ay), orient(x0, y0, x1, y1, bx, by)
    o3, o4 = orient(ax, ay, bx, by, x0, y0), orient(ax, ay, bx, by, x1, y1)
    cross = (o1 * o2 < 0) & (o3 * o4 < 0)
    if cross.any():
        t = o3[cross] / (o3[cross] - o4[cross])
        ix, iy = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
        best[cross] = np.stack([np.zeros_like(ix), ix, iy, ix, iy], axis=1)
    rr = zone.r[sel]
    g = best[:, 0] - rr
    j = int(np.argmin(g))
    dist, px, py, qx, qy = best[j]
    # the zone's point: from the axis point towards ours by the radius
    n = math.hypot(px - qx, py - qy)
    if n > 0:
        hx, hy = qx + (px - qx) * rr[j] / n, qy + (py - qy) * rr[j] / n
    else:
        hx, hy = qx, qy
    return max(float(g[j]), 0.0), (float(px), float(py)), (float(hx), float(hy)), int(sel[j])


def closest_on_zone(zone: HazardZone, point, hazard_point, i: int) -> Closest:
    return Closest((round(point[0], 4), round(point[1], 4)), (round(hazard_point[0], 4), round(hazard_point[1], 4)),
                   zone.part_names[int(zone.part[i])], round(float(zone.t[i]), 3))


def robot_poses(P, sample_dt: float, robot: int | None = None) -> list[tuple[np.ndarray, np.ndarray, np.ndarray,
                                                                             np.ndarray]]:
    """Each robot's capsules (``robot``'s only, if given) every ``sample_dt`` over its own cycle, before any stop:
    per robot (times, capsule indices, axis ends a, b: (times, capsules, 3)). Robot 0 is posed by
    ``kernels.robot_live``; robots 1.. at t = k * sample_dt without the pre-stop table (``kernels.other_robots``)."""
    W = K.make_work(P)
    nx = P.x_scal.shape[0]
    parts = []
    for r in range(nx + 1) if robot is None else (robot,):
        scal = P.scal if r == 0 else P.x_scal[r - 1]
        ts = np.arange(0.0, float(scal[L.C_CYCLE]), sample_dt)
        c0 = 0 if r == 0 else int(P.x_cap0[r - 1])
        caps = np.arange(c0, c0 + (P.cap_joint.shape[0] if r == 0 else int(P.x_ncap[r - 1])))
        ra = np.empty((len(ts), len(caps), 3))
        rb = np.empty((len(ts), len(caps), 3))
        if r > 0:
            x_scal = P.x_scal.copy()
            x_scal[:, L.C_DT] = sample_dt
            Pr = P._replace(x_scal=x_scal, pre_xv=np.zeros((0, nx)))
            state = np.full(L.NS, np.inf)
        for k, t in enumerate(ts):
            if r == 0:
                K.robot_live(P, float(t), np.inf, W)
            else:
                K.other_robots(Pr, np.int64(k), state, W)
            ra[k] = W.ra[caps]
            rb[k] = W.rb[caps]
        parts.append((ts, caps, ra, rb))
    return parts


def hazard_zone(layout, sample_dt: float = SAMPLE_DT, robot: int | None = None) -> HazardZone:
    """Sample the robot capsules over one cycle (before any stop) into floor stadiums. In a cell of several
    robots: every robot's, each over its own cycle (``cycle`` is robot 0's), or robot ``robot``'s only."""
    P = layout.params
    parts = robot_poses(P, sample_dt, robot)
    a = np.concatenate([ra[:, :, :2].reshape(-1, 2) for _, _, ra, _ in parts])
    b = np.concatenate([rb[:, :, :2].reshape(-1, 2) for _, _, _, rb in parts])
    r_ = np.concatenate([np.broadcast_to(P.cap_r[caps], (len(ts), len(caps))).reshape(-1)
                         for ts, caps, _, _ in parts])
    tt = np.concatenate([np.repeat(ts, len(caps)) for ts, caps, _, _ in parts])
    part = np.concatenate([np.tile(caps, len(ts)) for ts, caps, _, _ in parts])
    key = np.round(np.concatenate([a, b, r_[:, None]], axis=1) * 1e6).astype(np.int64)  # drops only exact repeats
    _, first = np.unique(key, axis=0, return_index=True)
    first = np.sort(first)
    return HazardZone(np.ascontiguousarray(a[first]), np.ascontiguousarray(b[first]),
                      np.ascontiguousarray(r_[first]), tt[first], part[first],
                      tuple(c.name for c in layout.capsules), float(P.scal[L.C_CYCLE]), sample_dt,
                      len(parts[0][0]))
