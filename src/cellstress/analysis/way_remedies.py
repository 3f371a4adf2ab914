"""Candidate changes that close a way in (``cellstress fix``), from ``check``'s openings and device rules.

Each answers one failing row with the least change of its kind, and never looks at the cell's name:

* **lower-panel**: an opening under a raised fence or door leaf that admits the whole body (ISO 13857: a slot
  over 180 mm): its bottom lowered to 180 mm (the least that closes it to the body), else to the floor (where
  a bottom edge still lets an arm under, ``check`` says so and only the floor passes). Two candidates, tried
  in that order; ``fix`` stops at the first that works.
* **close-gap**: a gap from a fence's free end to another barrier (or the floor's edge) that admits the body
  unseen, or that is the entry of a device whose ISO 13855 distance there falls short (seen, too late): one
  new fence panel across it, as high as the fence it continues; one part added. The panel is drawn as that
  fence's run continued (and joined to the run it meets, where the heights agree), the wall as one run. A gap
  that is a far enough entry (the cell's way in) is never closed.
* **raise-top**: a light curtain whose top beam can be reached over (ISO 13855 Table 1's C_RO): its top raised
  to the lowest of Table 1's columns at which its reach-over row passes (found by ``check`` itself, columns
  only: between columns the table gives the lower one's distances); none where even 2600 mm fails.
* **device-height**: a curtain whose lowest beam lets a body crawl under (over 300 mm) or whose top beam can be
  stepped over (under 900 mm): that beam moved to the limit (ISO 13855 6.2); a scanner's plane too low for
  its resolution or high enough to crawl under: moved into 15 (d - 50)..300 mm where that range is not empty
  (6.3; the field's own distance, which depends on the height, is then ``check``'s to judge).
* **raise-fence**: fences with a panel the hazard zone is too close behind for ISO 13857 Table 2 (the
  ``reach-over`` row): each raised to the lowest of the table's columns where none of its panels fails, found
  by ``check`` the same way (moving the panel instead is ``fix``'s ``move-cell``).
* moving a curtain back to S_RO is the ``move-device`` / ``move-cell`` candidate (``remedies.reach_over_move``).
"""

from __future__ import annotations

import copy
from collections.abc import Callable

from cellstress.analysis.espe_rules import BeamHeights, CurtainReachOver, ScannerMounting
from cellstress.analysis.iso13855 import StaticCheck
from cellstress.analysis.openings import ON_TOL
from cellstress.analysis.plane import point_segment
from cellstress.analysis.remedies import Remedy, cell_document, device_entry, dump_cell
from cellstress.cell.load import Cell
from cellstress.core import iso13855 as I
from cellstress.core import iso13857 as I13857
from cellstress.core.iso13857 import WHOLE_BODY_SLOT_MM

SLOT = WHOLE_BODY_SLOT_MM / 1000.0  # m: ISO 13857's largest slot the whole body does not pass
CRAWL_BEAM = I.CRAWL_UNDER_MAX_MM / 1000.0  # m: ISO 13855 6.2, a whole-body curtain's lowest beam at most this high
STEP_BEAM = I.STEP_OVER_MIN_MM / 1000.0  # m: ISO 13855 6.2, its top beam at least this high


def lowered_panels(cell: Cell, static: StaticCheck) -> list[tuple[Remedy, ...]]:
    """For each failing opening under a raised fence or door: its bottom at 180 mm, then at the floor."""
    base = cell_document(cell)
    out, seen = [], set()
    for o in static.openings:
        if o.ok or o.kind != "under" or (o.fence, o.door) in seen:
            continue
        seen.add((o.fence, o.door))
        if o.fence >= 0:
            target, name = ("fence", o.fence), f"fence {o.fence + 1}"
        elif o.door:
            target, name = ("door", o.door), f"door {o.door}"
        else:
            continue
        tries = []
        for bottom in (b for b in (SLOT, 0.0) if b < o.height - 1e-9):
            doc = copy.deepcopy(base)
            where = _target(doc, target)
            if where is None:
                break
            where["bottom"] = bottom
            to = "to the floor" if bottom == 0.0 else f"to {bottom * 1000:.0f} mm (ISO 13857 whole body: a slot)"
            tries.append(Remedy("lower-panel", f"lower {name}'s bottom edge from {o.height * 1000:.0f} mm {to}",
                                ("whole-body-opening",), 0, dump_cell(doc)))
        if tries:
            out.append(tuple(tries))
    return out


def _target(doc: dict, target: tuple) -> dict | None:
    kind, key = target
    if kind == "fence":
        fences = doc.get("fences") or []
        return fences[key] if key < len(fences) and isinstance(fences[key], dict) else None
    return device_entry(doc, key)


