"""The floor a worker can stand on unseen, for the static check: a 5 cm grid over the cell's floor, the cells a
worker's centre may occupy (a body radius from the floor's edge, the table, obstacles and walk-blocking fences)
without being seen by any device, and their connected regions (docs/cells.md, "Undetected reach")."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from cellstress.analysis.plane import distance_to_polyline, point_segment, points_in_polygon
from cellstress.core.records import ScanPlane
from cellstress.human.body import WALK_BLOCK_HEIGHT
from cellstress.sim import layout as L

GRID = 0.05  # m, flood-fill grid


def _upright_capsule_bands(body: np.ndarray) -> list[tuple[float, float, float]]:
    """(z low, z high, radius) of the upright worker's body capsules (kernels.human_pose at zero flexion)."""
    hip = body[L.B_HIP_Z]
    shoulder = hip + body[L.B_SHOULDER_RISE]
    arm_low = max(shoulder - (body[L.B_ARM_LEN] - body[L.B_R_ARM]), body[L.B_R_ARM])
    head = hip + body[L.B_HEAD_RISE]
    rl, rt, rh, ra = body[L.B_R_LEG], body[L.B_R_TRUNK], body[L.B_R_HEAD], body[L.B_R_ARM]
    return [(0.0, hip + rl, rl), (hip - rt, hip + body[L.B_TRUNK_TOP] + rt, rt),
            (head - rh, head + rh, rh), (arm_low - ra, shoulder + ra, ra)]


def detection_margin(body: np.ndarray, lo: float, hi: float) -> float:
    """How close (plan view) the worker's centre may come to a detection zone spanning heights lo..hi unseen.

    Facing the zone, every body capsule's axis lies on the line through the centre parallel to the zone's
    edge (legs and arms are side by side), so the worker stays unseen while the centre is farther than the
    largest radius among the capsules that reach into the height band.
    """
    radii = [r for (zl, zh, r) in _upright_capsule_bands(body) if zl <= hi and zh >= lo]
    return max(radii) if radii else 0.0


def walk_blocking_fences(spec):
    return [(a, b) for f in spec.fences if f.bottom < WALK_BLOCK_HEIGHT
            for a, b in zip(f.points, f.points[1:], strict=False)]


@dataclass(frozen=True, eq=False)
class FloorFill:
    """The grid, where a worker's centre may stand (``walk``: ignoring the devices; ``ok``: unseen as well), the
    connected regions of ``ok`` (``labels``) and the start's (``U``; empty when the start is seen)."""

    xs: np.ndarray  # (nx,) cell centres [m]
    ys: np.ndarray  # (ny,)
    X: np.ndarray  # (ny, nx)
    Y: np.ndarray
    walk: np.ndarray  # (ny, nx) bool
    ok: np.ndarray
    labels: np.ndarray  # (ny, nx) int, 0 outside ``ok``
    U: np.ndarray  # (ny, nx) bool
    detected: bool
    curtains: tuple  # ((start, end), ...) of every vertical detection zone
    m_scan: float | None  # the margins kept from scanner fields and from curtains (None: none of them)
    m_curtain: float | None
    x0: float
    y0: float

    def index(self, x: float, y: float) -> tuple[int, int] | None:
        """(iy, ix) of the grid cell holding (x, y), None off the grid."""
        ix = int(np.floor((x - self.x0) / GRID))
        iy = int(np.floor((y - self.y0) / GRID))
        if 0 <= ix < len(self.xs) and 0 <= iy < len(self.ys):
            return iy, ix
        return None


def floor_fill(spec, body: np.ndarray) -> FloorFill:
    """The undetected floor of the cell for a worker of ``body`` (``sim.layout`` body parameters) starting at
    ``spec.human.start``."""
    radius = float(body[L.B_BODY_RADIUS])
    fl = spec.floor
    h = GRID
    nx = int(round((fl.xmax - fl.xmin) / h))
    ny = int(round((fl.ymax - fl.ymin) / h))
    xs = fl.xmin + (np.arange(nx) + 0.5) * h
    ys = fl.ymin + (np.arange(ny) + 0.5) * h
    X, Y = np.meshgrid(xs, ys)  # (ny, nx)
    ok = (X - radius >= fl.xmin) & (X + radius <= fl.xmax) & (Y - radius >= fl.ymin) & (Y + radius <= fl.ymax)
    for ob in spec.solid_obstacles():  # (the robot's pedestal stands inside the hazard zone: no matter)
        poly = ob.footprint()
        ok &= ~points_in_polygon(X, Y, poly) & (distance_to_polyline(X, Y, poly, True) >= radius)
    for a, b in walk_blocking_fences(spec):
        ok &= point_segment(X, Y, a[0], a[1], b[0], b[1])[0] >= radius
    walk = ok.copy()
    m_scan: float | None = None
    m_curtain: float | None = None
    curtains = []
    for prim in (p for d in spec.devices for p in d.primitives()):
        if isinstance(prim, ScanPlane):
            m = detection_margin(body, prim.height, prim.height)
            m_scan = m if m_scan is None else max(m_scan, m)
            ok &= ~points_in_polygon(X, Y, prim.polygon) & (distance_to_polyline(X, Y, prim.polygon, True) > m)
        else:
            m = detection_margin(body, prim.bottom, prim.top)
            m_curtain = m if m_curtain is None else max(m_curtain, m)
            ok &= point_segment(X, Y, prim.start[0], prim.start[1], prim.end[0], prim.end[1])[0] > m
            curtains.append((tuple(prim.start), tuple(prim.end)))
    sx, sy = spec.human.start.xy
    ix = min(max(int((sx - fl.xmin) / h), 0), nx - 1)
    iy = min(max(int((sy - fl.ymin) / h), 0), ny - 1)
    labels, _ = ndimage.label(ok)
    seed = labels[iy, ix]
    if seed == 0:  # the start cell's centre is a little off the start point: try the neighbours
        near = labels[max(iy - 1, 0):iy + 2, max(ix - 1, 0):ix + 2]
        seed = int(near.max())
    detected = seed == 0
    U = (labels == seed) if not detected else np.zeros_like(ok)
    return FloorFill(xs, ys, X, Y, walk, ok, labels, U, bool(detected), tuple(curtains), m_scan, m_curtain,
                     float(fl.xmin), float(fl.ymin))
