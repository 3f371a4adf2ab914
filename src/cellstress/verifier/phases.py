"""Which start points and arrival phases a verification decides: the one place that chooses them.

An arrival phase is the robot's path time when the worker's episode starts. ``all`` decides every time step of
the robot's cycle, k * dt for k * dt < cycle (rounded to 1 ns, as ``sim.starts.phase_grid`` names them), for
every start point, whatever the cell says; ``cell`` decides the phases the cell's ``human.arrival`` allows
(``sim.starts.arrival_phases``: ``fixed``, the cell's own phase or a start point's; ``cycle``, every time step of
the cycle; a window, every time step in it); ``window`` (``--phases A:B``) the time steps of the cycle from A to B
seconds, ends included. ``starts`` names the start points to decide (none: every one), in the cell's order.
"""

from __future__ import annotations

from dataclasses import dataclass

from cellstress.sim.starts import arrival_phases as cell_phases
from cellstress.sim.starts import phase_grid

PHASE_MODES = ("all", "cell", "window")
_ON_GRID = 1e-9  # s: a grid phase on a window's end belongs to it (the grid is rounded to 1 ns)
DEFAULT_START = "start"  # the name of a cell's only start point (``human.start``) in verify's output


@dataclass(frozen=True)
class StartPoint:
    """A start pose as the cell names it; ``spec``: its ``human.starts`` entry (None: ``human.start``)."""

    name: str
    x: float
    y: float
    heading_deg: float
    spec: object = None

    @property
    def pose(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.heading_deg)


def start_points(cell) -> tuple[StartPoint, ...]:
    """The cell's start points: each of ``human.starts``, or ``human.start`` alone."""
    human = cell.spec.human
    if human.starts:
        return tuple(StartPoint(s.name, float(s.xy[0]), float(s.xy[1]), float(s.heading_deg), s)
                     for s in human.starts)
    s = human.start
    return (StartPoint(DEFAULT_START, float(s.xy[0]), float(s.xy[1]), float(s.heading_deg)),)


def arrival_phases(sim, start: StartPoint, mode: str = "all",
                   window: tuple[float, float] | None = None) -> tuple[float, ...]:
    """The arrival phases [s] to decide for ``start`` in ``sim``'s cell (``mode``: ``all``, ``cell`` or
    ``window`` with its ``window``, see the module)."""
    if mode not in PHASE_MODES:
        raise ValueError(f"phases must be one of {', '.join(PHASE_MODES)}, not {mode!r}")
    if mode == "cell":
        return cell_phases(sim, start.spec)
    cycle = float(sim.layout.trajectory.cycle)
    grid = tuple(p for p in phase_grid(sim.dt, 0.0, cycle) if p < cycle)  # the cycle's end is its start
    if mode == "all":
        return grid
    a, b = window
    chosen = tuple(p for p in grid if a - _ON_GRID <= p <= b + _ON_GRID)
    if not chosen:
        raise ValueError(f"phases: no arrival phase of the {sim.dt:g} s grid lies in {a:g}..{b:g} s (the robot's "
                         f"cycle is {cycle:g} s)")
    return chosen


def parse_phases(text: str) -> tuple[str, tuple[float, float] | None]:
    """``--phases``: ``all``, ``cell``, or a window ``A:B`` of the cycle in seconds -> (mode, window)."""
    if text in ("all", "cell"):
        return text, None
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = (float(x) for x in parts)
    except ValueError:
        raise ValueError(f"phases: all, cell or a window A:B in seconds of the robot's cycle, not "
                         f"{text[:40]!r}") from None
    if not (0.0 <= a < float("inf") and 0.0 <= b < float("inf")):
        raise ValueError(f"phases: a window's ends are seconds of the robot's cycle, finite and >= 0, not "
                         f"{text[:40]!r}")
    return "window", (a, b)


def chosen_starts(cell, names: tuple[str, ...] = ()) -> tuple[StartPoint, ...]:
    """The start points named (none: every one), in the cell's order; ValueError naming an unknown one."""
    points = start_points(cell)
    if not names:
        return points
    known = [p.name for p in points]
    for n in names:
        if n not in known:
            listed = ", ".join(known[:10]) + (", ..." if len(known) > 10 else "")
            raise ValueError(f"starts: the cell has no start point {n[:60]!r} (it has {listed[:300]})")
    return tuple(p for p in points if p.name in names)


def phases_are_grid(cell, mode: str) -> bool:
    """Whether ``mode`` decides the time-step grid of arrival moments (``all``, or a cell whose arrival is
    searched over its cycle or a window), rather than a cell's fixed moments."""
    return mode in ("all", "window") or cell.spec.human.arrival != "fixed"
