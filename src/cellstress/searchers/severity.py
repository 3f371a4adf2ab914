"""How bad a hazard is, so that findings are listed worst first (result files, the command line, the report and
``verify``'s witnesses).

A hazard's severity is its contact speed: v_R at the unsafe step, the speed of the robot touched (the paper's
measure, the one the contact criterion judges). Under a criterion that judges forces (``iso15066``) it is the
predicted peak force over the limit of the body region touched (quasi-static when it is clamped, transient
otherwise), a head contact while the robot moves counting at least 1 (its limit is any contact at all). A transient
contact while the robot creeps, slower than ``criteria.iso15066.CREEP_SPEED`` (0.123 m/s: below it the robot's
motion brings no transient contact over its ISO/TS 15066 limit on any body region but the head, however heavy the
robot), is still a finding of the criterion, but it is listed after every faster one: a robot at the end of its
braking that a worker leans against is not the first thing to fix. A clamping contact is never listed apart: a
creeping robot that keeps pushing a hand against the table until it stands is the hazard itself. Ties keep the
order found.
"""

from __future__ import annotations

from collections.abc import Sequence

from cellstress.criteria.iso15066 import CREEP_SPEED
from cellstress.searchers.result import Severity


def severity(v_r: float | None, verdict: dict | None) -> Severity:
    """The severity of a contact at speed ``v_r`` [m/s], with its criterion's verdict (``Verdict.as_dict``; None
    for a criterion that judges in the kernel)."""
    ratio = None
    if verdict is not None and "ratio" in verdict:
        ratio = float(verdict["ratio"])
        reason = verdict.get("reason") or ""
        if "contact while the robot moves" in reason:
            ratio = max(ratio, 1.0)
    v = 0.0 if v_r is None else float(v_r)
    # the creep speed bounds transient contacts only: a clamping one (iso15066) is never listed apart
    clamping = verdict is not None and verdict.get("case") == "clamping"
    return Severity.model_construct(v_R=v, force_ratio=ratio, creeping=bool(v < CREEP_SPEED and not clamping))


def rank(s: Severity | None) -> tuple[bool, float]:
    """Sort key, worst first: creeping contacts after the others, then the larger force ratio (or speed) first."""
    if s is None:
        return (True, 0.0)
    return (s.creeping, -(s.force_ratio if s.force_ratio is not None else s.v_R))


def worst_first(items: Sequence, key=lambda x: x.severity) -> list:
    """``items`` sorted worst first by their severity (``key``); a stable sort, so ties keep their order."""
    return sorted(items, key=lambda x: rank(key(x)))


def words(s: Severity | None) -> str:
    """A severity in a few words, for the command line and the report."""
    if s is None:
        return ""
    force = f", force {s.force_ratio:.2f} x its limit" if s.force_ratio is not None else ""
    creep = f" (creeping: below {CREEP_SPEED:.3f} m/s)" if s.creeping else ""
    return f"v_R {s.v_R:.3f} m/s{force}{creep}"
