"""Openings in the perimeter that let the whole body through (ISO 13857:2019, 4.2.4.1 / Table 4's limits: a slot
wider than 180 mm, a square or round opening wider than 240 mm), for the static check.

**The openings looked at.** (1) The gap under every fence panel or guard door raised off the floor: bottom x panel
length. (2) The gap from every free end of a fence (an end that meets no other panel) to the nearest point of each
segment of every barrier: a fence's panels (its own far ones included), a door leaf, the edges of the table and of
the obstacles, the floor's edge;
its height is the lower of the two barriers' tops. A line that crosses another barrier, or runs from the end back
beside its own wall (the point lies behind the end along the end's panel), is no opening. The cell
format has no solid above a panel, so there is no gap over a panel's top to look at.

**Shape.** An opening w x h: if its longer side is at most 240 mm it fits in a 240 mm square, which no body passes
(square rule, e = the longer side); otherwise it is a slot whose e is its shorter side, and the body passes if
e > 180 mm. Reading a rectangle as a slot is the conservative choice (the slot's limit is the lower one).

**In the perimeter.** An opening matters if it leads from floor the worker reaches unseen (the undetected fill
``analysis.floor_fill``, region of the start) to floor the worker cannot reach unseen by walking: probe points
0.25 m either side of its line (at a quarter, half and three quarters of its length); one side in the start's
region, the other walkable and outside it. A wide opening the walking worker passes is therefore no new way in
(its inside is already in the region, and the undetected reach judges what can be touched from there); what this
rule adds are the openings the walking worker cannot pass but a body can: crawling under a raised panel, squeezing
sideways through a gap narrower than the walking body.

**Covered.** A device covers an opening when a body passing it is detected: its line lies (within 5 cm) on a light
curtain's line or a door leaf, or inside a scanner's, mat's or monitored area's polygon (edge included); or every
inside probe point lies in a detection zone. Whether that device is far enough from the hazard is its own row.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cellstress.analysis.floor_fill import FloorFill
from cellstress.analysis.plane import point_segment, points_in_polygon
from cellstress.core.iso13857 import WHOLE_BODY_SLOT_MM, WHOLE_BODY_SQUARE_ROUND_MM
from cellstress.core.records import DoorLeaf, ScanPlane
from cellstress.human.body import PRONE_HEIGHT, WALK_BLOCK_HEIGHT

PROBE = 0.25  # m either side of an opening's line (beyond the detection margins and a grid cell)
ON_TOL = 0.05  # m, an opening within this of a detection primitive lies on it
JOIN_TOL = 1e-6  # m, a fence end this close to another panel meets it


@dataclass(frozen=True)
class Opening:
    """One opening in the perimeter with its size against ISO 13857's whole-body limits."""

    kind: str  # "under" (under a raised panel or door) or "gap" (from a fence's free end to another barrier)
    where: str  # e.g. "under fence 5 panel 1", "gap from fence 2's end to fence 3"
    start: tuple[float, float]  # its line on the floor [m]
    end: tuple[float, float]
    width: float  # m, along the floor
    height: float  # m, its clear height
    outside: tuple[float, float]  # a probe point on the side the worker reaches unseen
    inside: tuple[float, float]  # ... and one on the other side
    covered_by: tuple[str, ...] = ()  # devices that see a body passing it
    sim_note: str = ""  # what the simulated worker cannot do here ("": it can pass)
    fence: int = -1  # index (from 0) of the raised fence ("under") or of the fence whose free end opens the gap
    door: str = ""  # the guard door whose leaf is raised ("under" a door)

    @property
    def shape(self) -> str:
        return "square" if max(self.width, self.height) * 1000.0 <= WHOLE_BODY_SQUARE_ROUND_MM + 1e-6 else "slot"

    @property
    def e_mm(self) -> float:
        """ISO 13857's e: a slot's narrow width, a square's side."""
        return (max if self.shape == "square" else min)(self.width, self.height) * 1000.0

    @property
    def limit_mm(self) -> float:
        return WHOLE_BODY_SQUARE_ROUND_MM if self.shape == "square" else WHOLE_BODY_SLOT_MM

    @property
    def admits_body(self) -> bool:
        return self.e_mm > self.limit_mm + 1e-6

    @property
    def ok(self) -> bool:
        return not self.admits_body or bool(self.covered_by)

    def line(self) -> str:
        (x0, y0), (x1, y1) = self.start, self.end
        size = (f"{self.where} ({x0:.2f}, {y0:.2f})-({x1:.2f}, {y1:.2f}): {self.width * 1000:.0f} x "
                f"{self.height * 1000:.0f} mm, a {self.shape}, e = {self.e_mm:.0f} mm "
                f"{'>' if self.admits_body else '<='} {self.limit_mm:.0f} mm (ISO 13857 whole body)")
        if not self.admits_body:
            return size + ": the body does not pass: ok"
        if self.covered_by:
            return size + f": the body passes, seen by {', '.join(self.covered_by)}: ok"
        text = size + ": the body passes unseen into floor not otherwise reached: FAIL"
        return text + (f"; {self.sim_note}" if self.sim_note else "")


