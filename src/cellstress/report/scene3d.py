"""The data of the 3D view: the cell's solids, panels and detection fields, and per 50 ms step the robot's and
the worker's capsules, as the simulator holds them.

Nothing here computes geometry of its own: the obstacles are ``Layout.obstacles`` (the kernel's prisms), the
fence panels, door leaves and pallets are the rows of the kernel's ``fences`` array, the detection fields are
the kernel's channel arrays (``dev_kind``, ``dev_rect``, ``dev_poly``: a ``ScanPlane`` polygon at its height, a
``VerticalField`` or ``DoorLeaf`` rectangle), the robot's capsules come from ``sim.scene.robot_capsules`` at
each step's path time, the body's from ``sim.scene.body_pose`` and the reach volume from the reach field's
nodes with the kernel's fence-detour test (``sim.scene.reach_points``). The only arithmetic here is packing:
lengths in whole millimetres, the reach volume as its nodes in the shoulder frame once plus, per step, the
shoulders, the trunk frame and which nodes the fences cut off.
"""

from __future__ import annotations

import base64
import json
import math
from dataclasses import dataclass

import numpy as np

from cellstress.report import draw as D
from cellstress.report.episode import EpisodeView
from cellstress.sim import layout as L
from cellstress.sim import scene
from cellstress.sim.build import DOOR, SCANNER, Layout

REACH_STRIDE_3D = 4  # every 4th node of the reach field per axis (8 cm): about 3,500 points per arm
MAX_PROGRAM_STEPS = 600  # `show --3d`: one cycle at the cell's dt, thinned to at most this many frames


def mm(x) -> list:
    """Metres as whole millimetres (nested lists of ints): the view's resolution, and a third of the bytes."""
    return np.rint(np.asarray(x, dtype=float) * 1000.0).astype(np.int64).tolist()


# ---- the cell ---------------------------------------------------------------------------------------------
def triangulate(poly) -> list[tuple[int, int, int]]:
    """Triangles (index triples) covering a simple polygon, convex or not, by ear clipping."""
    p = np.asarray(poly, dtype=float)
    n = len(p)
    area = 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
    idx = list(range(n)) if area >= 0 else list(range(n))[::-1]  # counter-clockwise

    def cross(o, a, b) -> float:
        return (p[a, 0] - p[o, 0]) * (p[b, 1] - p[o, 1]) - (p[a, 1] - p[o, 1]) * (p[b, 0] - p[o, 0])

    tris: list[tuple[int, int, int]] = []
    guard = 0
    while len(idx) > 3 and guard < 10 * n:
        guard += 1
        for k in range(len(idx)):
            a, b, c = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            if cross(a, b, c) <= 1e-12:
                continue  # a reflex (or straight) corner is no ear
            if any(cross(a, b, q) >= 0 and cross(b, c, q) >= 0 and cross(c, a, q) >= 0
                   for q in idx if q not in (a, b, c)):
                continue
            tris.append((a, b, c))
            del idx[k]
            break
        else:
            break  # degenerate (self-touching) polygon: fan the rest
    tris += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    return tris


def _obstacle_kind(layout: Layout, o) -> str:
    if D._is_pedestal(layout, o):
        return "pedestal"
    return "table" if D._is_table(o) else "obstacle"


def _prisms(layout: Layout) -> list[dict]:
    out = []
    for o in layout.obstacles:
        foot = [tuple(map(float, q)) for q in o.footprint()]
        out.append({"kind": _obstacle_kind(layout, o), "name": o.name, "poly": mm(foot), "tris": triangulate(foot),
                    "z": mm([0.0, float(o.height)])})
    return out


def _panels(layout: Layout) -> list[dict]:
    """The kernel's fence rows: each a vertical panel x0 y0 x1 y1 bottom top; door leaves and pallets named."""
    P = layout.params
    doors = {int(f): int(d) for f, d in zip(P.door_fence, P.door_dev, strict=True)}
    pallets = {int(f) for f in P.panel_fence}
    out = []
    for i, row in enumerate(P.fences):
        kind = "door" if i in doors else "pallet" if i in pallets else "fence"
        item = {"kind": kind, "rect": mm(row)}
        if i in doors:
            item["channel"] = doors[i]
        out.append(item)
    return out


