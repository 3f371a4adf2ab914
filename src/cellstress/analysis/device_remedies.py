"""Candidate changes to a safeguard's settings or outline, or a new safeguard (``cellstress fix``).

Each answers one failing ``check`` row with the least change of its kind, is found with ``check`` itself where
the standard's arithmetic depends on the cell (bisection, re-measuring), and never looks at the cell's name:

* **warning-field**: a laser scanner's warning field whose ISO 13855 row fails (``DEVICE:warning``): the
  warning field's entry edge nearest the hazard moved out by the shortfall plus ``MARGIN`` (the protective
  field stays), re-measured and repeated (``ROUNDS`` at most).
* **reduced-speed**: a scanner whose protective row fails and which has a warning field: its reduced speed
  lowered to the largest multiple of ``SPEED_STEP`` at which the protective row passes (the protective
  distance grows with the reduced speed: bisected with ``check``); a warning field whose reduced speed lets
  the robot run faster than its ``speed_limit`` (``DEVICE:warning-speed``): lowered until it does not (the
  robot's real speed there scales with it), both where both rows fail. Without a warning field, a reduced-speed
  zone is added: a warning field drawn as the protective field's outline, that reduced speed, then grown as
  **warning-field** does until its own row passes (the lead the reduction needs, laser_scanner.py). None
  where even ``SPEED_STEP`` does not make the protective row pass (moving the field is then ``fix``'s move).
* **scanner-resolution**: a ``DEVICE-mounting`` row (the scan plane lower than 15 (d - 50) mm, ISO 13855
  6.3): the resolution set to the coarsest whole 10 mm that meets it at the plane's height.
* **mat-depth**: a ``DEVICE-depth`` row (a mat shallower than ISO 13855's 750 mm): the edge the shallowest
  crossing starts from moved out by the shortfall plus ``MARGIN``.
* **cover-gap**: a gap from a fence's free end that admits the body unseen: a new light curtain across it (one
  part added), as high as the fence, its lowest beam at ``CURTAIN_BOTTOM``, resolution ``CURTAIN_D_MM`` (C = 0:
  the shortest distance ISO 13855 allows a curtain), the schema's default response time, stopping every robot;
  ``check`` then judges its distance like any curtain's. The way to keep a gap open for material or people.

In the moves the worker's start points beyond the moved edge's line move with it and the floor grows to hold
what moved, as in ``remedies.apply_move``.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable

from cellstress.analysis.espe_rules import MatDepth, ScannerMounting
from cellstress.analysis.iso13855 import DeviceCheck, StaticCheck
from cellstress.analysis.remedies import (
    ROUNDS,
    Move,
    Remedy,
    cell_document,
    device_entry,
    device_move,
    dump_cell,
    move_starts_and_floor,
    past_shortfall,
    shift_point,
)
from cellstress.cell.load import Cell
from cellstress.core import iso13855 as I
from cellstress.devices.light_curtain import LightCurtain

SPEED_STEP = 0.05  # reduced speeds are tried in these steps (a fraction of the path speed)
CURTAIN_D_MM = 14.0  # a new curtain's resolution: ISO 13855's C = 8 (d - 14) is 0 there
CURTAIN_BOTTOM = 0.2  # m, a new curtain's lowest beam (ISO 13855 6.2: at most 300 mm, no crawling under)
RESOLUTION_STEP_MM = 10.0

StaticOf = Callable[[str], StaticCheck | None]


def _row(static: StaticCheck | None, name: str) -> DeviceCheck | None:
    return None if static is None else next((d for d in static.devices if d.device == name), None)


def _scanner(doc: dict, name: str) -> dict | None:
    dev = device_entry(doc, name)
    return dev if dev is not None and dev.get("type") == "laser-scanner" and isinstance(dev.get("polygon"), list) \
        else None


# ---- warning fields and reduced speed -----------------------------------------------------------------------
def _grow_warning(doc: dict, name: str, static_of: StaticOf) -> tuple[float, bool]:
    """Move the warning field of scanner ``name`` in ``doc`` out (in place) until its row passes; (metres moved
    in all, whether it passes)."""
    total = 0.0
    for _ in range(ROUNDS):
        row = _row(static_of(dump_cell(doc)), f"{name}:warning")
        if row is None:
            return total, False
        if row.ok:
            return total, True
        m = device_move(row)
        dev = _scanner(doc, name)
        if m is None or dev is None or not isinstance(dev.get("warning"), dict):
            return total, False
        dev["warning"]["polygon"] = [shift_point(p, m) for p in dev["warning"]["polygon"]]
        move_starts_and_floor(doc, m)
        total += m.delta
    row = _row(static_of(dump_cell(doc)), f"{name}:warning")
    return total, row is not None and row.ok


def enlarged_warnings(cell: Cell, static: StaticCheck, static_of: StaticOf) -> list[Remedy]:
    """For each scanner whose warning row fails: its warning field grown until that row passes."""
    base = cell_document(cell)
    out = []
    for d in static.devices:
        name = d.device.removesuffix(":warning")
        if d.ok or name == d.device or _scanner(base, name) is None:
            continue
        doc = copy.deepcopy(base)
        moved, ok = _grow_warning(doc, name, static_of)
        if moved > 0.0 and ok:
            out.append(Remedy("warning-field", f"enlarge {name}'s warning field {moved:.2f} m outward at its entry "
                              "nearest the hazard (the protective field as it is)", (d.device,), 0, dump_cell(doc)))
    return out


def _largest_speed(doc: dict, name: str, top_step: int, static_of: StaticOf) -> float | None:
    """The largest multiple of SPEED_STEP, at most ``top_step`` of them, at which scanner ``name``'s protective
    row passes (bisected: the protective distance grows with the reduced speed), None where even SPEED_STEP
    fails."""

    def passes(k: int) -> bool:
        trial = copy.deepcopy(doc)
        _scanner(trial, name)["warning"]["reduced_speed"] = round(k * SPEED_STEP, 6)
        row = _row(static_of(dump_cell(trial)), name)
        return row is not None and row.ok

    lo, hi = 1, top_step
    if hi < 1 or not passes(1):
        return None
    while lo < hi:
        mid = (lo + hi + 1) // 2
        lo, hi = (mid, hi) if passes(mid) else (lo, mid - 1)
    return round(lo * SPEED_STEP, 6)


def reduced_speeds(cell: Cell, static: StaticCheck, static_of: StaticOf) -> list[Remedy]:
    """For each scanner whose protective row fails, or whose warning field lets the robot run faster than its
    ``speed_limit`` (the ``DEVICE:warning-speed`` row): a lower reduced speed in its warning field, or a
    warning field (a reduced-speed zone) where it has none (module docstring)."""
    base = cell_document(cell)
    short = {d.device for d in static.devices if not d.ok}
    too_fast = {s.device.removesuffix(":warning"): s for s in static.speeds if not s.ok}
    out = []
    for dev in [d for d in (base.get("devices") or ()) if isinstance(d, dict)]:
        name = dev.get("name")
        if _scanner(base, name) is None or (name not in short and name not in too_fast):
            continue
        doc = copy.deepcopy(base)
        scanner = _scanner(doc, name)
        had = isinstance(scanner.get("warning"), dict)
        if not had:
            scanner["warning"] = {"polygon": copy.deepcopy(scanner["polygon"]), "reduced_speed": 1.0 - SPEED_STEP}
        before = float(scanner["warning"].get("reduced_speed", 0.25)) if had else 1.0
        top_step = math.ceil(before / SPEED_STEP - 1e-9) - 1  # the largest step strictly below
        rows = []
        if name in too_fast:  # the robot's real speed scales with the reduced speed
            s = too_fast[name]
            top_step = min(top_step, math.floor(before * s.configured / s.real / SPEED_STEP + 1e-9))
            rows.append(f"{s.device}-speed")
        if name in short:
            rows.insert(0, name)
            r = _largest_speed(doc, name, top_step, static_of)
        else:
            r = round(top_step * SPEED_STEP, 6) if top_step >= 1 else None
        if r is None:
            continue
        scanner["warning"]["reduced_speed"] = r
        moved, ok = _grow_warning(doc, name, static_of)
        if not ok:
            continue
        if had:
            words = f"cut the robot to {r:g} of its speed in {name}'s warning field (was {before:g})"
            words += f", the warning field {moved:.2f} m larger" if moved > 0.0 else ""
        else:
            words = (f"add a reduced-speed zone to {name}: a warning field {moved:.2f} m beyond the protective "
                     f"field that cuts the robot to {r:g} of its speed")
        out.append(Remedy("reduced-speed", words, tuple(rows), 0, dump_cell(doc)))
    return out


# ---- a scanner's resolution, a mat's depth ------------------------------------------------------------------
def finer_resolutions(cell: Cell, static: StaticCheck) -> list[Remedy]:
    """For each scanner whose plane is too low for its resolution: the coarsest whole 10 mm that fits."""
    base = cell_document(cell)
    out = []
    for rule in static.access:
        if not isinstance(rule, ScannerMounting) or rule.resolution_ok:
            continue
        d_mm = math.floor((rule.height * 1000.0 / 15.0 + I.NO_MIN_HEIGHT_UP_TO_D_MM) / RESOLUTION_STEP_MM + 1e-9) \
            * RESOLUTION_STEP_MM
        while d_mm > 0.0 and I.min_scan_height_mm(d_mm) > rule.height * 1000.0 + 1e-6:
            d_mm -= RESOLUTION_STEP_MM
        doc = copy.deepcopy(base)
        dev = _scanner(doc, rule.device)
        if dev is None or d_mm < RESOLUTION_STEP_MM or d_mm >= rule.resolution:
            continue
        dev["resolution_mm"] = d_mm
        out.append(Remedy("scanner-resolution", f"set {rule.device}'s resolution from {rule.resolution:g} to "
                          f"{d_mm:g} mm (ISO 13855 6.3: a plane at {rule.height * 1000:.0f} mm needs d <= "
                          f"H/15 + 50 mm)", (f"{rule.device}-mounting",), 0, dump_cell(doc)))
    return out


def deeper_mats(cell: Cell, static: StaticCheck) -> list[Remedy]:
    """For each mat shallower than ISO 13855's minimum: the edge its shallowest crossing starts from moved out."""
    base = cell_document(cell)
    out = []
    for rule in static.access:
        if not isinstance(rule, MatDepth) or rule.ok or rule.where is None:
            continue
        (px, py), (qx, qy) = rule.where
        length = math.hypot(px - qx, py - qy)
        doc = copy.deepcopy(base)
        dev = device_entry(doc, rule.device)
        if length < 1e-9 or dev is None or not isinstance(dev.get("polygon"), list):
            continue
        n = (round((px - qx) / length, 12) + 0.0, round((py - qy) / length, 12) + 0.0)
        delta = past_shortfall(I.MAT_MIN_DEPTH_MM / 1000.0 - rule.depth)
        m = Move(rule.device, ((px, py), (px, py)), n, n[0] * px + n[1] * py, delta)
        dev["polygon"] = [shift_point(p, m) for p in dev["polygon"]]
        move_starts_and_floor(doc, m)
        out.append(Remedy("mat-depth", f"deepen {rule.device} from {rule.depth * 1000:.0f} mm: its edge at "
                          f"({px:.2f}, {py:.2f}) {delta:.2f} m outward (ISO 13855: at least "
                          f"{I.MAT_MIN_DEPTH_MM:.0f} mm)", (f"{rule.device}-depth",), 0, dump_cell(doc)))
    return out


