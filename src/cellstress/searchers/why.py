"""Why a hazardous episode was not prevented, read off its timeline: which device saw the worker and when, when
its stop took effect, when the robot stood still, and how much too late that was for the contact.

Every number comes from the replayed records and the cell's response and stopping times; the static ISO 13855
distances (required and actual) are added where the words are shown (``cli``, ``report``), which may import the
static check.
"""

from __future__ import annotations

from cellstress.devices.base import stops_robot
from cellstress.searchers.result import DeviceTiming, Why
from cellstress.sim import layout as L


def _r(t: float) -> float:
    return round(float(t), 9)  # k * dt carries float noise


STOPPING = ("stop-pending", "braking", "stopped")  # StepRecord.stop_phase while a stop holds the robot


def safeguard_words(layout, records, unsafe_row: int) -> str | None:
    """What the speed reductions and automatic restarts of the episode did before the contact, from the rows'
    devices and stop phases; None when neither happened."""
    P = layout.params
    names = layout.device_names
    warn = {names[i]: (float(P.dev_speed[i]), float(P.dev_resp[i])) for i in range(len(names))
            if P.dev_speed[i] > 0.0}
    stop_names = {names[i] for i in range(len(names)) if P.dev_speed[i] == 0.0}
    parts = _separation_words(layout, records[: unsafe_row + 1])
    doors = {names[int(d)]: (float(P.door_open[i]), P.door_lock[i] != 0.0) for i, d in enumerate(P.door_dev)}
    seen_warn: set[str] = set()
    last_stop_seen: tuple[str, float] | None = None
    prev = None
    first_stop = min((r.t + float(P.dev_resp[names.index(n)]) for r in records[: unsafe_row + 1] for n in r.devices
                      if n in stop_names), default=None)
    parts += _muting_words(layout, records[: unsafe_row + 1])
    for r in records[: unsafe_row + 1]:
        for name in r.devices:
            if name in doors and (prev is None or name not in prev.devices):
                parts.append(_door_words(name, *doors[name], r.t, first_stop, layout))
            if name in warn and name not in seen_warn:
                seen_warn.add(name)
                frac, resp = warn[name]
                parts.append(f"{name} saw the worker at {r.t:.2f} s and cut the robot to {frac:g} of its speed "
                             f"from {_r(r.t + resp):.2f} s")
            if name in stop_names:
                last_stop_seen = (name, r.t)
        if prev is not None and prev.stop_phase in STOPPING and r.stop_phase not in STOPPING:
            who = "" if last_stop_seen is None else \
                f"{last_stop_seen[0]} last saw the worker at {last_stop_seen[1]:.2f} s; "
            unseen = "while no device saw the worker" if not r.devices else f"while {', '.join(r.devices)} saw them"
            parts.append(f"{who}the robot restarted automatically at {r.t:.2f} s {unseen}")
        prev = r
    if not parts:
        return None
    hit = records[unsafe_row]
    return "; ".join(parts) + f"; v_R at the contact {hit.v_R:.2f} m/s ({hit.stop_phase})"


def separation_devices(layout) -> set[str]:
    """Names of the channels that set the speed from the measured separation (speed and separation monitoring)."""
    P = layout.params
    return {layout.device_names[i] for i in range(len(layout.device_names)) if P.dev_speed[i] == L.SEPARATION}


def _separation_words(layout, records) -> list[str]:
    """When the separation monitor first saw the worker, when its first speed cut took effect (the rows' phase
    turns ``reduced-speed``), and the robot's speed at the end."""
    out = []
    for name in sorted(separation_devices(layout)):
        seen = next((r.t for r in records if name in r.devices), None)
        if seen is None:
            continue
        cut = next((r.t for r in records if r.stop_phase == "reduced-speed"), None)
        when = "it had not cut the speed yet" if cut is None else f"its first speed cut took effect at {cut:.2f} s"
        out.append(f"{name} measured the worker from {seen:.2f} s; {when}")
    return out


def _muting_words(layout, records) -> list[str]:
    """Each muted channel's muting during the episode up to the contact, from the cell's clock."""
    P = layout.params
    phase, cycle = float(P.scal[L.C_PHASE0]), float(P.scal[L.C_CYCLE])
    out = []
    for d, name in enumerate(layout.device_names):
        on, off = float(P.dev_muted[d, 0]), float(P.dev_muted[d, 1])
        if on == float("inf"):
            continue
        times = [r.t for r in records if on <= (phase + r.t) % cycle <= off or on <= (phase + r.t) % cycle + cycle
                 <= off]
        if times:
            still = " (still muted at the contact)" if times[-1] == records[-1].t else ""
            out.append(f"{name} was muted from {times[0]:.2f} s to {times[-1]:.2f} s ({on:g}..{off:g} s of the "
                       f"cycle){still}")
    return out


