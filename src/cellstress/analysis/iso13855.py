"""Static safety check of a cell: ISO 13855 safety distances and undetected reach (ISO 13857 style).

``cellstress check`` prints ``static_check(cell)``; ``check_cell(cell)`` returns the same as typed records.
The reasoning behind every number is in docs/cells.md. In short:

* **Hazard zone.** The floor footprint of everything the robot sweeps in one cycle: the capsule axes, posed
  every ``SAMPLE_DT`` over the cycle (``kernels.robot_live``), projected on the floor and inflated by their
  radii ("stadiums"). ISO 13855 measures safety distances horizontally to this zone.
* **ISO 13855 distances.** S = K T + C with T = device response + robot stopping time (its controller's delay
  and its braking time, as the simulator brakes: ``robot.stopping``); each device kind gives
  its own (``Device.required_distance``: the laser scanner's horizontal field, the light curtain as a body
  detector). The actual distance is measured from where a worker enters the device's detection primitive:
  each edge of a scan plane's polygon a worker can step across (edges lying along a walk-blocking fence, the
  table or the floor's edge are no entries), and a vertical field's line.
* **Undetected reach.** The floor the worker can walk on (5 cm grid, 0.2 m body radius) is flood-filled from
  the start point without being seen by any device. From there the trunk can lean the shoulders up to
  ``lean`` (the body model's largest horizontal hip-to-shoulder distance, 0.51 m for the paper's worker) but
  not through a fence or a light curtain (the curtain would see the trunk); from the shoulders the arm may
  reach ISO 13857's 850 mm around fence ends, over the table and over scanner fields (a scanner sees only its
  plane). The check fails if the hazard zone is within that reach. Reaching *through* a curtain is the
  curtain's own check (its C = 850 mm is exactly that allowance), so curtains close the way here.
* **Reach over the fences** (ISO 13857:2019 Table 2, high risk: ``analysis.reach_over``). Behind every panel
  the worker can stand at unseen, the hazard zone at height a must lie the table's c(a, b) behind the panel's
  top b; the check fails (``reach-over``) where it does not. A panel lower than 1 m is no barrier (clause
  4.2.2), one raised off the floor lets the arm under it (ISO 13857's tables for reaching under, Tables 6 and
  7, are for the lower limbs and not in ``core.iso13857``), and one that does not meet Table 2 lets it over:
  these three count as open in the undetected reach.
* **Ways in** (issue 34): openings in the perimeter the whole body passes unseen (ISO 13857's 180 / 240 mm,
  ``analysis.openings``); reaching over a light curtain (ISO 13855 C_RO), crawling under or stepping over it, a
  scanner's mounting height against its resolution, a mat's depth (``analysis.espe_rules``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy import ndimage

from cellstress.analysis.check_text import check_lines
from cellstress.analysis.espe_rules import curtain_reach_over, device_rules, entry_covers, failure_name
from cellstress.analysis.floor_fill import GRID, detection_margin, floor_fill
from cellstress.analysis.hazard_zone import Closest, HazardZone, closest_on_zone, hazard_zone, segment_to_zone
from cellstress.analysis.muting import muting_checks
from cellstress.analysis.openings import perimeter_openings
from cellstress.analysis.plane import (
    closest_reach,
    detour_nodes,
    distance_to_polyline,
    extended_walls,
    node_values,
    open_intervals,
    point_segment,
    points_in_polygon,
    rasterise_zone,
)
from cellstress.analysis.reach_over import HazardVolume, ReachOver, hazard_volume, panels_at, reach_over
from cellstress.analysis.stopping import speed_checks
from cellstress.analysis.worker_reach import worker_limit
from cellstress.cell.load import Cell, load_cell
from cellstress.core.iso13857 import NO_BARRIER_BELOW_MM
from cellstress.core.records import DoorLeaf, ScanPlane, VerticalField
from cellstress.devices.base import DeviceRecord, stops_robot
from cellstress.devices.light_curtain import LightCurtain
from cellstress.robot.stopping import RobotStop
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.build import build_layout

ARM_ALLOWANCE = 0.85  # m, ISO 13857 reach of the arm up to the armpit (also ISO 13855's C for body detection)
LOW_FENCE = NO_BARRIER_BELOW_MM / 1000.0  # m, ISO 13857 4.2.2: a structure lower than this is no barrier


# ---- records ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DeviceCheck:
    """ISO 13855 distance of one protective device."""

    device: str
    type: str  # the device kind (``Device.type``)
    response_time: float  # s
    stopping_time: float  # s
    T: float  # s, response + stopping
    K: float  # mm/s
    C: float  # mm
    required: float  # m, S
    actual: float  # m, horizontal distance from the detection zone's entry to the hazard zone (inf: no entry)
    ok: bool
    formula: str
    where: Closest | None  # None when the device has no entry (actual = inf)
    entries: tuple[tuple[tuple[float, float], tuple[float, float], float], ...] = ()  # (p0, p1, distance)
    # the same distance to the part of the zone the robot sweeps during one episode (t <= episode length
    # from the cell's phase): what a search can actually meet; for information, ISO uses the whole cycle
    episode_actual: float = math.inf
    field_edges: bool = False  # the entries are the open edges of a scan plane's field (listed one by one)
    robot: str = ""  # in a cell of several robots: the robot whose stopping time and hazard zone this row uses
    note: str = ""  # a further line of the device kind's own (a guard door: its access time, ISO 14119)


@dataclass(frozen=True)
class FencePanel:
    """One straight panel of a fence: ISO 13857 Table 2 behind it, and whether it closes the way."""

    start: tuple[float, float]
    end: tuple[float, float]
    top: float
    bottom: float
    to_hazard: float  # m, horizontal distance to the hazard zone's floor footprint
    closed: bool  # blocks leaning and reaching in the undetected-reach check
    reason: str
    fence: int = 0  # which fence of the cell (from 1)
    panel: int = 0  # which panel of that fence (from 1)
    reach_over: ReachOver | None = None  # ISO 13857 Table 2 behind it (None: lower than 1 m, no barrier)

    @property
    def name(self) -> str:
        return f"fence {self.fence} panel {self.panel}"


@dataclass(frozen=True)
class PanelReach:
    """ISO 13857 Table 2 at a panel the worker stands at unseen, for the hazard zone on the panel's other side."""

    panel: FencePanel
    reach: ReachOver
    limit: str = ""  # a failing panel the simulated worker cannot reach over: why (analysis.worker_reach)