# ---- a new curtain across a gap -----------------------------------------------------------------------------
def covered_gaps(cell: Cell, static: StaticCheck) -> list[Remedy]:
    """For each gap from a fence's free end that admits the body unseen: a light curtain across it."""
    base = cell_document(cell)
    names = {d.name for d in cell.spec.devices}
    out = []
    for o in static.openings:
        if o.kind != "gap" or o.ok or o.fence < 0 or o.fence >= len(cell.spec.fences):
            continue
        k = 1
        while f"gap-curtain-{k}" in names:
            k += 1
        name = f"gap-curtain-{k}"
        names.add(name)
        top = max(float(cell.spec.fences[o.fence].top), CURTAIN_BOTTOM + 0.1)
        doc = copy.deepcopy(base)
        doc.setdefault("devices", []).append({
            "name": name, "type": "light-curtain", "start": [float(v) for v in o.start],
            "end": [float(v) for v in o.end], "bottom": CURTAIN_BOTTOM, "top": top,
            "resolution_mm": CURTAIN_D_MM, "response_time": LightCurtain.model_fields["response_time"].default})
        (x0, y0), (x1, y1) = o.start, o.end
        out.append(Remedy("cover-gap", f"cover the {o.where} with a light curtain {name} ({x0:g}, {y0:g})-"
                          f"({x1:g}, {y1:g}), beams {CURTAIN_BOTTOM:g}-{top:g} m, {CURTAIN_D_MM:g} mm",
                          ("whole-body-opening",), 1, dump_cell(doc)))
    return out