def _channel_device(layout: Layout) -> list:
    """The device spec of each kernel channel (a device's channels are consecutive, in the devices' order)."""
    from cellstress.core.protocols import Channels

    out = []
    for d in layout.cell.spec.devices:
        n = len(d.channels()) if isinstance(d, Channels) else len(tuple(d.primitives()))
        out += [d] * n
    return out


def _fields(layout: Layout) -> list[dict]:
    """Each detection channel as the kernel holds it: a scan plane's polygon at its height, shown as the
    volume from the floor up to the plane; a vertical field's rectangle; a door's opening."""
    P = layout.params
    devs = _channel_device(layout)
    out = []
    for c, name in enumerate(layout.device_names):
        d = devs[c]
        kind = int(P.dev_kind[c])
        item = {"name": name, "device": d.name, "type": d.type, "color": getattr(d, "color", "#888888"),
                "speed": float(P.dev_speed[c])}
        if kind == SCANNER:
            start, count = (int(v) for v in P.dev_poly[c])
            poly = [tuple(map(float, q)) for q in P.dev_verts[start:start + count]]
            item.update(shape="prism", poly=mm(poly), tris=triangulate(poly), z=mm([0.0, float(P.dev_rect[c, 4])]))
        else:
            item.update(shape="door" if kind == DOOR else "rect", rect=mm(P.dev_rect[c]))
        out.append(item)
    return out


def _starts(layout: Layout) -> list[dict]:
    h = layout.cell.spec.human
    out = [{"name": "", "xy": mm(h.start.xy), "heading": round(float(h.start.heading_deg), 3)}]
    out += [{"name": s.name, "xy": mm(s.xy), "heading": round(float(s.heading_deg), 3)} for s in h.starts]
    return out


def _cell_data(layout: Layout) -> dict:
    """The parts of the cell that do not move (and the robot's capsule names and radii)."""
    fl = layout.cell.spec.floor
    return {"name": layout.cell.spec.name, "floor": mm([fl.xmin, fl.xmax, fl.ymin, fl.ymax]),
            "prisms": _prisms(layout), "panels": _panels(layout), "fields": _fields(layout),
            "starts": _starts(layout), "links": [c.name for c in layout.capsules], "link_r": mm(layout.params.cap_r),
            "robots": [{"name": r.name, "first": r.first_capsule, "n": len(r.capsules)} for r in layout.robots]}


# ---- the steps --------------------------------------------------------------------------------------------
def _bits(mask: np.ndarray) -> str:
    return base64.b64encode(np.packbits(mask.astype(np.uint8), bitorder="little").tobytes()).decode("ascii")


def reach_kept(layout: Layout, pose: scene.BodyPose, side: int, nodes: np.ndarray, stride: int) -> np.ndarray:
    """Which of ``nodes`` (``scene.reach_nodes``) ``scene.reach_points`` keeps for this pose and arm: its
    points mapped back to the grid (the shoulder frame is a rotation, so the indices come back exactly)."""
    pts = scene.reach_points(layout, pose, side, stride, nodes)
    keep = np.zeros(len(nodes), dtype=bool)
    if len(pts) == len(nodes):
        keep[:] = True
        return keep
    local = (pts - pose.shoulders[side]) @ pose.trunk
    if side == 0:
        local[:, 1] = -local[:, 1]
    h = stride * layout.reach.spacing
    key = np.rint((local - layout.reach.origin) / h).astype(np.int64)
    grid = np.rint((nodes - layout.reach.origin) / h).astype(np.int64)
    lookup = {tuple(g): i for i, g in enumerate(grid.tolist())}
    for k in key.tolist():
        keep[lookup[tuple(k)]] = True
    return keep


def _record_part(view: EpisodeView, i: int) -> dict:
    r = view.records[i]
    return {"t": round(r.t, 4), "d": None if r.d_HR is None else round(r.d_HR, 4),
            "v": None if r.v_R is None else round(r.v_R, 4), "phase": r.stop_phase, "seen": list(r.devices)}