def _door_words(name: str, opening: float, locked: bool, pushed: float, first_stop: float | None, layout) -> str:
    """A guard door's part of the timeline: when it was pushed, when it let the worker through, and how that
    compares with the robot's rest (its first stop plus the stopping time)."""
    rest = None if first_stop is None else _r(first_stop + float(layout.robots[0].stop.to_standstill))
    if locked:
        return f"{name} was pushed at {pushed:.2f} s and stayed locked until the robot was at rest ({rest:.2f} s)"
    through = _r(pushed + opening)
    gap = "" if rest is None else (f", {rest - through:.2f} s before the robot was at rest ({rest:.2f} s)"
                                   if rest > through else f", the robot at rest since {rest:.2f} s")
    return f"{name} opened at {pushed:.2f} s without guard locking and let the worker through from {through:.2f} s{gap}"


def touched_robot(layout, record):
    """The robot (a ``sim.build.RobotPart``) whose capsule a record's ``robot_link`` names: in a cell of several
    robots the capsules are named ``ROBOT:link``; robot 0 for a one-robot cell or a record without a link."""
    parts = layout.robots
    link = record.robot_link
    if len(parts) < 2 or not link or ":" not in link:
        return parts[0] if parts else None
    name = link.split(":", 1)[0]
    return next((p for p in parts if p.name == name), parts[0])


def explain(layout, records, unsafe_row: int) -> Why:
    """The ``Why`` of the hazard at ``records[unsafe_row]`` (``records``: the episode's ``StepRecord`` rows). In a
    cell of several robots only the devices that stop the touched robot count, with its stopping time."""
    spec = layout.cell.spec
    words = safeguard_words(layout, records, unsafe_row)
    robot = touched_robot(layout, records[unsafe_row])
    stop = (layout.robots[0] if robot is None else robot).stop  # its delay before braking, then its braking
    if len(layout.robots) > 1:
        others = [d.name for d in spec.devices if not stops_robot(d, robot.name)
                  and any(d.name in r.devices for r in records[: unsafe_row + 1])]
        if others:
            note = f"{', '.join(others)} saw the worker but {'does' if len(others) == 1 else 'do'} not stop " \
                   f"robot {robot.name}"
            words = note if words is None else f"{note}; {words}"
    stopping = {d.name for d in spec.devices if len(layout.robots) < 2 or stops_robot(d, robot.name)} - \
        separation_devices(layout)  # (a separation monitor commands speeds; its stop is one of them)
    response = {d.name: float(d.response_time) for d in spec.devices}
    saw: dict[str, float] = {}
    for r in records[: unsafe_row + 1]:
        for name in r.devices:
            saw.setdefault(name, r.t)
    timings = tuple(DeviceTiming.model_construct(
        device=d.name, saw_at_s=saw.get(d.name),
        stop_at_s=None if d.name not in saw else _r(saw[d.name] + response[d.name])) for d in spec.devices)
    hit = records[unsafe_row]
    contact = hit.t if hit.contact_t is None else hit.contact_t  # a contact between the steps: its own moment
    stops = [t for t in timings if t.stop_at_s is not None and t.device in stopping]
    if not stops:
        return Why.model_construct(detected=False, devices=timings, stopped_by=None, braking_from_s=None,
                                   standstill_at_s=None, contact_at_s=contact, late_by_s=None, safeguards=words)
    first = min(stops, key=lambda t: t.stop_at_s)  # (min keeps the cell's order among equal times)
    standstill = _r(first.stop_at_s + float(stop.to_standstill))
    return Why.model_construct(detected=True, devices=timings, stopped_by=first.device,
                               braking_from_s=_r(first.stop_at_s + float(stop.delay)), standstill_at_s=standstill,
                               contact_at_s=contact,
                               late_by_s=_r(standstill - contact), safeguards=words)


def why_words(why: Why) -> str:
    """The timeline in one sentence."""
    if not why.detected:
        extra = "" if why.safeguards is None else f"; {why.safeguards}"
        if why.safeguards is not None and "not stop robot" in why.safeguards:
            # several robots: seen, but by no device that stops the robot touched
            return f"no device that stops the touched robot saw the worker before the contact at " \
                   f"{why.contact_at_s:.2f} s{extra}"
        if why.safeguards is not None and " measured the worker from " in why.safeguards:
            return f"no device stopped the robot before the contact at {why.contact_at_s:.2f} s{extra}"
        return f"undetected: no device saw the worker before the contact at {why.contact_at_s:.2f} s{extra}"
    first = next(t for t in why.devices if t.device == why.stopped_by)
    late = why.late_by_s
    restarted = why.safeguards is not None and "restarted automatically" in why.safeguards
    verdict = (f"{late:.2f} s too late" if late > 0 else
               "the robot stood still in time, then restarted" if restarted else
               "the robot stood still in time but the criterion still judged the contact unsafe")
    extra = "" if why.safeguards is None else f"; {why.safeguards}"
    brake = "" if why.braking_from_s is None or why.braking_from_s == first.stop_at_s else \
        f" (the robot's controller began to brake at {why.braking_from_s:.2f} s)"
    return (f"{first.device} saw the worker at {first.saw_at_s:.2f} s; its stop took effect at "
            f"{first.stop_at_s:.2f} s{brake}; the robot would stand still at {why.standstill_at_s:.2f} s; the "
            f"contact came at {why.contact_at_s:.2f} s: {verdict}{extra}")
