"""Getting round an electro-sensitive device or a mat, for the static check (ISO 13855:2010): reaching over a light
curtain's top beam (C_RO, Table 1), crawling under its lowest beam or stepping over its top one, a laser scanner's
mounting height against its resolution, a safety mat too shallow to be stepped across unseen.

Each rule gives one record per device with its arithmetic (``line``) and ``ok``; ``StaticCheck.failures`` names
the failed ones ``DEVICE-reach-over``, ``DEVICE-crawl-under``, ``DEVICE-step-over``, ``DEVICE-mounting``,
``DEVICE-depth``. Where the standard's way round is one the simulated worker cannot take (no worker steps over
anything; the paper's worker does not crawl, nor tell reaching over a curtain from reaching through it, the
articulated one does both), the line says so: a search will not find that way in, and the static verdict stands
on its own. Sources and the choices made: docs/cells.md, "Ways in".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cellstress.analysis.plane import open_intervals, point_segment
from cellstress.analysis.reach_over import HazardVolume
from cellstress.core import iso13855 as I
from cellstress.core.iso13855 import mm
from cellstress.devices.laser_scanner import LaserScanner
from cellstress.devices.light_curtain import LightCurtain
from cellstress.devices.safety_mat import SafetyMat
from cellstress.human.body import WALK_BLOCK_HEIGHT

CANNOT_CRAWL = "the simulated worker cannot crawl or step over: a search will not find this way in"
CANNOT_STEP = "the simulated worker cannot step over: a search will not find this way in"
# The paper's worker neither crawls nor leans over a curtain; the articulated one crawls prone (its body 0.30 m
# high: human.body.PRONE_HEIGHT, so a beam or scan plane above that misses it) and reaches over a curtain's top
# with its arms (a curtain is a sensor, not a wall: an arm above the top beam is not seen). docs/worker.md.
CANNOT_REACH_OVER = ("the paper's worker's arms are reach volumes no device sees, over the top or through the field "
                     "alike: the articulated worker's search looks for this way in")
_TOL = 1e-9


def entry_covers(spec) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """The segments along which a worker cannot step into a detection zone: walk-blocking fence panels, the floor's
    edges, the edges of the table and of every obstacle."""
    fl = spec.floor
    out = [(tuple(a), tuple(b)) for f in spec.fences if f.bottom < WALK_BLOCK_HEIGHT
           for a, b in zip(f.points, f.points[1:], strict=False)]
    out += [((fl.xmin, fl.ymin), (fl.xmax, fl.ymin)), ((fl.xmax, fl.ymin), (fl.xmax, fl.ymax)),
            ((fl.xmax, fl.ymax), (fl.xmin, fl.ymax)), ((fl.xmin, fl.ymax), (fl.xmin, fl.ymin))]
    for ob in spec.solid_obstacles():
        poly = ob.footprint()
        out += [(tuple(poly[i]), tuple(poly[(i + 1) % len(poly)])) for i in range(len(poly))]
    return out


# ---- reaching over a light curtain (ISO 13855:2010 6.5, Table 1) -----------------------------------------
@dataclass(frozen=True)
class CurtainReachOver:
    """S_RO = K T + C_RO for a light curtain, in the band of hazard heights where the zone comes closest to it."""

    device: str
    top: float  # m, b: the upper edge of the detection zone
    T: float  # s, as the curtain's own row
    K: float  # mm/s
    c_ro: float  # mm, Table 1 for the band (inf: b below the table's first column)
    band: tuple[float, float]  # m, the rows a_i..a_i+1 of Table 1 (the lowest band open below, the top one above)
    hazard_height: float  # m, height of the zone's nearest point in the band (nan: none)
    behind: float  # m, horizontal distance from the curtain's line to the zone in that band (inf: none)
    through: float  # m, S_RT of the curtain's own row (through the field)
    robot: str = ""
    robot_part: str = ""
    t: float = math.nan  # s, episode time of that pose (mod the cycle)
    sim_note: str = CANNOT_REACH_OVER  # what the simulated worker cannot do here ("": the articulated worker can)
    beam_line: tuple[tuple[float, float], tuple[float, float]] | None = None  # the curtain's line on the floor

    @property
    def required(self) -> float:
        """S_RO [m]."""
        return (self.K * self.T + self.c_ro) / 1000.0

    @property
    def ok(self) -> bool:
        return self.behind >= self.required - _TOL

    @property
    def model_limit(self) -> str:
        """What the simulated worker cannot do to take this way in ('' where the row passes)."""
        return "" if self.ok else self.sim_note

    def line(self) -> str:
        lo, hi = self.band
        b = self.top * 1000.0
        if math.isinf(self.c_ro):
            return (f"{self.device}: reach over its top (ISO 13855 6.5, Table 1): upper edge b = {mm(b)} mm is below "
                    f"the table's first column ({mm(I.C_RO_B_MM[0])} mm): no distance is enough: FAIL"
                    + (f"; {self.model_limit}" if self.model_limit else ""))
        band = f"a {lo * 1000:.0f}..{hi * 1000:.0f} mm" if math.isfinite(hi) else f"a >= {lo * 1000:.0f} mm"
        text = (f"{self.device}: reach over its top (ISO 13855 6.5, Table 1): b = {mm(b)} mm, hazard at "
                f"{self.hazard_height:.2f} m ({band}): C_RO = {mm(self.c_ro)} mm, S_RO = {mm(self.K)}*{self.T:.2f} + "
                f"{mm(self.c_ro)} = {mm(self.required * 1000)} mm; the zone there is {self.behind:.3f} m from the "
                f"curtain: {'ok' if self.ok else 'FAIL'}; S = max(S_RT {mm(self.through * 1000)}, S_RO "
                f"{mm(self.required * 1000)}) = {mm(max(self.through, self.required) * 1000)} mm")
        if self.robot_part:
            text += f" ({self.robot_part} at t = {self.t:.2f} s)"
        return text + "; " + self.model_limit if self.model_limit else text


def _c_ro_bands(top: float) -> list[tuple[float, float, float]]:
    """(lo, hi, C_RO) [m, m, mm] of Table 1's row bands for an upper edge at ``top`` [m]: between two rows the larger
    value (the greater safety), the lowest band open below, above the top row none."""
    col = I.c_ro_column(top * 1000.0)
    a = [x / 1000.0 for x in I.C_RO_A_MM]
    if col is None:
        return [(-math.inf, math.inf, math.inf)]
    bands = [(-math.inf if i == 0 else a[i], a[i + 1], max(col[i], col[i + 1])) for i in range(len(a) - 1)]
    return bands + [(a[-1], math.inf, col[-1])]


def curtain_reach_over(device: LightCurtain, vol: HazardVolume, T: float, through: float,
                       robot: str = "", articulated: bool = False) -> CurtainReachOver:
    """Table 1 at a light curtain: over every row band, the horizontal distance from the curtain's line to the
    zone's part in the band against K T + C_RO; the band with the least margin (the lowest on a tie). The zone
    counts on both sides of the line (the check does not decide which side the hazard is on)."""
    p0, p1 = device.start, device.end
    d = point_segment(vol.c[:, 0], vol.c[:, 1], p0[0], p0[1], p1[0], p1[1])[0]
    z, rad = vol.c[:, 2], vol.r
    note = "" if articulated else CANNOT_REACH_OVER
    best: CurtainReachOver | None = None
    for lo, hi, c in _c_ro_bands(float(device.top)):
        gap = np.maximum(np.maximum(lo - z, z - hi), 0.0)  # vertical distance of each ball's centre from the band
        cut = gap < rad
        if not cut.any():
            continue
        dist = d[cut] - np.sqrt(rad[cut] ** 2 - gap[cut] ** 2)
        k = int(np.argmin(dist))
        i = int(np.flatnonzero(cut)[k])
        row = CurtainReachOver(device.name, float(device.top), T, I.K_REACH_OVER, c, (max(lo, 0.0), hi),
                               float(min(max(vol.c[i, 2], lo, 0.0), hi)), max(float(dist[k]), 0.0), through, robot,
                               vol.part_names[int(vol.part[i])], round(float(vol.t[i]), 3), note,
                               (tuple(map(float, device.start)), tuple(map(float, device.end))))
        if best is None or row.behind - row.required < best.behind - best.required - 1e-12:
            best = row
    if best is None:  # (no zone at all)
        return CurtainReachOver(device.name, float(device.top), T, I.K_REACH_OVER, 0.0, (0.0, math.inf), math.nan,
                                math.inf, through, robot, sim_note=note)
    return best


# ---- crawling under, stepping over (ISO 13855:2010 6.2, 6.3) ----------------------------------------------
@dataclass(frozen=True)
class BeamHeights:
    """A light curtain's lowest and highest beam against crawling under and stepping over (whole-body detection:
    every curtain of the model acts as one)."""

    device: str
    bottom: float  # m
    top: float  # m
    articulated: bool = False  # the cell's worker crawls (under a lowest beam above PRONE_HEIGHT)

    @property
    def crawl_ok(self) -> bool:
        return self.bottom * 1000.0 <= I.CRAWL_UNDER_MAX_MM + 1e-6

    @property
    def step_ok(self) -> bool:
        return self.top * 1000.0 >= I.STEP_OVER_MIN_MM - 1e-6

    @property
    def ok(self) -> bool:
        return self.crawl_ok and self.step_ok

    @property
    def crawl_limit(self) -> str:
        """What the simulated worker cannot do to crawl under the lowest beam ('' where it can, or need not)."""
        return "" if self.crawl_ok or self.articulated else CANNOT_CRAWL

    @property
    def step_limit(self) -> str:
        """What the simulated worker cannot do to step over the highest beam ('' where it need not)."""
        return "" if self.step_ok else CANNOT_STEP if self.articulated else CANNOT_CRAWL

    @property
    def model_limit(self) -> str:
        """The note the row's line carries ('' where the row passes or the worker can take every way in)."""
        if self.ok:
            return ""
        return self.step_limit if self.articulated else CANNOT_CRAWL

    def line(self) -> str:
        lo, hi = self.bottom * 1000.0, self.top * 1000.0
        text = (f"{self.device}: lowest beam {mm(lo)} mm <= {mm(I.CRAWL_UNDER_MAX_MM)} mm (crawling under)? "
                f"{'ok' if self.crawl_ok else 'FAIL'}; highest beam {mm(hi)} mm >= {mm(I.STEP_OVER_MIN_MM)} mm "
                f"(stepping over)? {'ok' if self.step_ok else 'FAIL'} (ISO 13855 6.2, whole-body detection)")
        return text + "; " + self.model_limit if self.model_limit else text


