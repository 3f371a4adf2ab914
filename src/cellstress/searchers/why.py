"""Why a hazardous episode was not prevented, read off its timeline: which device saw the worker and when, when
its stop took effect, when the robot stood still, and how much too late that was for the contact.

Every number comes from the replayed records and the cell's response and stopping times; the static ISO 13855
distances (required and actual) are added where the words are shown (``cli``, ``report``), which may import the
static check.
"""

from __future__ import annotations

from cellstress.searchers.result import DeviceTiming, Why


def _r(t: float) -> float:
    return round(float(t), 9)  # k * dt carries float noise


def explain(layout, records, unsafe_row: int) -> Why:
    """The ``Why`` of the hazard at ``records[unsafe_row]`` (``records``: the episode's ``StepRecord`` rows)."""
    spec = layout.cell.spec
    response = {d.name: float(d.response_time) for d in spec.devices}
    saw: dict[str, float] = {}
    for r in records[: unsafe_row + 1]:
        for name in r.devices:
            saw.setdefault(name, r.t)
    timings = tuple(DeviceTiming.model_construct(
        device=d.name, saw_at_s=saw.get(d.name),
        stop_at_s=None if d.name not in saw else _r(saw[d.name] + response[d.name])) for d in spec.devices)
    contact = records[unsafe_row].t
    stops = [t for t in timings if t.stop_at_s is not None]
    if not stops:
        return Why.model_construct(detected=False, devices=timings, stopped_by=None, braking_from_s=None,
                                   standstill_at_s=None, contact_at_s=contact, late_by_s=None)
    first = min(stops, key=lambda t: t.stop_at_s)  # (min keeps the cell's order among equal times)
    standstill = _r(first.stop_at_s + float(spec.robot.stopping_time))
    return Why.model_construct(detected=True, devices=timings, stopped_by=first.device,
                               braking_from_s=first.stop_at_s, standstill_at_s=standstill, contact_at_s=contact,
                               late_by_s=_r(standstill - contact))


def why_words(why: Why) -> str:
    """The timeline in one sentence."""
    if not why.detected:
        return f"undetected: no device saw the worker before the contact at {why.contact_at_s:.2f} s"
    first = next(t for t in why.devices if t.device == why.stopped_by)
    late = why.late_by_s
    verdict = (f"{late:.2f} s too late" if late > 0 else
               "the robot stood still in time but the criterion still judged the contact unsafe")
    return (f"{first.device} saw the worker at {first.saw_at_s:.2f} s; its stop took effect at "
            f"{first.stop_at_s:.2f} s; the robot would stand still at {why.standstill_at_s:.2f} s; the contact "
            f"came at {why.contact_at_s:.2f} s: {verdict}")