# ---- the barriers and the candidate openings --------------------------------------------------------------
@dataclass(frozen=True)
class _Barrier:
    name: str
    segments: tuple[tuple[tuple[float, float], tuple[float, float]], ...]
    top: float


def _barriers(spec) -> list[_Barrier]:
    out = []
    for i, f in enumerate(spec.fences, 1):
        segs = tuple((tuple(map(float, a)), tuple(map(float, b))) for a, b in zip(f.points, f.points[1:],
                                                                                 strict=False))
        out.append(_Barrier(f"fence {i}", segs, float(f.top)))
    for d in spec.devices:
        for p in d.primitives():
            if isinstance(p, DoorLeaf):
                out.append(_Barrier(f"door {d.name}", ((tuple(map(float, p.start)), tuple(map(float, p.end))),),
                                    float(p.top)))
    for ob in spec.solid_obstacles():
        poly = [tuple(map(float, q)) for q in ob.footprint()]
        out.append(_Barrier(ob.name, tuple((poly[k], poly[(k + 1) % len(poly)]) for k in range(len(poly))),
                            float(ob.height)))
    fl = spec.floor
    c = [(fl.xmin, fl.ymin), (fl.xmax, fl.ymin), (fl.xmax, fl.ymax), (fl.xmin, fl.ymax)]
    out.append(_Barrier("the floor's edge", tuple((c[k], c[(k + 1) % 4]) for k in range(4)), math.inf))
    return out


def _nearest_on(p, segs) -> tuple[float, tuple[float, float]]:
    best = (math.inf, p)
    for a, b in segs:
        d, qx, qy = point_segment(p[0], p[1], a[0], a[1], b[0], b[1])
        if float(d) < best[0]:
            best = (float(d), (float(qx), float(qy)))
    return best


def _cross(a, b, c, d) -> bool:
    """Whether the segments a-b and c-d intersect (touching included)."""
    def orient(p, q, r):
        v = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
        return 0 if abs(v) < 1e-12 else (1 if v > 0 else -1)

    def on(p, q, r):
        return min(p[0], q[0]) - 1e-12 <= r[0] <= max(p[0], q[0]) + 1e-12 and \
            min(p[1], q[1]) - 1e-12 <= r[1] <= max(p[1], q[1]) + 1e-12

    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    if o1 != o2 and o3 != o4:
        return True
    return (o1 == 0 and on(a, b, c)) or (o2 == 0 and on(a, b, d)) or (o3 == 0 and on(c, d, a)) or \
        (o4 == 0 and on(c, d, b))


def _blocked(p, q, barriers) -> bool:
    """Whether the line p-q, less a millimetre at each end, meets any barrier."""
    n = math.hypot(q[0] - p[0], q[1] - p[1])
    if n <= 2e-3:
        return False
    ux, uy = (q[0] - p[0]) / n, (q[1] - p[1]) / n
    a, b = (p[0] + 1e-3 * ux, p[1] + 1e-3 * uy), (q[0] - 1e-3 * ux, q[1] - 1e-3 * uy)
    return any(_cross(a, b, s0, s1) for br in barriers for s0, s1 in br.segments)


