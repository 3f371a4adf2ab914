"""The rows of ``cellstress check``, each with a stable name and a verdict: what a JUnit report lists as test
cases and what ``cellstress diff`` compares between two cells.

A row's name is the one ``StaticCheck.failures`` (and ``ProgramCheck.failures``) gives it when it fails, so a
failing row reads the same in the terminal, in a JUnit file and in a diff; rows that pass get the names they
would have had. Where one check yields several rows of one name (a device with an automatic restart on several
detection zones), the later ones get ``#2``, ``#3``: names stay unique, so a diff can match them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Literal

from cellstress.analysis.espe_rules import BeamHeights, CurtainReachOver, ScannerMounting
from cellstress.verifier.records import StaticFailure

Way = Literal["late", "unseen", "restart", "any", ""]  # CheckRow.way


@dataclass(frozen=True)
class RowPoint:
    """The static check's own geometric witness of a row: robot ``robot``'s capsule ``part`` ('' : robot 0, a
    cell of one) at episode time ``t`` [s] from the cell's phase, modulo its cycle, where the row's distance is
    attained, seen from the floor segment ``toward`` (a point twice: where the worker stands or reaches from; a
    panel or a curtain's line). A simulated witness is searched for at that robot point and moment
    (``analysis.witness``)."""

    robot: str
    part: str
    t: float
    toward: tuple[tuple[float, float], tuple[float, float]]


@dataclass(frozen=True)
class CheckRow:
    """One verdict of the static check."""

    name: str  # e.g. 'curtain', 'undetected-reach', 'scanner-restart', 'program:a'
    kind: str  # what was checked, in a few words (the JUnit class name)
    ok: bool
    value: str  # the measured quantity and its requirement, e.g. '0.412 m (needs 0.530 m)' ('' when none)
    detail: str  # the check's own line(s) of text
    limit: str = ""  # what the simulated worker cannot do to take this way in ('' where it can, or the row passes)
    point: RowPoint | None = None  # where the check found the zone too close (None: the row names no such place)
    # what a simulated contact must show to take this row's way in (``analysis.witness``): "late" (``device`` saw
    # the worker before it), "unseen" (``device``, or with none every stopping device, did not), "restart" (the
    # robot restarted by itself before it), "any" (a hazard in the cell is all the row asks), "" (no way in)
    way: Way = ""
    device: str = ""


def _m(x: float) -> str:
    return "none" if math.isinf(x) else f"{x:.3f} m"


def _robot(name: str, robot: str) -> str:
    return name + (f":{robot}" if robot else "")


def _at(robot: str, where) -> RowPoint | None:
    """The RowPoint of a ``hazard_zone.Closest`` (None: no distance attained)."""
    if where is None or not where.robot_part:
        return None
    p = (float(where.point[0]), float(where.point[1]))
    return RowPoint(robot, where.robot_part, float(where.t), (p, p))


def _over(robot: str, part: str, t: float, line) -> RowPoint | None:
    """The RowPoint of a reach over a panel's top or a curtain's top beam (line: its floor segment)."""
    if not part or not math.isfinite(t) or line is None:
        return None
    (x0, y0), (x1, y1) = line
    return RowPoint(robot, part, float(t), ((float(x0), float(y0)), (float(x1), float(y1))))


def _access_rows(rule) -> list[CheckRow]:
    """One row per verdict of a rule on getting over, under or across a device (named as ``failure_name``)."""
    text = rule.line()
    if isinstance(rule, CurtainReachOver):
        # the arm over the top may be seen late or not at all: any hazard witnesses it
        return [CheckRow(_robot(f"{rule.device}-reach-over", rule.robot), "ISO 13855 reach over a curtain", rule.ok,
                         f"{_m(rule.behind)} (needs {_m(rule.required)})", text, rule.model_limit,
                         _over(rule.robot, rule.robot_part, rule.t, rule.beam_line), "any", rule.device)]
    if isinstance(rule, BeamHeights):
        return [CheckRow(f"{rule.device}-crawl-under", "ISO 13855 crawling under", rule.crawl_ok,
                         f"lowest beam {rule.bottom:.3f} m", text, rule.crawl_limit, way="unseen", device=rule.device),
                CheckRow(f"{rule.device}-step-over", "ISO 13855 stepping over", rule.step_ok,
                         f"highest beam {rule.top:.3f} m", text, rule.step_limit, way="unseen", device=rule.device)]
    if isinstance(rule, ScannerMounting):
        return [CheckRow(f"{rule.device}-mounting", "ISO 13855 scanner mounting height", rule.resolution_ok,
                         f"scan plane {rule.height:.3f} m", text, way="unseen", device=rule.device),
                CheckRow(f"{rule.device}-crawl-under", "ISO 13855 crawling under", rule.crawl_ok,
                         f"scan plane {rule.height:.3f} m", text, rule.model_limit, way="unseen", device=rule.device)]
    return [CheckRow(f"{rule.device}-depth", "ISO 13855 mat depth", rule.ok, f"depth {_m(rule.depth)}", text,
                     rule.model_limit, way="unseen", device=rule.device)]


def check_rows(static, programs=()) -> tuple[CheckRow, ...]:
    """Every row of a ``StaticCheck`` and of the robots' ``ProgramCheck``s, in the order ``check`` prints them."""
    rows: list[CheckRow] = []
    for p in programs:
        rows.append(CheckRow(_robot("program", p.robot), "robot program", p.ok, f"{len(p.moves)} moves, cycle "
                             f"{p.cycle:.2f} s", "\n".join(p.lines())))
    for d in static.devices:
        rows.append(CheckRow(_robot(d.device, d.robot), f"ISO 13855 {d.type}", d.ok,
                             f"{_m(d.actual)} (needs {_m(d.required)})", f"T = {d.response_time:.2f} + "
                             f"{d.stopping_time:.2f} s, {d.formula}", point=_at(d.robot, d.where), way="late",
                             device=d.device))
    for a in (static.approach, *static.robot_approaches):
        rows.append(CheckRow(_robot("undetected-reach", a.robot), "undetected reach", a.ok,
                             f"{_m(a.distance)} (needs {a.arm_allowance:.3f} m)", f"from {a.undetected_area:.1f} m^2 "
                             "of floor the worker stands on unseen", a.limit, _at(a.robot, a.where), "unseen"))
        if a.panels_at:
            fails = a.reach_over_fails
            # the simulated worker takes this way in unless it can reach over none of the failing panels
            limit = "; ".join(dict.fromkeys(p.limit for p in fails)) if all(p.limit for p in fails) else ""
            # the witness: the tightest failing panel the simulated worker is not said to be unable to reach over
            open_ = sorted((p for p in fails if not p.limit), key=lambda p: p.reach.behind - p.reach.required)
            point = (_over(a.robot, open_[0].reach.robot_part, open_[0].reach.t,
                           (open_[0].panel.start, open_[0].panel.end)) if open_ else None)
            rows.append(CheckRow(_robot("reach-over", a.robot), "ISO 13857 Table 2 reach over a fence", not fails,
                                 f"{len(fails)} of {len(a.panels_at)} panels too close", "", limit, point, "unseen"))
    for r in static.restarts:
        rows.append(CheckRow(f"{r.device}-restart", "automatic restart", r.ok,
                             f"{_m(r.behind.distance)} (needs {r.behind.arm_allowance:.3f} m)",
                             f"automatic restart after {r.clear_time:g} s clear",
                             point=_at(r.behind.robot, r.behind.where), way="restart", device=r.device))
    rows += [CheckRow(f"{m.device}-muting", "IEC 62046 muting", m.ok, f"muted until {m.until:g} s, pallet out "
                      f"at {m.pallet_out:g} s", m.line(), way="any", device=m.device) for m in static.mutings]
    rows += [CheckRow(f"{s.device}-speed", "configured speed", s.ok,
                      f"configured {s.configured:.3g} m/s (the robot reaches {s.real:.3g} m/s)", s.line(), way="any",
                      device=s.device) for s in static.speeds]
    if static.openings:
        bad = [o for o in static.openings if not o.ok]
        rows.append(CheckRow("whole-body-opening", "ISO 13857 whole-body openings", not bad,
                             f"{len(bad)} of {len(static.openings)} openings admit the body unseen",
                             "\n".join(o.line() for o in static.openings),
                             "; ".join(dict.fromkeys(o.sim_note for o in bad if o.sim_note)), way="unseen"))
    for rule in static.access:
        rows += _access_rows(rule)
    return _unique(rows)


def _unique(rows: list[CheckRow]) -> tuple[CheckRow, ...]:
    seen: dict[str, int] = {}
    out = []
    for r in rows:
        n = seen[r.name] = seen.get(r.name, 0) + 1
        out.append(r if n == 1 else replace(r, name=f"{r.name}#{n}"))
    return tuple(out)


def static_failures(static, programs=()) -> tuple[StaticFailure, ...]:
    """The failing rows of a ``StaticCheck`` (and ``ProgramCheck``s), as a verdict keeps them beside itself: a proof
    or a search of the simulated worker does not clear a row the static check fails (``limit`` says why it may
    not even try)."""
    return tuple(StaticFailure(name=r.name[:200], value=r.value[:400], limit=r.limit[:400])
                 for r in check_rows(static, programs) if not r.ok)