def closed_gaps(cell: Cell, static: StaticCheck) -> list[Remedy]:
    """For each gap from a fence's free end that the body passes unseen, or through which a device's entry is
    too close to the hazard (the device sees it, too late): one panel across it, as high as that fence. A gap
    whose entry is far enough (the cell's way in) is left open."""
    base = cell_document(cell)
    out = []
    for o in static.openings:
        if o.kind != "gap" or o.fence < 0 or o.fence >= len(cell.spec.fences):
            continue
        short = tuple(d.device for d in static.devices if not d.ok and any(
            dist < d.required and _along(p0, p1, o.start, o.end) for p0, p1, dist in d.entries))
        if o.ok and not short:
            continue
        top = float(cell.spec.fences[o.fence].top)
        doc = copy.deepcopy(base)
        joined = _joined_run(doc, cell.spec.fences, o.fence, o.start, o.end)
        if joined is None:
            doc.setdefault("fences", []).append({"points": [list(o.start), list(o.end)], "top": top})
        (x0, y0), (x1, y1) = o.start, o.end
        rows = short if o.ok else ("whole-body-opening", *short)
        how = "" if joined is None else f", fence {o.fence + 1} continued{joined}"
        out.append(Remedy("close-gap", f"close the {o.where} with a fence panel ({x0:g}, {y0:g})-({x1:g}, {y1:g}), "
                          f"{top:g} m high{how}", rows, 1, dump_cell(doc)))
    return out


def _joined_run(doc: dict, fences, f: int, start, end) -> str | None:
    """Draw the closing panel as part of fence ``f``'s own run (its free end ``start`` moved on to ``end``), and
    where another fence of the same heights begins or ends at ``end``, that one too, with points in a straight
    line dropped: the wall as one run, as a designer draws it (the simulator lets an arm through the seam of two
    collinear runs: docs/architecture.md, "Known"). Returns what else was joined ('' for nothing), None
    where fence ``f``'s run cannot be continued (the panel is then a fence of its own)."""
    entries = doc.get("fences") or []
    if not all(isinstance(e, dict) for e in entries) or len(entries) != len(fences):
        return None
    own = [tuple(map(float, p)) for p in fences[f].points]
    if _same(own[0], start):
        own.reverse()
    if not _same(own[-1], start):
        return None
    pts, other, words = own + [tuple(map(float, end))], None, ""
    for g, fence in enumerate(fences):
        ends = [tuple(map(float, p)) for p in fence.points]
        if g == f or (fence.top, fence.bottom) != (fences[f].top, fences[f].bottom):
            continue
        if _same(ends[-1], end):
            ends.reverse()
        if _same(ends[0], end):  # its own (unrounded) points, not the opening's
            pts, other, words = own + ends, g, f" and joined to fence {g + 1}"
            break
    entries[f]["points"] = [list(p) for p in _straightened(pts)]
    if other is not None:
        del entries[other]
    return words


def _same(a, b) -> bool:
    """The same point, up to the 0.1 mm an opening's ends are rounded to (``analysis.openings``)."""
    return abs(a[0] - b[0]) <= 1e-4 and abs(a[1] - b[1]) <= 1e-4


def _straightened(pts: list) -> list:
    """The polyline without points that lie on the straight line between their neighbours (or repeat one)."""
    out = [pts[0]]
    for k in range(1, len(pts)):
        p = pts[k]
        if p == out[-1]:
            continue
        if len(out) >= 2:
            a, b = out[-2], out[-1]
            cross = (b[0] - a[0]) * (p[1] - b[1]) - (b[1] - a[1]) * (p[0] - b[0])
            dot = (b[0] - a[0]) * (p[0] - b[0]) + (b[1] - a[1]) * (p[1] - b[1])
            if abs(cross) <= 1e-9 and dot > 0.0:
                out[-1] = p
                continue
        out.append(p)
    return out


def _along(p0, p1, a, b) -> bool:
    """Whether the segment p0-p1 lies along a-b (both its ends within ``ON_TOL`` of it)."""
    return all(float(point_segment(x, y, a[0], a[1], b[0], b[1])[0]) <= ON_TOL for x, y in (p0, p1))


def _lowest(columns: list[float], ok: Callable[[float], bool]) -> float | None:
    """The lowest of ascending ``columns`` where ``ok`` holds, bisecting (it holds on a suffix: a reach-over
    table's distance never grows with the structure's height); None where it holds nowhere."""
    lo, hi = 0, len(columns)
    while lo < hi:
        mid = (lo + hi) // 2
        if ok(columns[mid]):
            hi = mid
        else:
            lo = mid + 1
    return columns[lo] if lo < len(columns) else None


