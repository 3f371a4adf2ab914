"""Candidate changes to a cell (``cellstress fix``): each a whole cell file's text, derived from ``check``'s rows.

Every remedy edits the cell file's own YAML mapping (the user's fields as written, defaults left out) and never
looks at the cell's name: the built-in flawed cells and their fixed twins are the tests, not special cases.

* **move**: a device whose ISO 13855 distance falls short (``DeviceCheck.actual < required``) gets the entry
  edge nearest the hazard zone moved straight away from it by the shortfall plus ``MARGIN``, rounded up to the
  centimetre. Two variants: ``device`` moves only the device's own points on or beyond that edge's line;
  ``cell`` stretches the whole cell beyond that line (fence points and every device's points), so walls that
  ended at the old edge follow it and the cell stays closed; in both the worker's start points beyond the line
  move with it and the floor grows by the move (a start inside the moved field would test nothing). The
  check decides which works; ``fix`` keeps both when both do and ranks them by cost.
* **settings** named by a failing row: ``guard_locking: true`` on a guard door whose ISO 13855 row fails,
  ``restart: manual`` for a ``DEVICE-restart`` row, the muting's ``until`` set to the pallet's end for a
  ``DEVICE-muting`` row, a speed and separation controller's configured times set to the real ones its row
  names as underestimated and its configured top speed to the robot's real one (``DEVICE-speed``), and a
  device wired to a robot whose ``undetected-reach:ROBOT`` row fails.
* **slow-per-move**: the program's speed scales, one per move (``with_scales``; ``analysis.safe_speed`` finds them).
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path

import yaml

from cellstress.analysis.espe_rules import CurtainReachOver
from cellstress.analysis.iso13855 import DeviceCheck, StaticCheck
from cellstress.cell.files import confined
from cellstress.cell.load import Cell, builtin_text, parse_cell, safe_load_yaml
from cellstress.core.io import atomic_write_text, read_input_bytes

MARGIN = 0.05  # m added to an ISO 13855 shortfall: the check's own distances are rounded to the mm
ON_LINE = 1e-6  # m: a point this close to the moved edge's line counts as on it
ROUNDS = 4  # a move is re-measured and repeated at most this often (an oblique edge gains less than it moves)


@dataclass(frozen=True)
class Remedy:
    """One candidate change: what it is (in words), which check rows it answers, and the whole changed cell."""

    kind: str  # 'move-device', 'move-cell', 'guard-locking', 'manual-restart', 'muting-end', 'ssm-times', 'ssm-speed',
    # 'wire', 'slow-per-move', analysis.way_remedies' 'lower-panel', 'close-gap', 'raise-top', 'raise-fence',
    # 'device-height', and analysis.device_remedies' 'warning-field', 'reduced-speed', 'scanner-resolution',
    # 'mat-depth', 'cover-gap'
    change: str  # e.g. "move front-mat's edge (-1.5, 2.3)-(1.5, 2.3) 0.47 m outward (+y)"
    rows: tuple[str, ...]  # the failing check rows (or 'hazard') it answers
    parts_added: int  # new devices or fences ('close-gap' and 'cover-gap' add one; the others none)
    text: str  # the changed cell file (YAML)


# ---- the cell file as data --------------------------------------------------------------------------------
def cell_document(cell: Cell) -> dict:
    """The cell file's YAML mapping as written (built-in or file), with every file it reads made absolute, so a
    changed copy written elsewhere reads the same robot, trajectory and stopping data, and with the criterion
    ``cell`` is judged by. With ``CELLSTRESS_FILES=inside`` the names stay as written: a copy may read only
    files in the original's folder, so it is read as if it lay there (``parse_candidate``)."""
    if cell.directory is None:
        text = builtin_text(cell.source)
    else:
        text = read_input_bytes(Path(cell.source).expanduser()).decode("utf-8")
    doc = safe_load_yaml(text)
    # the criterion the cell is judged by here (``--criterion`` may differ from the file's), written out whole
    doc["criterion"] = cell.spec.criterion.model_dump(mode="json")
    base = None if confined() else cell.files_dir
    for robot in _robots(doc):
        _absolute(robot, "urdf", base)
        _absolute(robot.get("task") or {}, "trajectory_csv", base)
        _absolute(robot.get("stopping") or {}, "data", base)
    return doc


def _absolute(where: dict, key: str, base: Path | None) -> None:
    value = where.get(key) if isinstance(where, dict) else None
    if isinstance(value, str) and base is not None and not os.path.isabs(value):
        path = base / value
        if path.is_file():  # a URDF may also be a short name ('ur5'), which is no file
            where[key] = os.path.realpath(path)