@dataclass(frozen=True)
class ScannerMounting:
    """A horizontal laser scanner's scan plane H against its resolution d: 15 (d - 50) <= H <= 1000 mm, and no
    higher than 300 mm, above which a person may crawl under the field (ISO 13855:2010 6.3)."""

    device: str
    height: float  # m, H
    resolution: float  # mm, d
    articulated: bool = False  # the cell's worker crawls (under a scan plane above PRONE_HEIGHT)

    @property
    def min_height_mm(self) -> float:
        return I.min_scan_height_mm(self.resolution)

    @property
    def c_mm(self) -> float:
        """The intrusion allowance the field's distance uses (``devices.laser_scanner`` takes the same function)."""
        return I.horizontal_c_mm(self.height * 1000.0)

    @property
    def resolution_ok(self) -> bool:
        return self.height * 1000.0 >= self.min_height_mm - 1e-6

    @property
    def crawl_ok(self) -> bool:
        return self.height * 1000.0 <= min(I.CRAWL_UNDER_MAX_MM, I.SCAN_PLANE_MAX_MM) + 1e-6

    @property
    def ok(self) -> bool:
        return self.resolution_ok and self.crawl_ok

    @property
    def model_limit(self) -> str:
        """What the simulated worker cannot do to take this way in: crawl under the plane ('' where it need not,
        or can: the articulated worker crawls)."""
        return "" if self.crawl_ok or self.articulated else CANNOT_CRAWL

    def line(self) -> str:
        h, d = self.height * 1000.0, self.resolution
        text = (f"{self.device}: scan plane H = {mm(h)} mm, resolution d = {mm(d)} mm: H >= 15*({mm(d)} - 50) = "
                f"{mm(self.min_height_mm)} mm? {'ok' if self.resolution_ok else 'FAIL'}; H <= "
                f"{mm(I.CRAWL_UNDER_MAX_MM)} mm (crawling under)? {'ok' if self.crawl_ok else 'FAIL'} (ISO 13855 "
                f"6.3; its C = {mm(self.c_mm)} mm is in S)")
        return text + "; " + self.model_limit if self.model_limit else text