@dataclass(frozen=True)
class ApproachCheck:
    """Closest reach to the hazard zone without being detected (ISO 13857 style)."""

    start: tuple[float, float]
    start_detected: bool
    undetected_area: float  # m^2 of floor the worker's centre reaches undetected
    lean: float  # m, largest horizontal hip-to-shoulder distance of the body model
    arm_allowance: float  # m
    scanner_margin: float | None  # m, the centre may come this close to a scanner field undetected (None: none)
    curtain_margin: float | None  # m, ... to a light curtain (None: the cell has none)
    stand: tuple[float, float] | None  # standing point of the closest reach
    distance: float  # m, shortest arm path from an undetected shoulder position to the zone (inf: none)
    where: Closest | None
    ok: bool
    robot: str = ""  # in a cell of several robots: the robot whose hazard zone it measures to
    guards: tuple[str, ...] = ()  # ... and the devices that stop that robot (the others do not count)
    panels_at: tuple[PanelReach, ...] = ()  # panels of 1 m or more the worker stands at unseen: ISO 13857 Table 2
    limit: str = ""  # short only over panels the simulated worker cannot reach over: what it cannot do

    @property
    def reach_over_fails(self) -> tuple[PanelReach, ...]:
        """The panels the worker stands at unseen whose top the hazard zone is too close behind (Table 2)."""
        return tuple(p for p in self.panels_at if not p.reach.ok)