def raised_tops(cell: Cell, static: StaticCheck, static_of: Callable[[str], StaticCheck | None]) -> list[Remedy]:
    """For each curtain whose reach-over row fails: its top at the lowest Table 1 column where the row passes.
    ``static_of(text)``: the check of the cell file ``text`` (None where it is no valid cell)."""
    base = cell_document(cell)
    out, seen = [], set()
    for r in static.access:
        if not isinstance(r, CurtainReachOver) or r.ok or r.device in seen:
            continue
        seen.add(r.device)
        row = f"{r.device}-reach-over" + (f":{r.robot}" if r.robot else "")

        def text_at(top: float, device: str = r.device) -> str:
            doc = copy.deepcopy(base)
            device_entry(doc, device)["top"] = top
            return dump_cell(doc)

        def passes(top: float, row: str = row) -> bool:
            after = static_of(text_at(top))
            return after is not None and row not in after.failures()

        top = _lowest([b / 1000.0 for b in I.C_RO_B_MM if b / 1000.0 > r.top + 1e-9], passes)
        if top is not None:
            out.append(Remedy("raise-top", f"raise {r.device}'s top beam from {r.top * 1000:.0f} mm to "
                              f"{top * 1000:.0f} mm (ISO 13855 Table 1)", (row,), 0, text_at(top)))
    return out


def raised_fences(cell: Cell, static: StaticCheck, static_of: Callable[[str], StaticCheck | None]) -> list[Remedy]:
    """One candidate raising every fence with a panel the hazard zone is too close behind (ISO 13857 Table 2,
    the ``reach-over`` rows): each fence's top at the lowest of the table's columns where none of its panels
    fails any more (the others as they are)."""
    base = cell_document(cell)
    fences = sorted({pr.panel.fence for a in (static.approach, *static.robot_approaches) for pr in a.reach_over_fails})
    doc, words = copy.deepcopy(base), []
    for f in fences:
        entries = doc.get("fences") or []
        if not 1 <= f <= len(entries) or not isinstance(entries[f - 1], dict):
            continue
        old = float(cell.spec.fences[f - 1].top)

        def text_at(top: float, f: int = f) -> str:
            trial = copy.deepcopy(base)
            trial["fences"][f - 1]["top"] = top
            return dump_cell(trial)

        def passes(top: float, f: int = f) -> bool:
            after = static_of(text_at(top))
            return after is not None and not any(pr.panel.fence == f for a in (after.approach, *after.robot_approaches)
                                                 for pr in a.reach_over_fails)

        top = _lowest([b / 1000.0 for b in I13857.TABLE_2.b_mm if b / 1000.0 > old + 1e-9], passes)
        if top is None:
            return []  # (the table's last column has c = 0: only a broken check gets here)
        entries[f - 1]["top"] = top
        words.append(f"fence {f} from {old:g} m to {top:g} m")
    if not words:
        return []
    rows = tuple(dict.fromkeys("reach-over" + (f":{a.robot}" if a.robot else "")
                               for a in (static.approach, *static.robot_approaches) if a.reach_over_fails))
    return [Remedy("raise-fence", "raise " + "; ".join(words) + " (ISO 13857 Table 2)", rows, 0, dump_cell(doc))]


def device_heights(cell: Cell, static: StaticCheck) -> list[Remedy]:
    """For each curtain a body crawls under or steps over: the beam at ISO 13855 6.2's limit; for each scanner
    whose plane is too low for its resolution or high enough to crawl under: the plane at the nearest height
    that meets both, where one does (6.3: 15 (d - 50) mm <= H <= 300 mm)."""
    base = cell_document(cell)
    out = []
    for r in static.access:
        if isinstance(r, BeamHeights) and not (r.crawl_ok and r.step_ok):
            fields, words, rows = {}, [], []
            if not r.crawl_ok:
                fields["bottom"] = CRAWL_BEAM
                words.append(f"lowest beam from {r.bottom * 1000:.0f} to {CRAWL_BEAM * 1000:.0f} mm")
                rows.append(f"{r.device}-crawl-under")
            if not r.step_ok:
                fields["top"] = STEP_BEAM
                words.append(f"top beam from {r.top * 1000:.0f} to {STEP_BEAM * 1000:.0f} mm")
                rows.append(f"{r.device}-step-over")
            what = ", ".join(words) + " (ISO 13855 6.2)"
        elif isinstance(r, ScannerMounting) and not r.ok:
            lo, hi = r.min_height_mm / 1000.0, I.CRAWL_UNDER_MAX_MM / 1000.0
            if lo > hi + 1e-9:
                continue  # no height meets both: a finer resolution is the change, not a setting
            height = min(max(r.height, lo), hi)
            fields = {"height": round(height, 6)}
            rows = [f"{r.device}-{w}" for w, ok in (("mounting", r.resolution_ok), ("crawl-under", r.crawl_ok))
                    if not ok]
            what = (f"scan plane from {r.height * 1000:.0f} to {height * 1000:.0f} mm (ISO 13855 6.3: "
                    f"{lo * 1000:.0f}..{hi * 1000:.0f} mm for {r.resolution:g} mm)")
        else:
            continue
        doc = copy.deepcopy(base)
        dev = device_entry(doc, r.device)
        if dev is None:
            continue
        dev.update(fields)
        out.append(Remedy("device-height", f"{r.device}: {what}", tuple(rows), 0, dump_cell(doc)))
    return out