def parse_candidate(cell: Cell, text: str, path: Path) -> Cell:
    """A changed copy of ``cell`` written to ``path`` and read back as any cell file is: its relative file names
    resolve beside it, or, with ``CELLSTRESS_FILES=inside``, beside the original (whose folder the copy's
    files must lie in; the copy is to be put there to be used)."""
    atomic_write_text(path, text)
    home = cell.files_dir if confined() and cell.directory is not None else path.resolve().parent
    return parse_cell(text, str(path), home)


def _robots(doc: dict) -> list[dict]:
    out = [doc["robot"]] if isinstance(doc.get("robot"), dict) else []
    return out + [r for r in doc.get("robots") or () if isinstance(r, dict)]


def dump_cell(doc: dict) -> str:
    return yaml.safe_dump(doc, sort_keys=False, allow_unicode=True, width=120, default_flow_style=None)


def _devices(doc: dict) -> list[dict]:
    return [d for d in doc.get("devices") or () if isinstance(d, dict)]


def device_entry(doc: dict, name: str) -> dict | None:
    return next((d for d in _devices(doc) if d.get("name") == name), None)


# ---- moving an edge -----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Move:
    """An edge's line moved along its outward normal: points p with n.p >= line move by delta * n."""

    device: str  # the device's name, or 'fence F panel P' (only ever moved with the cell)
    edge: tuple[tuple[float, float], tuple[float, float]]
    normal: tuple[float, float]
    line: float
    delta: float


def cm_up(x: float) -> float:
    """``x`` [m] rounded up to the centimetre (a hair below a whole centimetre stays there)."""
    return math.ceil(x * 100.0 - 1e-9) / 100.0


def past_shortfall(shortfall: float) -> float:
    """How far to move an edge short of a required distance by ``shortfall`` [m]: plus ``MARGIN``, cm up."""
    return cm_up(shortfall + MARGIN)


def device_move(d: DeviceCheck) -> Move | None:
    """How far and where to move device ``d``'s nearest entry so that its distance meets ISO 13855."""
    if d.ok or d.where is None or not math.isfinite(d.actual):
        return None
    edge = _nearest_entry(d)
    if edge is None:
        return None
    (x0, y0), (x1, y1) = edge
    length = math.hypot(x1 - x0, y1 - y0)
    if length < 1e-9:
        return None
    n = (-(y1 - y0) / length, (x1 - x0) / length)
    hx, hy = d.where.hazard_point
    if n[0] * ((x0 + x1) / 2 - hx) + n[1] * ((y0 + y1) / 2 - hy) < 0:
        n = (-n[0], -n[1])
    n = (round(n[0], 12) + 0.0, round(n[1], 12) + 0.0)
    delta = past_shortfall(d.required - d.actual)
    return Move(d.device, edge, n, n[0] * x0 + n[1] * y0, delta)


def reach_over_move(r: CurtainReachOver, d: DeviceCheck) -> Move | None:
    """How far to move a light curtain (``d``: its own ISO 13855 row, for the edge and the hazard's side) whose
    top can be reached over, so that the zone lies S_RO (``r.required``, ISO 13855 Table 1) behind its line."""
    if r.ok or r.device != d.device or not (math.isfinite(r.required) and math.isfinite(r.behind)):
        return None
    m = device_move(replace(d, ok=False, actual=0.0, required=0.0))  # the edge and its outward normal only
    if m is None:
        return None
    return replace(m, delta=past_shortfall(r.required - r.behind))


def panel_move(pr) -> Move | None:
    """How far to move a fence panel that fails ISO 13857 Table 2 (an ``ApproachCheck.reach_over_fails`` item)
    towards the worker's side so that the hazard zone lies Table 2's c behind its top (plus ``MARGIN``)."""
    reach, panel = pr.reach, pr.panel
    if reach.ok or not reach.side or not (math.isfinite(reach.required) and math.isfinite(reach.behind)):
        return None
    (x0, y0), (x1, y1) = panel.start, panel.end
    length = math.hypot(x1 - x0, y1 - y0)
    if length < 1e-9:
        return None
    n = (reach.side * -(y1 - y0) / length, reach.side * (x1 - x0) / length)
    n = (round(n[0], 12) + 0.0, round(n[1], 12) + 0.0)
    delta = past_shortfall(reach.required - reach.behind)
    return Move(panel.name, ((x0, y0), (x1, y1)), n, n[0] * x0 + n[1] * y0, delta)


def _nearest_entry(d: DeviceCheck):
    if d.entries:
        p0, p1, _ = min(d.entries, key=lambda e: e[2])
        return (tuple(p0), tuple(p1))
    return None


