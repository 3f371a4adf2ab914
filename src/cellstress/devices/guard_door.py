"""An interlocked guard door (ISO 14119): a leaf in the fence line that the worker opens by walking into it.

Closed, the leaf blocks walking, the trunk and the arms like a fence panel. Its interlocking switch signals the
moment the worker pushes it (a stop after the switch's ``response_time``); the door is passable
``opening_time`` later. Without guard locking it starts to open at once, whatever the robot does; with guard
locking (ISO 14119:2013, locked until the hazard has ceased) it stays locked until the robot is at rest and
starts to open then. Model and numbers: docs/cells.md.

Minimum distance without guard locking (ISO 13855:2010, interlocking guards without guard locking):
S = K T + C with K = 1600 mm/s (walking approach), T = the switch's response + the robot's stopping time, less
the time the door takes to open wide enough (which the standard lets the designer credit), and C = 850 mm (the
door open, the arm reaches through it as past a body-detecting field). With guard locking no distance is
needed: the door opens only once the hazard has ceased.
"""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import model_validator

from cellstress.core.fields import Elevation, Height, Point2, PositiveTime
from cellstress.core.iso13855 import K_WALK, MIN_C_BODY, mm
from cellstress.core.records import DoorLeaf, IsoDistance
from cellstress.devices.base import DeviceRecord


class GuardDoor(DeviceRecord):
    """``start``-``end``: the door's line on the floor [m], the leaf from ``bottom`` to ``top`` [m];
    ``opening_time`` [s] from the push until a person fits through; ``guard_locking``: locked until the robot
    is at rest; ``response_time`` [s] of the interlocking switch."""

    type: Literal["guard-door"]
    """An interlocked guard door in the fence line."""
    start: Point2
    """One end of the door's opening on the floor [m] (the hinge side)."""
    end: Point2
    """The other end [m]."""
    bottom: Elevation = 0.0
    """Height of the leaf's lower edge [m]."""
    top: Height = 2.0
    """Height of the leaf's upper edge [m]."""
    response_time: PositiveTime = 0.05
    """Time [s] from the push (the leaf's first movement; with guard locking the request to enter) to the
    interlock's stop signal."""
    opening_time: PositiveTime = 0.6
    """Time [s] from the push until the leaf is open wide enough for a person to pass (with guard locking:
    from the unlocking)."""
    guard_locking: bool = False
    """Guard locking (ISO 14119): the door stays locked until the robot is at rest."""
    restart: Literal["manual"] = "manual"
    """A door's stop is released only by a reset outside the cell (the model never closes a door again)."""

    detection_phrase: ClassVar[str] = "pushes the guard door open"
    color: ClassVar[str] = "#e76f51"

    @model_validator(mode="after")
    def _shape(self) -> GuardDoor:
        if self.start == self.end:
            raise ValueError("start and end are the same point")
        if self.top <= self.bottom:
            raise ValueError(f"top ({self.top}) must be above bottom ({self.bottom})")
        return self

    def primitives(self) -> tuple[DoorLeaf, ...]:
        return (DoorLeaf(tuple(self.start), tuple(self.end), self.bottom, self.top, self.opening_time,
                         self.guard_locking),)

    def required_distance(self, stopping_time: float) -> IsoDistance:
        if self.guard_locking:
            return IsoDistance(K_WALK, 0.0, 0.0, 0.0, "guard locking: the door opens only once the robot is at "
                                                      "rest, so no distance is required (ISO 14119:2013)")
        t_full = self.response_time + stopping_time
        T = max(t_full - self.opening_time, 0.0)
        s = K_WALK * T + MIN_C_BODY
        return IsoDistance(K_WALK, T, MIN_C_BODY, s,
                           f"S = 1600*({self.response_time:g} + {stopping_time:g} - {self.opening_time:g} opening) "
                           f"+ 850 = {mm(s)} mm (interlocking guard without guard locking)")

    def static_check(self, distance: float, stopping_time: float) -> tuple[float, str]:
        """This kind's part of the static check (analysis.iso13855 asks any device that has it): the distance
        stands as measured; the note gives the access time (ISO 14119)."""
        return distance, self.access_note(distance, stopping_time)

    def access_note(self, distance: float, stopping_time: float) -> str:
        """The access time against the time to rest, for a door ``distance`` [m] from the hazard zone: the door
        open wide enough, then a walk at K to within the arm's reach C. ISO 14119:2013 asks for guard locking
        where the hazard lasts longer than that (the same inequality as the distance, in time)."""
        rest = self.response_time + stopping_time
        access = self.opening_time + max(distance * 1000.0 - MIN_C_BODY, 0.0) / K_WALK
        head = (f"access time {self.opening_time:g} + max({distance:.3f} - 0.850, 0)/1.6 = {access:.2f} s, "
                f"robot at rest {rest:.2f} s after the push")
        if self.guard_locking:
            return head + ": guard locking holds the door until then (ISO 14119:2013)"
        if access >= rest:
            return head + ": no guard locking needed (ISO 14119:2013)"
        return head + ": guard locking required (ISO 14119:2013)"

    def describe(self) -> str:
        (x0, y0), (x1, y1) = self.start, self.end
        lock = "guard locking" if self.guard_locking else "no guard locking"
        return f"({x0:g}, {y0:g})-({x1:g}, {y1:g}), opens in {self.opening_time:g} s, {lock}"

    def draw(self, ax):
        from matplotlib.lines import Line2D

        (x0, y0), (x1, y1) = self.start, self.end
        # a locked door is drawn solid with a bolt mark; an unlocked one dashed (it gives way to a push)
        style = "-" if self.guard_locking else (0, (2, 1))
        ax.plot([x0, x1], [y0, y1], color=self.color, lw=5, ls=style, solid_capstyle="butt", zorder=4.5)
        if self.guard_locking:
            ax.plot([(x0 + x1) / 2], [(y0 + y1) / 2], marker="s", ms=7, color="black", zorder=4.6)
        lock = "guard locking" if self.guard_locking else "no guard locking"
        return Line2D([], [], color=self.color, lw=5, ls=style,
                      label=f"guard door '{self.name}' ({lock}, opens in {self.opening_time:g} s, "
                            f"{self.response_time:g} s)")