# ---- the depth of a safety mat (ISO 13855:2010, pressure-sensitive mats) -----------------------------------
@dataclass(frozen=True)
class MatDepth:
    """The shortest step across a mat: from a point of an edge a worker can step over, perpendicular into the mat,
    to where that line leaves the mat over an edge a worker can step onto the floor from (inf: none)."""

    device: str
    depth: float  # m
    where: tuple[tuple[float, float], tuple[float, float]] | None  # the crossing's two ends

    @property
    def ok(self) -> bool:
        return self.depth * 1000.0 >= I.MAT_MIN_DEPTH_MM - 1e-6

    @property
    def model_limit(self) -> str:
        """What the simulated worker cannot do to take this way in ('' where the row passes)."""
        return "" if self.ok else CANNOT_CRAWL

    def line(self) -> str:
        need = f"{mm(I.MAT_MIN_DEPTH_MM)} mm (stepping across it unseen; ISO 13855, pressure-sensitive mats)"
        if self.where is None:
            return (f"{self.device}: depth: every crossing from an open edge ends at a fence, the table, an obstacle "
                    f"or the floor's edge, so no step crosses it (needs {need}): ok")
        (x0, y0), (x1, y1) = self.where
        text = (f"{self.device}: depth {mm(self.depth * 1000)} mm from ({x0:.2f}, {y0:.2f}) to ({x1:.2f}, {y1:.2f}) "
                f">= {need}? {'ok' if self.ok else 'FAIL'}")
        return text if self.ok else text + "; " + self.model_limit