def _episode_data(view: EpisodeView, label: str, stride: int = REACH_STRIDE_3D) -> dict:
    """Every step of a replayed episode: robot capsules, body capsules, the reach volume's kept nodes, the
    numbers of the timeline, when each channel first sees the worker, and the contact (or closest call)."""
    layout = view.layout
    n = len(view.records)
    paper = not layout.worker.articulated
    nodes = scene.reach_nodes(layout, stride) if paper else np.zeros((0, 3))
    robot, body, sh, trunk, keep, rows = [], [], [], [], [], []
    for i in range(n):
        a, b = view.robot(i)
        robot.append(mm(np.concatenate([a, b], axis=1).ravel()))
        pose = view.pose(i)
        body.append(mm(np.concatenate([pose.a, pose.b], axis=1).ravel()))
        sh.append(mm(pose.shoulders.ravel()))
        trunk.append(np.round(pose.trunk.ravel(), 5).tolist())
        if paper:
            masks = [reach_kept(layout, pose, s, nodes, stride) for s in (0, 1)]
            keep.append([None if m.all() else _bits(m) for m in masks])
        rows.append(_record_part(view, i))
    first = {}
    for i, r in enumerate(view.records):
        for name in r.devices:
            first.setdefault(name, i)
    key = view.key_row
    hit = view.records[key]
    links = [c.name for c in layout.capsules]
    parts = list(pose.names)
    marker = {"step": key, "kind": "contact" if view.unsafe else "closest",
              "rp": mm(hit.robot_point), "hp": mm(hit.human_point),
              "link": links.index(hit.robot_link) if hit.robot_link in links else -1,
              "part": parts.index(hit.body_part) if hit.body_part in parts else -1,
              "reach": {"left-reach": 0, "right-reach": 1}.get(hit.body_part, -1),
              "text": f"{hit.robot_link} / {hit.body_part}"}
    return {"label": label, "dt": view.dt, "n": n, "robot": robot, "body": body, "body_r": mm(pose.r),
            "parts": parts, "sh": sh, "trunk": trunk, "keep": keep if paper else None, "rows": rows,
            "first_seen": first, "marker": marker, "path": mm([[r.x, r.y] for r in view.records]),
            "actions": list(view.actions), "spa": view.steps_per_action}


def _program_data(layout: Layout, label: str = "robot program, one cycle") -> dict:
    """`show --3d`: the robots over one cycle of robot 0's program from the cell's phase, no worker."""
    dt = float(layout.cell.spec.simulation.dt)
    cycle = float(layout.trajectory.cycle)
    n = int(math.floor(cycle / dt + 1e-9)) + 1
    step = max(1, math.ceil(n / MAX_PROGRAM_STEPS))
    phase = float(layout.params.scal[L.C_PHASE0])
    robot, rows = [], []
    for k in range(0, n, step):
        a, b = scene.robot_capsules(layout, phase + k * dt)
        robot.append(mm(np.concatenate([a, b], axis=1).ravel()))
        rows.append({"t": round(k * dt, 4), "d": None, "v": None, "phase": "running", "seen": []})
    return {"label": label, "dt": dt * step, "n": len(robot), "robot": robot, "body": None, "body_r": [],
            "parts": [], "sh": None, "trunk": None, "keep": None, "rows": rows, "first_seen": {}, "marker": None,
            "path": [], "actions": [], "spa": 0}


def _reach_data(layout: Layout, stride: int = REACH_STRIDE_3D) -> dict | None:
    """The right arm's reach-volume nodes in its shoulder frame (the left arm's are their mirror image)."""
    if layout.worker.articulated:
        return None
    return {"nodes": mm(scene.reach_nodes(layout, stride)), "stride_m": stride * float(layout.reach.spacing)}


@dataclass(frozen=True)
class ViewData:
    """What one 3D view shows: the cell and one or more episodes (a witness list offers each)."""

    cell: dict
    reach: dict | None
    episodes: tuple[dict, ...]

    def to_json(self) -> str:
        """Canonical JSON, safe inside a ``<script type="application/json">`` element."""
        text = json.dumps({"cell": self.cell, "reach": self.reach, "episodes": list(self.episodes)},
                          sort_keys=True, separators=(",", ":"), allow_nan=False)
        return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def view_of_episodes(layout: Layout, episodes: list[tuple[EpisodeView, str]]) -> ViewData:
    return ViewData(_cell_data(layout), _reach_data(layout), tuple(_episode_data(v, label) for v, label in episodes))


def view_of_program(layout: Layout) -> ViewData:
    return ViewData(_cell_data(layout), None, (_program_data(layout),))