@dataclass(frozen=True)
class StaticCheck:
    cell: str
    zone: HazardZone = field(repr=False)
    devices: tuple[DeviceCheck, ...]
    approach: ApproachCheck
    fences: tuple[FencePanel, ...]
    shoulder_height: float  # m, upright (the highest a shoulder gets)
    arm_length: float  # m, the body model's arm (upper arm + forearm + hand)
    episode: float  # s, length of one search episode
    phase_fixed: bool = True  # the worker arrives at the cell's own phase (human.arrival: fixed)
    restarts: tuple = ()  # RestartCheck of every device with an automatic restart
    robot_approaches: tuple[ApproachCheck, ...] = ()  # several robots: the undetected reach to robots 1..
    robot_cycles: tuple[tuple[str, float], ...] = ()  # several robots: each one's cycle time [s]
    mutings: tuple = ()  # analysis.muting.MutingCheck of every muted light curtain
    speeds: tuple = ()  # analysis.stopping.SpeedCheck: each configured device speed against the robot's real one
    openings: tuple = ()  # analysis.openings.Opening: every opening in the perimeter, against the whole body
    access: tuple = ()  # analysis.espe_rules records: getting over, under or across the devices (ISO 13855)

    @property
    def ok(self) -> bool:
        return not self.failures()

    def failures(self) -> list[str]:
        """Names of the failed checks: device names, 'undetected-reach', 'reach-over' (ISO 13857 Table 2),
        'DEVICE-restart', 'DEVICE-muting', 'DEVICE-speed' (a configured speed below the robot's real one; in a
        cell of several robots, with ':ROBOT' after a device's or the reach checks' names), 'whole-body-opening'
        (an opening in the perimeter the body passes unseen), 'DEVICE-reach-over' (over a curtain's top, with
        ':ROBOT' in a cell of several), 'DEVICE-crawl-under', 'DEVICE-step-over', 'DEVICE-mounting' (a scanner
        lower than its resolution allows), 'DEVICE-depth' (a mat that can be stepped across)."""
        out = [d.device + (f":{d.robot}" if d.robot else "") for d in self.devices if not d.ok]
        for a in (self.approach, *self.robot_approaches):
            if not a.ok:
                out.append("undetected-reach" + (f":{a.robot}" if a.robot else ""))
            if a.reach_over_fails:
                out.append("reach-over" + (f":{a.robot}" if a.robot else ""))
        out += [f"{r.device}-restart" for r in self.restarts if not r.ok]
        out += [f"{m.device}-muting" for m in self.mutings if not m.ok]
        out += [f"{s.device}-speed" for s in self.speeds if not s.ok]
        if any(not o.ok for o in self.openings):
            out.append("whole-body-opening")
        out += [name for rule in self.access for name in failure_name(rule)]
        return out

    def lines(self) -> list[str]:
        return check_lines(self)


# ---- the cell's parts -------------------------------------------------------------------------------------


def lean_reach(layout) -> float:
    """Largest horizontal distance from the hip centre to a shoulder joint over all trunk postures."""
    P = layout.params
    W = K.make_work(P)
    hs = layout.cell.spec.human
    fwd = np.deg2rad(np.linspace(0.0, hs.max_forward_flexion_deg, 12))
    lat = np.deg2rad(np.linspace(-hs.max_lateral_flexion_deg, hs.max_lateral_flexion_deg, 15))
    best = 0.0
    for f in fwd:
        for lt in lat:
            K.human_pose(P, L.pose_vector(0.0, 0.0, 0.0, float(f), float(lt)), W)
            best = max(best, float(np.hypot(W.sh[:, 0], W.sh[:, 1]).max()))
    return best


# ---- the checks -------------------------------------------------------------------------------------------
def episode_length(spec) -> float:
    sim = spec.simulation
    return sim.dt * sim.steps_per_action * sim.actions_per_episode


