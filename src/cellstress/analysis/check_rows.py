"""The rows of ``cellstress check``, each with a stable name and a verdict: what a JUnit report lists as test
cases and what ``cellstress diff`` compares between two cells.

A row's name is the one ``StaticCheck.failures`` (and ``ProgramCheck.failures``) gives it when it fails, so a
failing row reads the same in the terminal, in a JUnit file and in a diff; rows that pass get the names they
would have had. Where one check yields several rows of one name (a device with an automatic restart on several
detection zones), the later ones get ``#2``, ``#3``: names stay unique, so a diff can match them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cellstress.analysis.espe_rules import BeamHeights, CurtainReachOver, ScannerMounting
from cellstress.verifier.records import StaticFailure


@dataclass(frozen=True)
class CheckRow:
    """One verdict of the static check."""

    name: str  # e.g. 'curtain', 'undetected-reach', 'scanner-restart', 'program:a'
    kind: str  # what was checked, in a few words (the JUnit class name)
    ok: bool
    value: str  # the measured quantity and its requirement, e.g. '0.412 m (needs 0.530 m)' ('' when none)
    detail: str  # the check's own line(s) of text
    limit: str = ""  # what the simulated worker cannot do to take this way in ('' where it can, or the row passes)


def _m(x: float) -> str:
    return "none" if math.isinf(x) else f"{x:.3f} m"


def _robot(name: str, robot: str) -> str:
    return name + (f":{robot}" if robot else "")


def _access_rows(rule) -> list[CheckRow]:
    """One row per verdict of a rule on getting over, under or across a device (named as ``failure_name``)."""
    text = rule.line()
    if isinstance(rule, CurtainReachOver):
        return [CheckRow(_robot(f"{rule.device}-reach-over", rule.robot), "ISO 13855 reach over a curtain", rule.ok,
                         f"{_m(rule.behind)} (needs {_m(rule.required)})", text, rule.model_limit)]
    if isinstance(rule, BeamHeights):
        return [CheckRow(f"{rule.device}-crawl-under", "ISO 13855 crawling under", rule.crawl_ok,
                         f"lowest beam {rule.bottom:.3f} m", text, rule.crawl_limit),
                CheckRow(f"{rule.device}-step-over", "ISO 13855 stepping over", rule.step_ok,
                         f"highest beam {rule.top:.3f} m", text, rule.step_limit)]
    if isinstance(rule, ScannerMounting):
        return [CheckRow(f"{rule.device}-mounting", "ISO 13855 scanner mounting height", rule.resolution_ok,
                         f"scan plane {rule.height:.3f} m", text),
                CheckRow(f"{rule.device}-crawl-under", "ISO 13855 crawling under", rule.crawl_ok,
                         f"scan plane {rule.height:.3f} m", text, rule.model_limit)]
    return [CheckRow(f"{rule.device}-depth", "ISO 13855 mat depth", rule.ok, f"depth {_m(rule.depth)}", text,
                     rule.model_limit)]


def check_rows(static, programs=()) -> tuple[CheckRow, ...]:
    """Every row of a ``StaticCheck`` and of the robots' ``ProgramCheck``s, in the order ``check`` prints them."""
    rows: list[CheckRow] = []
    for p in programs:
        rows.append(CheckRow(_robot("program", p.robot), "robot program", p.ok, f"{len(p.moves)} moves, cycle "
                             f"{p.cycle:.2f} s", "\n".join(p.lines())))
    for d in static.devices:
        rows.append(CheckRow(_robot(d.device, d.robot), f"ISO 13855 {d.type}", d.ok,
                             f"{_m(d.actual)} (needs {_m(d.required)})", f"T = {d.response_time:.2f} + "
                             f"{d.stopping_time:.2f} s, {d.formula}"))
    for a in (static.approach, *static.robot_approaches):
        rows.append(CheckRow(_robot("undetected-reach", a.robot), "undetected reach", a.ok,
                             f"{_m(a.distance)} (needs {a.arm_allowance:.3f} m)", f"from {a.undetected_area:.1f} m^2 "
                             "of floor the worker stands on unseen", a.limit))
        if a.panels_at:
            fails = a.reach_over_fails
            # the simulated worker takes this way in unless it can reach over none of the failing panels
            limit = "; ".join(dict.fromkeys(p.limit for p in fails)) if all(p.limit for p in fails) else ""
            rows.append(CheckRow(_robot("reach-over", a.robot), "ISO 13857 Table 2 reach over a fence", not fails,
                                 f"{len(fails)} of {len(a.panels_at)} panels too close", "", limit))
    for r in static.restarts:
        rows.append(CheckRow(f"{r.device}-restart", "automatic restart", r.ok,
                             f"{_m(r.behind.distance)} (needs {r.behind.arm_allowance:.3f} m)",
                             f"automatic restart after {r.clear_time:g} s clear"))
    rows += [CheckRow(f"{m.device}-muting", "IEC 62046 muting", m.ok, f"muted until {m.until:g} s, pallet out "
                      f"at {m.pallet_out:g} s", m.line()) for m in static.mutings]
    rows += [CheckRow(f"{s.device}-speed", "configured speed", s.ok,
                      f"configured {s.configured:.3g} m/s (the robot reaches {s.real:.3g} m/s)", s.line())
             for s in static.speeds]
    if static.openings:
        bad = [o for o in static.openings if not o.ok]
        rows.append(CheckRow("whole-body-opening", "ISO 13857 whole-body openings", not bad,
                             f"{len(bad)} of {len(static.openings)} openings admit the body unseen",
                             "\n".join(o.line() for o in static.openings),
                             "; ".join(dict.fromkeys(o.sim_note for o in bad if o.sim_note))))
    for rule in static.access:
        rows += _access_rows(rule)
    return _unique(rows)


def _unique(rows: list[CheckRow]) -> tuple[CheckRow, ...]:
    seen: dict[str, int] = {}
    out = []
    for r in rows:
        n = seen[r.name] = seen.get(r.name, 0) + 1
        out.append(r if n == 1 else CheckRow(f"{r.name}#{n}", r.kind, r.ok, r.value, r.detail, r.limit))
    return tuple(out)


def static_failures(static, programs=()) -> tuple[StaticFailure, ...]:
    """The failing rows of a ``StaticCheck`` (and ``ProgramCheck``s), as a verdict keeps them beside itself: a proof
    or a search of the simulated worker does not clear a row the static check fails (``limit`` says why it may
    not even try)."""
    return tuple(StaticFailure(name=r.name[:200], value=r.value[:400], limit=r.limit[:400])
                 for r in check_rows(static, programs) if not r.ok)
