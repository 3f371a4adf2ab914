"""The static check's report as text: the lines ``cellstress check`` prints (``StaticCheck.lines``)."""

from __future__ import annotations

import math

from cellstress.analysis.hazard_zone import Closest
from cellstress.core.iso13857 import MIN_HIGH_RISK_STRUCTURE_MM, WHOLE_BODY_SLOT_MM, WHOLE_BODY_SQUARE_ROUND_MM

LOW_HIGH_RISK = MIN_HIGH_RISK_STRUCTURE_MM / 1000.0  # m


def _xy(p) -> str:
    return f"({p[0]:.2f}, {p[1]:.2f})"


def _verdict(ok: bool) -> str:
    return "ok" if ok else "FAIL"


def _where(w: Closest | None, cycle: float) -> str:
    if w is None:
        return ""
    return (f" at {_xy(w.point)} -> {_xy(w.hazard_point)}: {w.robot_part} at t = {w.t:.2f} s "
            f"(episode time, mod {cycle:.2f} s)")


def check_lines(r) -> list[str]:
    """The lines of a ``StaticCheck``."""
    z = r.zone
    x0, x1, y0, y1 = z.extent()
    each = f" ({', '.join(f'{n} {c:.2f} s' for n, c in r.robot_cycles)}: each robot over its own)" \
        if r.robot_cycles else ""
    out = [f"hazard zone: robot capsules over one {z.cycle:.2f} s cycle{each} every {z.sample_dt * 1000:.0f} ms, "
           f"x {x0:.3f}..{x1:.3f} m, y {y0:.3f}..{y1:.3f} m"]
    cycles = dict(r.robot_cycles)
    for d in r.devices:
        whose = f", stopping robot {d.robot}" if d.robot else ""
        out.append(f"{d.device} ({d.type}{whose}): T = {d.response_time:.2f} + {d.stopping_time:.2f} s, {d.formula}")
        if d.field_edges and not d.entries:
            out.append("  no open field edge: every edge lies along a fence, the table or the floor's edge")
        if d.field_edges:
            for q0, q1, dist in d.entries:
                out.append(f"  open edge {_xy(q0)}-{_xy(q1)}: {dist:.3f} m to the hazard zone, "
                           f"needs {d.required:.3f} m: {_verdict(dist >= d.required - 1e-9)}")
        where = _where(d.where, cycles.get(d.robot, z.cycle))
        out.append(f"  {d.device}: {d.actual:.3f} m >= {d.required:.3f} m? {_verdict(d.ok)}{where}")
        if r.phase_fixed and math.isfinite(d.episode_actual) and d.episode_actual > d.actual + 5e-4:
            out.append(f"    (during one episode, t = 0..{r.episode:.2f} s from the cell's phase, "
                       f"the robot comes no closer than {d.episode_actual:.3f} m)")
        if d.note:
            out.append(f"  {d.note}")
    closed = [p for p in r.fences if p.closed]
    if r.fences:
        out.append(f"fences: {len(closed)} of {len(r.fences)} panels close the way (lower than 1 m, raised off the "
                   "floor, or not meeting ISO 13857 Table 2 behind its top: open)")
    for p in r.fences:
        if not p.closed:
            out.append(f"  {p.name} {_xy(p.start)}-{_xy(p.end)} counts as open: {p.reason}")
    if r.openings:
        out.append(f"openings in the perimeter (ISO 13857 whole body: a slot wider than {WHOLE_BODY_SLOT_MM:.0f} mm, a "
                   f"square or round opening wider than {WHOLE_BODY_SQUARE_ROUND_MM:.0f} mm, unless a device sees it):")
        out += [f"  {o.line()}" for o in r.openings]
    if r.access:
        out.append("getting over, under or across the devices (ISO 13855):")
        out += [f"  {a.line()}" for a in r.access]
    for a in (r.approach, *r.robot_approaches):
        out += _approach_lines(a, cycles.get(a.robot, z.cycle))
    for rc in r.restarts:
        b = rc.behind
        out.append(f"{rc.device}: automatic restart after {rc.clear_time:g} s clear; a worker who crossed it stands "
                   f"unseen on {b.undetected_area:.1f} m^2 next to it")
        if b.where is None:
            out.append(f"  from there the hazard zone cannot be reached: {_verdict(b.ok)}")
        else:
            out.append(f"  closest: stand at {_xy(b.stand)}, shoulder at {_xy(b.where.point)}, arm path "
                       f"{b.distance:.3f} m >= {b.arm_allowance:.2f} m? {_verdict(b.ok)}{_where(b.where, z.cycle)}"
                       + ("" if b.ok else ": the robot restarts while the worker stands unseen within reach"))
        out += _reach_over_lines(b, z.cycle)
    out += [m.line() for m in r.mutings]
    out += [s.line() for s in r.speeds]
    fails = r.failures()
    out.append("result: pass" if not fails else f"result: FAIL ({', '.join(fails)})")
    return out