def _device_checks(spec, zone: HazardZone, robot_stop: RobotStop, robot: str = "") -> tuple[DeviceCheck, ...]:
    """Every device's ISO 13855 row, for the robot that stops as ``robot_stop`` says (the simulator's own delay and
    braking: T = response + delay + braking); with ``robot`` (a cell of several robots), for that robot: its
    hazard zone (``zone``), and ``spec.devices`` the devices that stop it."""
    stop = robot_stop.to_standstill
    delay, braking = robot_stop.delay, robot_stop.braking
    t_ep = episode_length(spec)
    covers = entry_covers(spec)
    out = []
    for d in spec.devices:
        iso = d.stop_distance(delay, braking) if isinstance(d, DeviceRecord) else d.required_distance(stop)
        entries, actual, where, ep = _entries_to_zone(d.primitives(), covers, zone, t_ep)
        required = iso.S / 1000.0
        note = ""
        if isinstance(d, DeviceRecord):  # a device kind's own part (a guard door, speed and separation)
            actual, note = d.stop_check(actual, delay, braking)
        out.append(DeviceCheck(d.name, d.type, d.response_time, stop, iso.T, iso.K, iso.C, required,
                               actual, bool(actual >= required - 1e-9), iso.formula, where,
                               tuple(entries), ep, any(isinstance(p, ScanPlane) for p in d.primitives()), robot,
                               note))
        warn = d.warning_stop_distance(delay, braking) if isinstance(d, DeviceRecord) else None
        if warn is not None:  # the warning field: measured like a field, against its own distance
            out.append(_warning_check(d, warn, stop, covers, zone, t_ep))
    return tuple(out)


def _warning_check(d, iso, stop: float, covers, zone: HazardZone, t_ep: float) -> DeviceCheck:
    chans = [c for c in d.channels() if c.speed > 0.0]
    entries, actual, where, ep = _entries_to_zone([c.primitive for c in chans], covers, zone, t_ep)
    required = iso.S / 1000.0
    return DeviceCheck(chans[0].name, f"{d.type} warning field", d.response_time, stop, iso.T, iso.K, iso.C,
                       required, actual, bool(actual >= required - 1e-9), iso.formula, where, tuple(entries), ep,
                       True)


def _entries_to_zone(prims, covers, zone: HazardZone, t_ep: float):
    """(every entry segment of the primitives with its distance to the zone, the least distance, where it is,
    the least distance to the part of the zone swept during one episode)."""
    entries, best, ep = [], (math.inf, None), math.inf
    for prim in prims:
        for q0, q1 in _entry_segments(prim, covers):
            dist, p, hp, k = segment_to_zone(q0, q1, zone)
            entries.append((q0, q1, dist))
            if dist < best[0]:
                best = (dist, closest_on_zone(zone, p, hp, k))
            ep = min(ep, segment_to_zone(q0, q1, zone, t_ep)[0])
    return entries, best[0], best[1], ep


def _entry_segments(prim, covers) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Where a worker enters a detection primitive, in plan view: a scan plane's polygon edges that no fence,
    table or floor edge covers; a vertical field's line."""
    if isinstance(prim, ScanPlane):
        poly = prim.polygon
        return [seg for i in range(len(poly)) for seg in open_intervals(poly[i], poly[(i + 1) % len(poly)], covers)]
    if isinstance(prim, VerticalField | DoorLeaf):  # (a door: its opening)
        return [(tuple(prim.start), tuple(prim.end))]
    raise TypeError(f"unknown detection primitive {type(prim).__name__}")


