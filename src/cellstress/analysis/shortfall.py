"""Why a hazard happened, in words: the episode's timeline (``searchers.why``) next to the static ISO 13855
distances of the safeguard that should have prevented it (required S against where it stands), or, when no
device saw the worker, the undetected reach against the arm allowance."""

from __future__ import annotations

from cellstress.analysis.iso13855 import StaticCheck
from cellstress.searchers.result import Why
from cellstress.searchers.why import why_words


def distance_words(why: Why, static: StaticCheck) -> str:
    """What the static check says about the safeguard that failed (empty when it has nothing to add)."""
    if why.detected:
        rows = [d for d in static.devices if d.device == why.stopped_by]
        if not rows:
            return ""
        d = min(rows, key=lambda r: r.actual - r.required)  # several robots: the row nearest failing
        verdict = ("short by" if not d.ok else "met, with")
        gap = abs(d.actual - d.required)
        whose = f" robot {d.robot}'s" if d.robot else ""
        return (f"ISO 13855 requires S = {d.required:.2f} m; {d.device} stands {d.actual:.2f} m from the"
                f"{whose} hazard zone ({verdict} {gap:.2f} m)")
    sep = [d for d in static.devices if d.type == "speed-separation" and why.safeguards is not None
           and f"{d.device} measured the worker" in why.safeguards]
    if sep:
        d = sep[0]
        verdict = "short by" if not d.ok else "met, with"
        return (f"ISO/TS 15066 requires S_p = {d.required:.2f} m at full speed with the real reaction time "
                f"{d.response_time:g} s and stopping time {d.stopping_time:g} s; {d.device} allowed full speed down "
                f"to {d.actual:.2f} m ({verdict} {abs(d.actual - d.required):.2f} m)")
    muted = [m for m in static.mutings if not m.ok]
    if muted:
        return "; ".join(f"{m.device} stayed muted {m.until - m.pallet_out:.2f} s after the pallet had cleared the "
                         "opening (IEC 62046: the muting ends as it clears)" for m in muted)
    a = min((static.approach, *static.robot_approaches), key=lambda r: r.distance)  # several robots: the nearest
    if a.distance == float("inf"):
        return "the static check finds no undetected reach to the hazard zone"
    verdict = "short by" if not a.ok else "met, with"
    whose = f" to robot {a.robot}" if a.robot else ""
    return (f"undetected reach{whose}: the shortest arm path from where no device that stops it sees the worker "
            f"is {a.distance:.2f} m, " if a.robot else
            "undetected reach: the shortest arm path from where no device sees the worker is "
            f"{a.distance:.2f} m, ") + \
        f"{a.arm_allowance:.2f} m needed ({verdict} {abs(a.distance - a.arm_allowance):.2f} m)"


def shortfall(why: Why, static: StaticCheck | None) -> str:
    """The timeline and, when the static check is at hand, the distances: one sentence."""
    extra = "" if static is None else distance_words(why, static)
    return why_words(why) + (f"; {extra}" if extra else "")