def _free_ends(spec, barriers) -> list[tuple[int, tuple[float, float], int]]:
    """(fence index from 0, the end point, index of its own panel) of every fence end that meets no other panel,
    door leaf or obstacle."""
    out = []
    for i, f in enumerate(spec.fences):
        n = len(f.points) - 1
        for end, own in ((tuple(map(float, f.points[0])), 0), (tuple(map(float, f.points[-1])), n - 1)):
            joined = False
            for k, br in enumerate(barriers):
                segs = [s for j, s in enumerate(br.segments) if not (k == i and j == own)]
                if segs and _nearest_on(end, segs)[0] <= JOIN_TOL:
                    joined = True
                    break
            if not joined:
                out.append((i, end, own))
    return out


def _ahead(fence, own: int, end, q) -> bool:
    """Whether q lies ahead of or beside the fence's free ``end`` (not back along the fence's own end panel): a
    gap opens from the end of a wall; a line from the end back across the floor beside the wall is no opening."""
    a, b = fence.points[own], fence.points[own + 1]
    other = b if tuple(map(float, a)) == tuple(end) else a
    ux, uy = end[0] - other[0], end[1] - other[1]
    return (q[0] - end[0]) * ux + (q[1] - end[1]) * uy >= -1e-9 * math.hypot(ux, uy)


def candidate_openings(spec) -> list[tuple[str, str, tuple, tuple, float, int, str]]:
    """(kind, where, start, end, clear height, fence index, door name) of every opening to look at, without
    duplicates (``Opening.fence``, ``Opening.door``)."""
    barriers = _barriers(spec)
    out, seen = [], set()
    for i, f in enumerate(spec.fences, 1):
        if f.bottom > 0.0:
            for j, (a, b) in enumerate(zip(f.points, f.points[1:], strict=False), 1):
                out.append(("under", f"under fence {i} panel {j}", tuple(map(float, a)), tuple(map(float, b)),
                            float(f.bottom), i - 1, ""))
    for d in spec.devices:
        for p in d.primitives():
            if isinstance(p, DoorLeaf) and p.bottom > 0.0:
                out.append(("under", f"under door {d.name}", tuple(map(float, p.start)), tuple(map(float, p.end)),
                            float(p.bottom), -1, d.name))
    for i, end, own in _free_ends(spec, barriers):
        for k, br in enumerate(barriers):  # each segment of each barrier: a fence's own far panels included
            for j, seg in enumerate(br.segments):
                if k == i and j == own:
                    continue
                d, q = _nearest_on(end, [seg])
                if d <= JOIN_TOL or not _ahead(spec.fences[i], own, end, q) or _blocked(end, q, barriers):
                    continue
                key = tuple(sorted((tuple(np.round(end, 4)), tuple(np.round(q, 4)))))
                if key in seen:
                    continue
                seen.add(key)
                top = min(float(spec.fences[i].top), br.top)
                out.append(("gap", f"gap from fence {i + 1}'s end to {br.name}", end, q, top, i, ""))
    return out


