"""Which start points and arrival phases a verification decides: the one place that chooses them.

An arrival phase is the robot's path time when the worker's episode starts. ``all`` decides every time step of
the robot's cycle, k * dt for k * dt < cycle (rounded to 1 ns, as ``sim.starts.phase_grid`` names them), for
every start point, whatever the cell says; ``cell`` decides the phases the cell's ``human.arrival`` allows
(``sim.starts.arrival_phases``: ``fixed``, the cell's own phase or a start point's; ``cycle``, every time step of
the cycle; a window, every time step in it).
"""

from __future__ import annotations

from dataclasses import dataclass

from cellstress.sim.starts import arrival_phases as cell_phases
from cellstress.sim.starts import phase_grid

PHASE_MODES = ("all", "cell")
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


def arrival_phases(sim, start: StartPoint, mode: str = "all") -> tuple[float, ...]:
    """The arrival phases [s] to decide for ``start`` in ``sim``'s cell (``mode``: ``all`` or ``cell``, see the
    module)."""
    if mode not in PHASE_MODES:
        raise ValueError(f"phases must be one of {', '.join(PHASE_MODES)}, not {mode!r}")
    if mode == "cell":
        return cell_phases(sim, start.spec)
    cycle = float(sim.layout.trajectory.cycle)
    return tuple(p for p in phase_grid(sim.dt, 0.0, cycle) if p < cycle)  # the cycle's end is its start


def phases_are_grid(cell, mode: str) -> bool:
    """Whether ``mode`` decides the time-step grid of arrival moments (``all``, or a cell whose arrival is
    searched over its cycle or a window), rather than a cell's fixed moments."""
    return mode == "all" or cell.spec.human.arrival != "fixed"