def _approach_lines(a, cycle: float) -> list[str]:
    out = []
    margins = [f">{m:.2f} m from {what}" for m, what in ((a.scanner_margin, "scanner fields"),
                                                         (a.curtain_margin, "curtains")) if m is not None]
    where = f"stand {' and '.join(margins)}" if margins else "no detection zone to keep away from"
    whose = f" to robot {a.robot}'s hazard zone (devices that stop it: {', '.join(a.guards) or 'none'})" \
        if a.robot else ""
    head = (f"undetected reach{whose} from {_xy(a.start)}: {where} ({a.undetected_area:.1f} m^2), lean {a.lean:.3f} m, "
            f"arm {a.arm_allowance:.2f} m")
    out.append(head)
    if a.start_detected:
        out.append("  the start point is inside a detection zone: no undetected approach")
    elif a.where is None:
        out.append(f"  the hazard zone cannot be reached around the fences: {_verdict(a.ok)}")
    else:
        out.append(f"  closest: stand at {_xy(a.stand)}, shoulder at {_xy(a.where.point)}, arm path "
                   f"{a.distance:.3f} m >= {a.arm_allowance:.2f} m? {_verdict(a.ok)}{_where(a.where, cycle)}")
    if a.limit:
        out.append(f"    {a.limit}")
    return out + _reach_over_lines(a, cycle)


def _panel_row(pr, cycle: float) -> str:
    """'fence F panel P (..)-(..): top b m, hazard at a m, c = x m behind it; ISO 13857 Table 2 requires y m'."""
    p, ro = pr.panel, pr.reach
    lo, hi = ro.band
    return (f"    {p.name} {_xy(p.start)}-{_xy(p.end)}: top {p.top:.2f} m, hazard at {ro.hazard_height:.2f} m, "
            f"c = {ro.behind:.3f} m behind it; ISO 13857 Table 2 requires {ro.required:.3f} m (a {lo * 1000:.0f}.."
            f"{hi * 1000:.0f} mm, b {p.top * 1000:.0f} mm): {_verdict(ro.ok)}; {ro.robot_part} at "
            f"t = {ro.t:.2f} s (episode time, mod {cycle:.2f} s)")


def _reach_over_lines(a, cycle: float) -> list[str]:
    """ISO 13857 Table 2 at the panels the worker stands at unseen: a row per panel that fails it, else the one
    with the least margin."""
    if not a.panels_at:
        return []
    fails = a.reach_over_fails
    low = sum(p.panel.top < LOW_HIGH_RISK for p in a.panels_at)
    head = (f"  reach over the {len(a.panels_at)} fence panels the worker stands at unseen (ISO 13857 Table 2, "
            "high risk" + (f"; {low} lower than 1.4 m, which 4.4 allows only with further protective measures"
                           if low else "") + "): ")
    if fails:
        out = [head + f"{len(fails)} too close"]
        for p in fails:
            out.append(_panel_row(p, cycle))
            if p.limit:  # the simulated worker cannot reach over it (analysis.worker_reach)
                out.append("      " + p.limit)
        return out
    tight = min(a.panels_at, key=lambda p: p.reach.behind - p.reach.required)
    if math.isinf(tight.reach.behind):
        return [head + "no part of the hazard zone lies within the table's distances behind any of them: ok"]
    return [head + "the tightest:", _panel_row(tight, cycle)]