# ---- in the perimeter, covered ----------------------------------------------------------------------------
def _probes(a, b, off: float) -> tuple[list, list]:
    """Probe points at a quarter, half and three quarters of a-b, ``off`` metres to its left and to its right."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    n = math.hypot(dx, dy)
    nx, ny = -dy / n, dx / n
    mids = [(a[0] + f * dx, a[1] + f * dy) for f in (0.25, 0.5, 0.75)]
    return ([(m[0] + off * nx, m[1] + off * ny) for m in mids], [(m[0] - off * nx, m[1] - off * ny) for m in mids])


def _covering(spec, a, b, inside, fill: FloorFill) -> tuple[str, ...]:
    out = []
    for d in spec.devices:
        for p in d.primitives():
            if isinstance(p, ScanPlane):
                px, py = np.array([a[0], b[0], 0.5 * (a[0] + b[0])]), np.array([a[1], b[1], 0.5 * (a[1] + b[1])])
                edge = np.array([min(point_segment(x, y, *p.polygon[k], *p.polygon[(k + 1) % len(p.polygon)])[0]
                                     for k in range(len(p.polygon))) for x, y in zip(px, py, strict=True)])
                on = bool(np.all(points_in_polygon(px, py, p.polygon) | (edge <= ON_TOL)))
            else:
                s0, s1 = p.start, p.end
                on = all(float(point_segment(x, y, s0[0], s0[1], s1[0], s1[1])[0]) <= ON_TOL
                         for x, y in (a, b, (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]))))
            if on and d.name not in out:
                out.append(d.name)
    if not out:  # every inside probe seen: walkable but outside the unseen floor
        cells = [fill.index(*q) for q in inside]
        if cells and all(c is not None and fill.walk[c] and not fill.ok[c] for c in cells):
            out.append("a detection zone just inside")
    return tuple(out)


def simulated_body_passes_under(articulated: bool, bottom: float) -> bool:
    """Whether the simulated worker gets under a panel whose bottom edge is ``bottom`` [m] above the floor: walking
    from WALK_BLOCK_HEIGHT; the articulated worker also crawling, above its prone body's height PRONE_HEIGHT (the
    declaration kernels.sensing.panel_stops_body reads: the same comparisons)."""
    return not bottom < WALK_BLOCK_HEIGHT or (articulated and not bottom <= PRONE_HEIGHT)


def crawl_note(articulated: bool, bottom: float) -> str:
    """What an opening under a panel raised ``bottom`` [m] says about the simulated worker ("": it passes)."""
    if simulated_body_passes_under(articulated, bottom):
        return ""
    if articulated:
        return (f"the simulated worker crawls under a panel only above {PRONE_HEIGHT:.2f} m, its prone body's "
                "height: a search will not find this way in")
    return (f"the paper's worker cannot crawl (it walks under a panel only from {WALK_BLOCK_HEIGHT:.1f} m; "
            f"the articulated worker crawls under one above {PRONE_HEIGHT:.2f} m): a search will not find this way in")


def perimeter_openings(spec, fill: FloorFill, body_radius: float) -> tuple[Opening, ...]:
    """The openings of ``candidate_openings`` that lead from the start's unseen region to floor outside it."""
    out = []
    for kind, where, a, b, top, fence, door in candidate_openings(spec):
        width = math.hypot(b[0] - a[0], b[1] - a[1])
        if width <= JOIN_TOL:
            continue
        left, right = _probes(a, b, PROBE)
        sides = []
        for pts in (left, right):
            cells = [fill.index(*q) for q in pts]
            reached = any(c is not None and fill.U[c] for c in cells)
            beyond = any(c is not None and fill.walk[c] and not fill.U[c] for c in cells)
            sides.append((reached, beyond, pts))
        pair = next(((o[2], i[2]) for o, i in ((sides[0], sides[1]), (sides[1], sides[0])) if o[0] and i[1]), None)
        if pair is None:
            continue
        out_pts, in_pts = pair
        covered = _covering(spec, a, b, in_pts, fill)
        if kind == "under":
            note = crawl_note(spec.human.model == "articulated", top)
        else:
            note = (f"the simulated worker (body radius {body_radius:.2f} m) needs {2 * body_radius:.2f} m: a search "
                    "will not find this way in") if width < 2 * body_radius else ""
        mid = (0.5 * (out_pts[0][0] + out_pts[-1][0]), 0.5 * (out_pts[0][1] + out_pts[-1][1]))
        mid_in = (0.5 * (in_pts[0][0] + in_pts[-1][0]), 0.5 * (in_pts[0][1] + in_pts[-1][1]))
        out.append(Opening(kind, where, (round(a[0], 4), round(a[1], 4)), (round(b[0], 4), round(b[1], 4)),
                           width, top, (round(mid[0], 4), round(mid[1], 4)), (round(mid_in[0], 4),
                                                                              round(mid_in[1], 4)),
                           covered, note, fence, door))
    return tuple(out)