def _fence_panels(spec, zone: HazardZone, vol: HazardVolume) -> tuple[FencePanel, ...]:
    out = []
    for i, f in enumerate(spec.fences, 1):
        for j, (a, b) in enumerate(zip(f.points, f.points[1:], strict=False), 1):
            dist = segment_to_zone(a, b, zone)[0]
            ro = reach_over(a, b, f.top, vol) if f.top >= LOW_FENCE else None
            if ro is None:
                closed, why = False, f"top {f.top:.2f} m < {LOW_FENCE:.1f} m (ISO 13857 4.2.2: no barrier)"
            elif f.bottom > 0.0:
                closed, why = False, f"raised {f.bottom:.2f} m off the floor: the arm may pass under"
            elif not ro.ok:
                closed, why = False, (f"the hazard zone at {ro.hazard_height:.2f} m is {ro.behind:.3f} m behind its "
                                      f"{f.top:.2f} m top, ISO 13857 Table 2 requires {ro.required:.3f} m: "
                                      "the arm may reach over")
            else:
                closed, why = True, "ISO 13857 Table 2 met"
            out.append(FencePanel(tuple(a), tuple(b), f.top, f.bottom, dist, closed, why, i, j, ro))
    return tuple(out)


def _approach_check(spec, layout, zone: HazardZone, vol: HazardVolume, panels, lean: float, allowance: float,
                    behind=None) -> ApproachCheck:
    """The undetected reach from the start point; with ``behind`` (a device's detection primitive), from every
    floor region next to that zone instead: where a worker who crossed it stands once it no longer sees them
    (what an automatic restart lets the robot meet)."""
    body = layout.params.body
    radius = float(body[L.B_BODY_RADIUS])
    fl = spec.floor
    h = GRID
    ff = floor_fill(spec, body)
    X, Y, xs, ys, labels, U, detected = ff.X, ff.Y, ff.xs, ff.ys, ff.labels, ff.U, ff.detected
    ok, m_scan, m_curtain, curtains = ff.ok, ff.m_scan, ff.m_curtain, list(ff.curtains)
    ny, nx = ok.shape
    sx, sy = spec.human.start.xy
    if behind is not None:  # every region that touches the zone's margin (plus two grid cells): either side
        if isinstance(behind, ScanPlane):
            reach = detection_margin(body, behind.height, behind.height) + 2 * h
            touch = points_in_polygon(X, Y, behind.polygon) | (distance_to_polyline(X, Y, behind.polygon, True)
                                                                <= reach)
        else:
            reach = detection_margin(body, behind.bottom, behind.top) + 2 * h
            touch = point_segment(X, Y, behind.start[0], behind.start[1], behind.end[0], behind.end[1])[0] <= reach
        ids = np.unique(labels[touch & ok])
        U = np.isin(labels, ids[ids > 0])
        detected = not U.any()

    walls = [(p.start, p.end) for p in panels if p.closed] + curtains
    arm_walls = extended_walls(walls)
    nodes = detour_nodes(walls)
    g, gi = node_values(nodes, zone.a, zone.b, zone.r, arm_walls)
    R = int(math.ceil(lean / h)) + 1
    offs = [(dy, dx) for dy in range(-R, R + 1) for dx in range(-R, R + 1) if math.hypot(dy, dx) * h <= lean]
    offs = np.asarray(sorted(offs, key=lambda o: (o[0] ** 2 + o[1] ** 2, o)), dtype=np.int64).reshape(-1, 2)
    # a lower bound of every cell's distance to the zone: cells within h/sqrt2 of it are occupied, so the zone
    # point nearest p lies within h/sqrt2 of an occupied cell's centre
    grow = h / math.sqrt(2.0)
    occ = rasterise_zone(zone.a, zone.b, zone.r, fl.xmin, fl.ymin, h, ny, nx, grow)
    E = np.maximum(ndimage.distance_transform_edt(~occ, sampling=h) - grow, 0.0).ravel() if occ.any() \
        else np.full(ny * nx, 0.0)
    best, bi, bp, bc = closest_reach(U, fl.xmin, fl.ymin, h, E, offs, arm_walls, zone.a, zone.b, zone.r,
                                      arm_walls, nodes, g, gi)
    where, stand = None, None
    if bp >= 0 and math.isfinite(best):
        px, py = xs[bp % nx], ys[bp // nx]
        stand = (round(float(xs[bc % nx]), 4), round(float(ys[bc // nx]), 4))
        k = int(bi)
        # the zone point: nearest boundary point of stadium k (exact when the line is clear, else indicative)
        hp = point_segment(px, py, zone.a[k, 0], zone.a[k, 1], zone.b[k, 0], zone.b[k, 1])
        dd = float(hp[0])
        f = (dd - zone.r[k]) / dd if dd > 0 else 0.0
        hx, hy = px + (float(hp[1]) - px) * f, py + (float(hp[2]) - py) * f
        where = closest_on_zone(zone, (px, py), (hx, hy), k)
    limit = _over_panels_limit(spec, layout, panels, vol, curtains, (U, fl, h, E, offs, zone), allowance) \
        if best < allowance - 1e-9 else ""
    # the panels the worker stands at unseen: a walk-blocking panel keeps the centre a body radius away
    barriers = [p for p in panels if p.reach_over is not None]
    at = panels_at(X[U], Y[U], [(p.start, p.end) for p in barriers], radius + h)
    return ApproachCheck((float(sx), float(sy)), bool(detected), float(U.sum() * h * h), lean, allowance,
                         m_scan, m_curtain, stand, float(best), where, bool(best >= allowance - 1e-9),
                         panels_at=tuple(_panel_reach(spec, layout, barriers[i], vol, side) for i, side in at),
                         limit=limit)


def _over_panels_limit(spec, layout, panels, vol, curtains, grid, allowance: float) -> str:
    """The undetected reach fell short over panels that ISO 13857 Table 2 fails (open to any person): with those
    the simulated worker cannot reach over (``worker_reach``) closed, is it met? Then that is the row's limit."""
    U, fl, h, E, offs, zone = grid
    shut = [p for p in panels if not p.closed and p.bottom <= 0.0 and p.reach_over is not None
            and not p.reach_over.ok and worker_limit(spec.human, layout.params, p.start, p.end, p.top, vol, 0)]
    if not shut:
        return ""
    walls = [(p.start, p.end) for p in panels if p.closed or p in shut] + curtains
    arm_walls = extended_walls(walls)
    nodes = detour_nodes(walls)
    g, gi = node_values(nodes, zone.a, zone.b, zone.r, arm_walls)
    best = closest_reach(U, fl.xmin, fl.ymin, h, E, offs, arm_walls, zone.a, zone.b, zone.r, arm_walls, nodes, g,
                         gi)[0]
    if best < allowance - 1e-9:
        return ""
    rest = "no arm path gets there" if math.isinf(best) else f"its shortest arm path is {best:.3f} m"
    return (f"the arm comes that close only over {', '.join(p.name for p in shut)}, which the simulated worker cannot "
            f"reach over (the reach-over row says why); kept out of them, {rest}")


def _panel_reach(spec, layout, panel: FencePanel, vol: HazardVolume, side: int) -> PanelReach:
    """Table 2 at a panel the worker stands at, and, where it fails, whether the simulated worker can reach over."""
    ro = reach_over(panel.start, panel.end, panel.top, vol, side)
    limit = "" if ro.ok else worker_limit(spec.human, layout.params, panel.start, panel.end, panel.top, vol, side)
    return PanelReach(panel, ro, limit)


@dataclass(frozen=True)
class RestartCheck:
    """A device that restarts the robot by itself: where can a worker who crossed its zone stand, unseen, and
    how far is the hazard zone from there (IEC 62046 / ISO 13849: automatic restart only where nobody can stay
    undetected between the device and the hazard)."""

    device: str
    clear_time: float  # s
    behind: ApproachCheck  # the undetected reach from the regions next to its zone

    @property
    def ok(self) -> bool:
        return self.behind.ok and not self.behind.reach_over_fails


def _restart_checks(spec, layout, zone: HazardZone, vol: HazardVolume, panels, lean: float
                    ) -> tuple[RestartCheck, ...]:
    out = []
    for d in spec.devices:
        if not isinstance(d, DeviceRecord) or d.restart == "manual":
            continue
        for prim in d.primitives():
            out.append(RestartCheck(d.name, d.clear_time,
                                    _approach_check(spec, layout, zone, vol, panels, lean, ARM_ALLOWANCE, prim)))
    return tuple(out)


def check_cell(cell: Cell | str | Path, layout=None) -> StaticCheck:
    """Run every static check; ``layout`` (a sim.build.Layout of the same cell) saves rebuilding the robot."""
    if layout is None:
        if not isinstance(cell, Cell):
            cell = load_cell(cell)
        layout = build_layout(cell)
    spec = layout.cell.spec
    body = layout.params.body
    shoulder = float(body[L.B_HIP_Z] + body[L.B_SHOULDER_RISE])
    zone, vol = hazard_zone(layout), hazard_volume(layout)
    panels = _fence_panels(spec, zone, vol)
    lean = lean_reach(layout)
    if len(spec.robots) > 1:
        devices, approaches = _per_robot(spec, layout, lean)
        approach, more = approaches[0], approaches[1:]
    else:
        devices = _device_checks(spec, zone, layout.robots[0].stop)
        approach, more = _approach_check(spec, layout, zone, vol, panels, lean, ARM_ALLOWANCE), ()
    return StaticCheck(spec.name, zone, devices, approach, panels, shoulder, float(body[L.B_ARM_LEN]),
                       episode_length(spec), spec.human.arrival == "fixed",
                       _restart_checks(spec, layout, zone, vol, panels, lean), more,
                       tuple((p.name, float(p.trajectory.cycle)) for p in layout.robots) if more else (),
                       muting_checks(spec), speed_checks(layout),
                       perimeter_openings(spec, floor_fill(spec, body), float(body[L.B_BODY_RADIUS])),
                       _access_rules(spec, layout, devices, vol))


def _access_rules(spec, layout, devices, vol: HazardVolume) -> tuple:
    """Reach over every light curtain's top (for each robot it stops, with that robot's T and hazard zone), then
    the rules of ``espe_rules.device_rules``."""
    by_name = {d.name: d for d in spec.devices}
    names = [r.name for r in spec.robots]
    vols: dict[str, HazardVolume] = {}
    out = []
    for row in devices:
        dev = by_name.get(row.device)
        if not isinstance(dev, LightCurtain) or row.type != dev.type:
            continue
        if row.robot and row.robot not in vols:
            vols[row.robot] = hazard_volume(layout, robot=names.index(row.robot))
        out.append(curtain_reach_over(dev, vols.get(row.robot, vol), row.T, row.required, row.robot,
                                      spec.human.model == "articulated"))
    return tuple(out) + device_rules(spec)


def _per_robot(spec, layout, lean: float) -> tuple[tuple[DeviceCheck, ...], list[ApproachCheck]]:
    """A cell of several robots, robot by robot: each device that stops the robot, with the robot's stopping
    time, measured to the robot's own hazard zone; and the undetected reach to that zone, where a device that
    does not stop the robot is no protection (the worker walks through it: a curtain wired to robot a only
    leaves robot b open, and this check fails for b)."""
    devices: list[DeviceCheck] = []
    approaches = []
    for r, rs in enumerate(spec.robots):
        z = hazard_zone(layout, robot=r)
        mine = tuple(d for d in spec.devices if stops_robot(d, rs.name))
        sr = spec.model_copy(update={"devices": mine})
        devices += _device_checks(sr, z, layout.robots[r].stop, rs.name)
        v = hazard_volume(layout, robot=r)
        a = _approach_check(sr, layout, z, v, _fence_panels(spec, z, v), lean, ARM_ALLOWANCE)
        approaches.append(replace(a, robot=rs.name, guards=tuple(d.name for d in mine)))
    return tuple(devices), approaches


def device_distances(cell: Cell | str | Path, layout=None) -> list[DeviceCheck]:
    """The ISO 13855 distance check of every protective device of the cell."""
    return list(check_cell(cell, layout).devices)


def static_check(cell: Cell | str | Path, layout=None) -> list[str]:
    """Lines for ``cellstress check`` to print."""
    return check_cell(cell, layout).lines()