def shift_point(p, m: Move):
    """Point p moved by the move where it lies on or beyond the edge's line, else as it is."""
    x, y = float(p[0]), float(p[1])
    if m.normal[0] * x + m.normal[1] * y >= m.line - ON_LINE:
        return [round(x + m.delta * m.normal[0], 6) + 0.0, round(y + m.delta * m.normal[1], 6) + 0.0]
    return list(p)


def _shift_device(dev: dict, m: Move, warning: bool) -> None:
    for key in ("start", "end"):
        if isinstance(dev.get(key), list):
            dev[key] = shift_point(dev[key], m)
    if isinstance(dev.get("polygon"), list):
        dev["polygon"] = [shift_point(p, m) for p in dev["polygon"]]
    warn = dev.get("warning")
    if warning and isinstance(warn, dict) and isinstance(warn.get("polygon"), list):
        warn["polygon"] = [shift_point(p, m) for p in warn["polygon"]]


def _is_panel(m: Move) -> bool:
    return m.device.startswith("fence ") and " panel " in m.device


def apply_move(doc: dict, m: Move, whole: bool) -> None:
    """Move the edge in ``doc`` (in place): the device alone, or the whole cell beyond the edge's line. The
    worker's start points beyond the line move in both: a start left inside the moved field would have the
    worker seen from the first step, a test of nothing."""
    whole = whole or _is_panel(m)
    if not whole:
        dev = device_entry(doc, m.device)
        if dev is not None:
            _shift_device(dev, m, warning=False)
    else:
        for dev in _devices(doc):
            _shift_device(dev, m, warning=True)
        for fence in doc.get("fences") or ():
            if isinstance(fence, dict) and isinstance(fence.get("points"), list):
                fence["points"] = [shift_point(p, m) for p in fence["points"]]
    move_starts_and_floor(doc, m)


def move_starts_and_floor(doc: dict, m: Move) -> None:
    """The worker's start points beyond the move's line moved with it, and the floor grown by it (in place)."""
    human = doc.get("human") or {}
    for start in [human.get("start"), *(human.get("starts") or ())]:
        if isinstance(start, dict) and isinstance(start.get("xy"), list):
            start["xy"] = shift_point(start["xy"], m)
    floor = doc.get("floor")
    if isinstance(floor, dict):
        for axis, (lo, hi) in ((0, ("xmin", "xmax")), (1, ("ymin", "ymax"))):
            step = m.delta * m.normal[axis]
            if abs(step) > 1e-12:
                key = hi if step > 0 else lo
                floor[key] = round(float(floor[key]) + step, 6) + 0.0


def move_words(m: Move, whole: bool) -> str:
    (x0, y0), (x1, y1) = m.edge
    if _is_panel(m):
        return (f"move {m.device} ({x0:g}, {y0:g})-({x1:g}, {y1:g}) {m.delta:.2f} m towards the worker (ISO 13857 "
                f"Table 2), direction ({m.normal[0]:.3g}, {m.normal[1]:.3g}), with the cell beyond it")
    what = "with the cell beyond it (walls, other devices)" if whole else "(the device alone)"
    return (f"move {m.device}'s edge ({x0:g}, {y0:g})-({x1:g}, {y1:g}) {m.delta:.2f} m outward, direction "
            f"({m.normal[0]:.3g}, {m.normal[1]:.3g}), {what}")


# ---- settings named by a row --------------------------------------------------------------------------------
def setting_remedies(cell: Cell, static: StaticCheck) -> list[Remedy]:
    """One remedy per failing row that names a device setting (module docstring), in the rows' order."""
    out: list[Remedy] = []
    base = cell_document(cell)
    for d in static.devices:
        dev = device_entry(base, d.device)
        if d.ok or dev is None:
            continue
        if dev.get("type") == "guard-door" and not dev.get("guard_locking", False):
            out.append(_setting(base, d.device, "guard-locking", {"guard_locking": True}, (d.device,),
                                f"guard locking on {d.device} (locked until the robot is at rest, ISO 14119)"))
        if dev.get("type") == "speed-separation" and "underestimated" in d.note:
            times = {}
            if float(dev.get("reaction_time", 0.0)) < d.response_time - 1e-12:
                times["reaction_time"] = round(d.response_time, 6)
            if float(dev.get("stopping_time", 0.0)) < d.stopping_time - 1e-12:
                times["stopping_time"] = round(d.stopping_time, 6)
            if times:
                words = ", ".join(f"{k} {v:g} s" for k, v in times.items())
                out.append(_setting(base, d.device, "ssm-times", times, (d.device,),
                                    f"configure {d.device}'s controller with the real times ({words})"))
    for sp in static.speeds:  # a monitor set for a slower robot: its configured top speed set to the real one
        dev = device_entry(base, sp.device)
        if not sp.ok and dev is not None and dev.get("type") == "speed-separation":
            real = cm_up(sp.real)
            out.append(_setting(base, sp.device, "ssm-speed", {"max_speed": real}, (f"{sp.device}-speed",),
                                f"configure {sp.device} for the robot's real top speed ({real:g} m/s, was "
                                f"{sp.configured:g})"))
    for r in static.restarts:
        if not r.ok and device_entry(base, r.device) is not None:
            out.append(_setting(base, r.device, "manual-restart", {"restart": "manual"}, (f"{r.device}-restart",),
                                f"manual restart on {r.device} (a reset outside the cell)"))
    for m in static.mutings:
        dev = device_entry(base, m.device)
        if not m.ok and dev is not None and isinstance(dev.get("muting"), dict):
            muting = {**dev["muting"], "until": m.pallet_out}
            out.append(_setting(base, m.device, "muting-end", {"muting": muting}, (f"{m.device}-muting",),
                                f"end {m.device}'s muting when the pallet is out ({m.pallet_out:g} s)"))
    out += _wiring(base, static)
    return out


