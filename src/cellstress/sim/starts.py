"""Where and when a worker arrives: a cell's named start points (``human.starts``), the moments of the robot's
cycle a search may choose (``human.arrival``), and the ``start:NAME`` and ``phase:SECONDS`` decisions that name them
at the head of an action sequence (as ``result.json`` records the episodes of such cells)."""

from __future__ import annotations

import math
from collections.abc import Sequence

from cellstress.core.errors import ActionError

START_PREFIX = "start:"
PHASE_PREFIX = "phase:"
MAX_PHASE = 3600.0  # s, as robot.task.phase


def start_simulator(sim, start, phase: float | None = None):
    """The simulator of one ``human.starts`` entry: its pose and the robot's phase at arrival (``phase``, else the
    start point's own, else the cell's)."""
    return sim.with_start((start.xy[0], start.xy[1], start.heading_deg), start.phase if phase is None else phase)


def phase_grid(dt: float, lo: float, hi: float) -> tuple[float, ...]:
    """The time steps k * dt in [lo, hi], rounded to 1 ns so that their decimal names read back to the same float."""
    first = max(0, math.ceil(lo / dt - 1e-9))
    last = math.floor(hi / dt + 1e-9)
    return tuple(round(k * dt, 9) for k in range(first, last + 1))


def arrival_phases(sim, start=None) -> tuple[float, ...]:
    """The robot's phases (its path time at the worker's arrival, s) a search chooses from, for the start point
    ``start`` (a ``human.starts`` entry; None: ``human.start``). ``arrival: fixed`` gives one: the start point's
    own phase or the cell's ``robot.task.phase``; ``cycle`` every time step of one cycle; a window every time step
    in it."""
    spec = sim.cell.spec
    arrival = spec.human.arrival
    if arrival == "fixed":
        own = None if start is None else start.phase
        return (float(spec.robot.task.phase if own is None else own),)
    if arrival == "cycle":
        cycle = float(sim.layout.trajectory.cycle)
        return tuple(p for p in phase_grid(sim.dt, 0.0, cycle) if p < cycle)  # (the cycle's end is its start)
    return phase_grid(sim.dt, arrival.start, arrival.end)


def phase_token(phase: float) -> str:
    return f"{PHASE_PREFIX}{phase!r}"


def is_arrival_token(action) -> bool:
    return isinstance(action, str) and (action.startswith(START_PREFIX) or action.startswith(PHASE_PREFIX))


def parse_phase(token: str) -> float:
    text = token[len(PHASE_PREFIX):]
    try:
        value = float(text)
    except ValueError:
        raise ActionError(f"{token!r}: the phase is not a number of seconds") from None
    if not (math.isfinite(value) and 0.0 <= value <= MAX_PHASE):
        raise ActionError(f"{token!r}: the phase must be between 0 and {MAX_PHASE:g} s")
    return value


def split_start(sim, actions: Sequence) -> tuple[object, list]:
    """(simulator for the leading ``start:NAME`` and ``phase:SECONDS`` of ``actions``, or ``sim`` itself without
    them; the remaining actions)."""
    acts = list(actions)
    start = None
    if acts and isinstance(acts[0], str) and acts[0].startswith(START_PREFIX):
        name = acts.pop(0)[len(START_PREFIX):]
        start = next((s for s in sim.cell.spec.human.starts if s.name == name), None)
        if start is None:
            known = ", ".join(s.name for s in sim.cell.spec.human.starts) or "none"
            raise ActionError(f"unknown start {name!r} (the cell's starts: {known})")
    phase = None
    if acts and isinstance(acts[0], str) and acts[0].startswith(PHASE_PREFIX):
        phase = parse_phase(acts.pop(0))
    if start is not None:
        return start_simulator(sim, start, phase), acts
    if phase is not None:
        return sim.with_start(sim.start, phase), acts
    return sim, acts
