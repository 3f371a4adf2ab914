"""Which start points and arrival phases a verification decides: the one place that reads them from a cell.

An arrival phase is the robot's path time when the worker's episode starts (``robot.task.phase``, or a start
point's own ``phase``). ``all`` decides every phase of the robot's cycle on the simulation's time grid,
i * dt for i in range(ceil(cycle / dt)) (rounded to 1 ns, so that 0.15 is written 0.15); ``cell`` only the
phases the cell gives. (When the cell format gains an arrival window, ``human.arrival``, this is the function
that reads it.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

PHASE_MODES = ("all", "cell")
DEFAULT_START = "start"  # the name of a cell's only start point (``human.start``) in verify's output


@dataclass(frozen=True)
class StartPoint:
    """A start pose, named as the cell names it; ``phase``: its own arrival phase (None: the robot task's)."""

    name: str
    x: float
    y: float
    heading_deg: float
    phase: float | None = None

    @property
    def pose(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.heading_deg)


def start_points(cell) -> tuple[StartPoint, ...]:
    """The cell's start points: each of ``human.starts``, or ``human.start`` alone."""
    human = cell.spec.human
    if human.starts:
        return tuple(StartPoint(s.name, float(s.xy[0]), float(s.xy[1]), float(s.heading_deg), s.phase)
                     for s in human.starts)
    s = human.start
    return (StartPoint(DEFAULT_START, float(s.xy[0]), float(s.xy[1]), float(s.heading_deg)),)


def arrival_phases(cell, start: StartPoint, cycle: float, mode: str = "all") -> tuple[float, ...]:
    """The arrival phases [s] to decide for ``start`` (``mode``: ``all`` or ``cell``, see the module); ``cycle``
    is the robot's cycle time (``Layout.trajectory.cycle``)."""
    if mode not in PHASE_MODES:
        raise ValueError(f"phases must be one of {', '.join(PHASE_MODES)}, not {mode!r}")
    own = float(cell.spec.robot.task.phase if start.phase is None else start.phase)
    if mode == "cell":
        return (own,)
    dt = float(cell.spec.simulation.dt)
    n = max(1, math.ceil(cycle / dt - 1e-9))  # a cycle that is a whole number of steps is not one step longer
    return tuple(round(i * dt, 9) for i in range(n))
