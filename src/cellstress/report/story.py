"""The hazard in plain language, written from the replayed trace: where the worker went and how they moved,
which device saw them and when, which robot link met which body part, how fast the robot moved and how far
its stop had got. Every number comes from the records; nothing is guessed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cellstress.report.episode import EpisodeView
from cellstress.searchers.why import touched_robot
from cellstress.sim.layout import C_PHASE0

_PARTS = {"left-reach": "within reach of the worker's left hand",
          "right-reach": "within reach of the worker's right hand",
          "left-arm": "touches the worker's left arm", "right-arm": "touches the worker's right arm",
          "left-leg": "touches the worker's left leg", "right-leg": "touches the worker's right leg",
          "trunk": "touches the worker's trunk", "head": "touches the worker's head",
          "left-forearm": "touches the worker's left forearm", "right-forearm": "touches the worker's right forearm",
          "left-hand": "touches the worker's left hand", "right-hand": "touches the worker's right hand"}
_PHASES = {"running": "no stop has been requested, the robot runs at full speed",
           "stop-pending": "a stop has been requested but has not taken effect yet",
           "braking": "the robot is braking but has not stopped",
           "stopped": "the robot has stopped",
           "reduced-speed": "a warning field or a speed and separation monitor has cut the robot's speed"}


def link_words(name: str | None) -> str:
    """'forearm_link' -> 'forearm (forearm_link)'; 'tool0#extra0' -> 'part held on tool0 (tool0#extra0)'."""
    if not name:
        return "robot"
    base, _, extra = name.partition("#")
    words = base.removesuffix("_link").replace("_", " ")
    return f"part held on {base} ({name})" if extra else f"{words} ({name})"


def _xy(r: dict) -> str:
    return f"({r.x:.2f}, {r.y:.2f}) m"


def _device_kind(view: EpisodeView, name: str) -> tuple[str, float]:
    """(what the worker does when the device sees them, its response time) of the device named ``name``."""
    for d in view.layout.cell.spec.devices:
        if d.name == name:
            return d.detection_phrase, float(d.response_time)
    return "is seen by the device", math.nan


@dataclass(frozen=True)
class Account:
    """A one-sentence summary and the detailed sentences, in order."""

    headline: str
    details: tuple[str, ...]


def stop_request(view: EpisodeView, upto: int) -> tuple[float, str] | None:
    """(time the stop takes effect, device that set it) from the detections up to row ``upto``: each device
    that sees the worker asks for a stop one response time later, and the earliest request wins."""
    best: tuple[float, str] | None = None
    for r in view.records[: upto + 1]:
        for name in r.devices:
            t_s = r.t + _device_kind(view, name)[1]
            if best is None or t_s < best[0]:
                best = (round(t_s, 9), name)
    return best


def account(view: EpisodeView, episodes: int | None = None) -> Account:
    recs = view.records
    key = view.key_row
    hit = recs[key]
    x0, y0, h0 = view.start
    phase, cycle = float(view.layout.params.scal[C_PHASE0]), float(view.layout.trajectory.cycle)
    chosen = "" if view.layout.cell.spec.human.arrival == "fixed" else " (a moment the search chose)"
    details: list[str] = [f"The worker starts at ({x0:.2f}, {y0:.2f}) m facing {h0:g}°, arriving when the robot is "
                          f"{phase % cycle:.2f} s into its {cycle:.2f} s cycle{chosen}."]

    # what the worker does, action by action, with the distance actually covered (fences and table block)
    for k, act in enumerate(view.actions):
        rows = view.action_rows(k)
        first, last = recs[rows.start - 1], recs[rows[-1]]
        moved = math.hypot(last.x - first.x, last.y - first.y)
        walk = act.partition("+")[0]
        where = f"to {_xy(last)}" if moved > 0.005 else "in place"
        blocked = " (blocked: does not move)" if walk == "walk" and moved <= 0.005 else ""
        details.append(f"Action {k + 1} ({first.t:.2f}-{last.t:.2f} s): {view.layout.worker.action_words(act)}, {where}"
                       f"{blocked}; heading {last.heading_deg:.0f}°, bent {last.forward_flexion_deg:.0f}° "
                       f"forward and {abs(last.lateral_flexion_deg):.0f}° to the "
                       f"{'left' if last.lateral_flexion_deg >= 0 else 'right'}.")

    det = view.detection_row
    seen_by = ""
    if det is not None and det <= key:
        r = recs[det]
        parts = []
        for name in r.devices:
            kind, resp = _device_kind(view, name)
            verb = kind
            parts.append(f"{verb} '{name}' (response {resp:g} s)")
        stop = stop_request(view, key)
        details.append(f"At t = {r.t:.2f} s the worker {' and '.join(parts)} at {_xy(r)}; the stop takes "
                       f"effect at t = {stop[0]:.2f} s." if stop else "")
        seen_by = (f"is detected by '{', '.join(r.devices)}' at t = {r.t:.2f} s at {_xy(r)}; "
                   f"{hit.t - r.t:.2f} s after detection ")
    else:
        details.append("No safety device detects the worker" + (" before the contact." if view.unsafe else "."))
        seen_by = f"is never detected; at t = {hit.t:.2f} s "

    link, part = link_words(hit.robot_link), hit.body_part
    px, py, pz = hit.robot_point
    phase = hit.stop_phase
    stop = stop_request(view, key)
    if phase == "stop-pending" and stop:
        phase_text = f"a stop requested by '{stop[1]}' takes effect only at t = {stop[0]:.2f} s"
    elif phase == "braking" and stop:
        rs = touched_robot(view.layout, hit).stop
        phase_text = (f"the robot has been braking since t = {stop[0] + rs.delay:.2f} s and would stand still at "
                      f"t = {stop[0] + rs.to_standstill:.2f} s")
    else:
        phase_text = _PHASES.get(phase, phase)
    moves = ", ".join(view.layout.worker.action_words(a, short=True) for a in view.actions)
    if view.unsafe:
        details.append(f"At t = {hit.t:.2f} s (step {hit.step}) the robot's {link} is "
                       f"{_PARTS.get(part, part)} at ({px:.2f}, {py:.2f}, {pz:.2f}) m, while the robot moves at "
                       f"v_R = {hit.v_R:.2f} m/s: {phase_text}. "
                       + ("No stop was requested" if phase == "running" else "The stop is not complete")
                       + ": this is an unsafe contact.")
        headline = (f"The worker {moves}; it {seen_by}the robot's {link.split(' (')[0]} is "
                    f"{_PARTS.get(part, part).replace('touches', 'touching')}, moving at {hit.v_R:.2f} m/s; "
                    f"{'the stop is not complete' if phase != 'running' else 'no stop was requested'}.")
    else:
        n = f" in {episodes} episodes" if episodes is not None else ""
        details.append(f"The closest call is at t = {hit.t:.2f} s (step {hit.step}): d_HR = "
                       f"{hit.d_HR:.3f} m between the robot's {link} and the worker's {part}, the robot moving at "
                       f"v_R = {hit.v_R:.2f} m/s; {phase_text}.")
        headline = (f"No hazard was found{n}. The riskiest episode kept (episode {view.episode}) comes within "
                    f"{hit.d_HR:.3f} m of the robot's {link.split(' (')[0]} at t = {hit.t:.2f} s, the robot "
                    f"moving at {hit.v_R:.2f} m/s.")
    return Account(headline, tuple(d for d in details if d))