def _ray_exit(p, n, poly, skip: int) -> tuple[float, int]:
    """The first crossing (t > 0, edge index) of the ray p + t n with the polygon's edges other than ``skip``."""
    best, at = math.inf, -1
    for j in range(len(poly)):
        if j == skip:
            continue
        a, b = poly[j], poly[(j + 1) % len(poly)]
        ex, ey = b[0] - a[0], b[1] - a[1]
        den = n[0] * ey - n[1] * ex
        if abs(den) < 1e-12:
            continue
        wx, wy = a[0] - p[0], a[1] - p[1]
        t = (wx * ey - wy * ex) / den
        s = (wx * n[1] - wy * n[0]) / den
        if t > 1e-9 and -1e-9 <= s <= 1.0 + 1e-9 and t < best:
            best, at = t, j
    return best, at


def _covered(q, covers) -> bool:
    return any(point_segment(q[0], q[1], a[0], a[1], b[0], b[1])[0] <= 1e-4 for a, b in covers)


def mat_depth(device: SafetyMat, covers, step: float = 0.02) -> MatDepth:
    """The mat's depth (``MatDepth``), probing every ``step`` metres of each open edge."""
    poly = [tuple(map(float, p)) for p in device.polygon]
    area2 = sum(poly[i][0] * poly[(i + 1) % len(poly)][1] - poly[(i + 1) % len(poly)][0] * poly[i][1]
                for i in range(len(poly)))
    sign = 1.0 if area2 > 0 else -1.0  # counter-clockwise: the inside lies left of each edge
    best, where = math.inf, None
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        n = (-sign * (b[1] - a[1]) / length, sign * (b[0] - a[0]) / length)
        for q0, q1 in open_intervals(a, b, covers):
            seg = math.hypot(q1[0] - q0[0], q1[1] - q0[1])
            m = max(int(math.ceil(seg / step)), 1)
            for k in range(m + 1):
                f = k / m
                p = (q0[0] + f * (q1[0] - q0[0]), q0[1] + f * (q1[1] - q0[1]))
                t, _ = _ray_exit(p, n, poly, i)
                if not math.isfinite(t) or t >= best:
                    continue
                q = (p[0] + t * n[0], p[1] + t * n[1])
                if not _covered(q, covers):
                    best, where = t, (p, q)
    return MatDepth(device.name, best, None if where is None else
                    ((round(where[0][0], 4), round(where[0][1], 4)), (round(where[1][0], 4), round(where[1][1], 4))))


def device_rules(spec) -> tuple:
    """The rules that need no hazard zone: every curtain's beam heights, every scanner's mounting, every mat's
    depth, in the order of the cell's devices."""
    covers = entry_covers(spec)
    articulated = spec.human.model == "articulated"
    out: list = []
    for d in spec.devices:
        if isinstance(d, LightCurtain):
            out.append(BeamHeights(d.name, float(d.bottom), float(d.top), articulated))
        elif isinstance(d, LaserScanner):
            out.append(ScannerMounting(d.name, float(d.height), float(d.resolution_mm), articulated))
        elif isinstance(d, SafetyMat):
            out.append(mat_depth(d, covers))
    return tuple(out)


def failure_name(rule) -> list[str]:
    """The names ``StaticCheck.failures`` gives a failed rule."""
    if rule.ok:
        return []
    if isinstance(rule, CurtainReachOver):
        return [f"{rule.device}-reach-over" + (f":{rule.robot}" if rule.robot else "")]
    if isinstance(rule, BeamHeights):
        return [f"{rule.device}-{w}" for w, ok in (("crawl-under", rule.crawl_ok), ("step-over", rule.step_ok))
                if not ok]
    if isinstance(rule, ScannerMounting):
        return [f"{rule.device}-{w}" for w, ok in (("mounting", rule.resolution_ok), ("crawl-under", rule.crawl_ok))
                if not ok]
    return [f"{rule.device}-depth"]
