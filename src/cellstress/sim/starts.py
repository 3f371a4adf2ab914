"""A cell's named start points (``human.starts``): the simulator of each, and the ``start:NAME`` prefix that names
one at the head of an action sequence (as ``result.json`` records episodes of multi-start cells)."""

from __future__ import annotations

from collections.abc import Sequence

from cellstress.core.errors import ActionError

START_PREFIX = "start:"


def start_simulator(sim, start):
    """The simulator of one ``human.starts`` entry: its pose and, if it has one, its own robot phase."""
    return sim.with_start((start.xy[0], start.xy[1], start.heading_deg), start.phase)


def split_start(sim, actions: Sequence) -> tuple[object, list]:
    """(simulator for the leading ``start:NAME`` of ``actions`` or ``sim`` itself, the remaining actions)."""
    acts = list(actions)
    if not acts or not isinstance(acts[0], str) or not acts[0].startswith(START_PREFIX):
        return sim, acts
    name = acts[0][len(START_PREFIX):]
    for s in sim.cell.spec.human.starts:
        if s.name == name:
            return start_simulator(sim, s), acts[1:]
    known = ", ".join(s.name for s in sim.cell.spec.human.starts) or "none"
    raise ActionError(f"unknown start {name!r} (the cell's starts: {known})")