def _setting(base: dict, device: str, kind: str, fields: dict, rows: tuple[str, ...], words: str) -> Remedy:
    doc = copy.deepcopy(base)
    dev = device_entry(doc, device)
    if dev is not None:
        dev.update(copy.deepcopy(fields))
    return Remedy(kind, words, rows, 0, dump_cell(doc))


def _wiring(base: dict, static: StaticCheck) -> list[Remedy]:
    """A robot whose undetected-reach row fails while some device does not stop it: wire that device to it."""
    out = []
    for a in (static.approach, *static.robot_approaches):
        if a.ok or not a.robot:
            continue
        for dev in _devices(base):
            stops = dev.get("stops")
            if isinstance(stops, list) and a.robot not in stops:
                doc = copy.deepcopy(base)
                target = device_entry(doc, dev.get("name"))
                target["stops"] = [*stops, a.robot]
                out.append(Remedy("wire", f"wire {dev.get('name')} to robot {a.robot} (it stops "
                                  f"{', '.join(map(str, stops))} only)", (f"undetected-reach:{a.robot}",), 0,
                                  dump_cell(doc)))
    return out


def moved(cell: Cell, moves: tuple[Move, ...], whole: bool, extra: float = 0.0) -> Remedy:
    """The cell with ``moves`` applied one after the other, each ``extra`` metres further than ISO 13855 needs
    (where the check passes and the re-test still finds a hazard, ``analysis.fix`` tries larger ones)."""
    moves = tuple(replace(m, delta=round(m.delta + extra, 6)) for m in moves)
    doc = cell_document(cell)
    for m in moves:
        apply_move(doc, m, whole)
    rows = tuple(dict.fromkeys(m.device for m in moves))
    return Remedy("move-cell" if whole else "move-device", "; ".join(move_words(m, whole) for m in moves), rows, 0,
                  dump_cell(doc))


def program_moves(cell: Cell) -> tuple[tuple[int, int, float], ...]:
    """Every move of every robot program that has a speed field: (robot index, move index, its speed scale)."""
    out = []
    for k, r in enumerate(_robots(cell_document(cell))):
        task = r.get("task") or {}
        if task.get("trajectory_csv"):
            continue
        n = len(task.get("waypoints_deg") or task.get("poses") or ())
        scales = task.get("speed_scales") or [task.get("speed_scale", 0.5)] * n
        out += [(k, i, float(scales[i])) for i in range(n)]
    return tuple(out)


def with_scales(cell: Cell, scales: dict[tuple[int, int], float], words: str,
                phases: dict[int, float] | None = None) -> Remedy:
    """The cell with the given moves' speed scales (robot index, move index) -> scale, other moves unchanged;
    ``phases``: robot index -> its program's new ``phase`` (the same point of the path in the slower cycle)."""
    doc = cell_document(cell)
    for k, r in enumerate(_robots(doc)):
        task = r.get("task")
        if not isinstance(task, dict) or task.get("trajectory_csv"):
            continue
        if phases and k in phases:
            task["phase"] = round(phases[k], 6)
        n = len(task.get("waypoints_deg") or task.get("poses") or ())
        old = task.pop("speed_scales", None) or [task.get("speed_scale", 0.5)] * n
        task.pop("speed_scale", None)
        task["speed_scales"] = [max(0.01, math.floor(scales.get((k, i), float(old[i])) * 1e4) / 1e4)
                                for i in range(n)]
    return Remedy("slow-per-move", words, ("hazard",), 0, dump_cell(doc))
